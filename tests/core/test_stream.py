"""Streaming stores (cpp/include/epc_fast/stream.h): a call whose outputs total
``_core.stream_min_bytes`` or more writes the whole cache lines of its full blocks with
non-temporal stores, and ordinary copies elsewhere (lines a block shares with its neighbours,
partial blocks, smaller calls). How a value is stored must never change it: every test compares a
streaming call with the same points evaluated in calls too small to stream, bit for bit.
"""
from __future__ import annotations

import numpy as np
import pytest

from epc_fast import _core, api, evaluate
from epc_fast.selfcheck import random_designs
from helpers.designs import WIDE_POINTS, ordinary_points, random_design_points, with_extremes

ALL_FIELDS = tuple(api.OUTPUT_DTYPES)
BYTES_PER_POINT = sum(d.itemsize for d in api.OUTPUT_DTYPES.values())  # every output: 50
#: A little over the streaming threshold for a call computing every output, and not a multiple
#: of the block size, so that the last block is partial (an ordinary copy).
STREAMING_POINTS = _core.stream_min_bytes // BYTES_PER_POINT + 3 * _core.block_size + 37
#: Calls of this many points total far less than the threshold: none of them streams.
PIECE_POINTS = 20_000


def _in_pieces(kwargs, n, fields=ALL_FIELDS, **options):
    """The outputs ``fields`` of the points of ``kwargs`` (arrays of n values), from calls of
    PIECE_POINTS points: none of them streams."""
    pieces = [evaluate(**{k: v[i:i + PIECE_POINTS] for k, v in kwargs.items()}, **options)
              for i in range(0, n, PIECE_POINTS)]
    return {f: np.concatenate([getattr(p, f) for p in pieces]) for f in fields}


def _assert_same_bits(result, expected):
    for field in ALL_FIELDS:
        got = np.asarray(getattr(result, field) if not isinstance(result, dict) else result[field])
        assert got.dtype == expected[field].dtype, field
        assert got.tobytes() == expected[field].tobytes(), field


def test_the_call_is_large_enough_to_stream_and_its_pieces_are_not():
    assert STREAMING_POINTS * BYTES_PER_POINT >= _core.stream_min_bytes
    assert PIECE_POINTS * BYTES_PER_POINT < _core.stream_min_bytes
    assert STREAMING_POINTS % _core.block_size != 0
    # every x86-64 module streams (SSE2 and wider)
    assert _core.streaming_stores == _core.module_name.startswith("_core_x86_64")


@pytest.fixture(scope="module")
def designs():
    # the whole domain: every status and cause, invalid points among them
    return random_design_points(STREAMING_POINTS, seed=73)


@pytest.mark.parametrize("options", [{}, {"precision": "float32"}, {"threads": 1},
                                     {"f50_solver": "brent", "t_mpe_solver": "brent"}],
                         ids=["default", "float32", "1-thread", "brent"])
def test_a_streaming_call_gives_the_bits_of_calls_too_small_to_stream(designs, options):
    expected = _in_pieces(designs, STREAMING_POINTS, **options)
    assert len(np.unique(expected["status"])) == 4  # ok, invalid, unreachable, blur unbounded
    result = evaluate(**designs, **options)
    # the core's own arrays of 1 MiB and more are 64-byte aligned (output_cache.h), so they are
    # streamed into; the uint8 ones (340 kB here) are NumPy's, and are ordinary copies
    big = [f for f in ALL_FIELDS if getattr(result, f).nbytes >= 1 << 20]
    assert len(big) == 6 and all(getattr(result, f).ctypes.data % 64 == 0 for f in big)
    _assert_same_bits(result, expected)


@pytest.mark.parametrize("offset_bytes", [0, 8, 16, 32], ids=lambda b: f"offset-{b}")
def test_out_arrays_at_any_alignment_hold_the_same_bits(designs, offset_bytes):
    """Caller's arrays at 8-byte offsets from a cache line: each block streams its whole lines
    and copies the two it shares with its neighbours."""
    expected = _in_pieces(designs, STREAMING_POINTS)
    out = {}
    for field, dtype in api.OUTPUT_DTYPES.items():
        raw = np.full(STREAMING_POINTS * dtype.itemsize + 128, 0xAB, np.uint8)
        start = (-raw.ctypes.data) % 64 + offset_bytes
        out[field] = raw[start:start + STREAMING_POINTS * dtype.itemsize].view(dtype)
        assert out[field].ctypes.data % 64 == offset_bytes
    evaluate(**designs, out=out)
    _assert_same_bits(out, expected)


def test_float32_lanes_redone_in_float64_overwrite_streamed_lines():
    """float32's wide lanes (lengths outside 2^-40..2^40 mm) are written over the block's
    streamed lines after a fence (kernel.h evaluate_block): the float64 values must win."""
    n_extreme = len(WIDE_POINTS)
    ordinary = ordinary_points(STREAMING_POINTS - n_extreme, seed=8)
    # spread over the call, so that streamed full blocks hold them
    at = np.linspace(100, STREAMING_POINTS - 100, n_extreme).astype(int)
    kwargs, is_extreme = with_extremes(ordinary, list(WIDE_POINTS.values()), at)
    expected = _in_pieces(kwargs, STREAMING_POINTS, precision="float32")
    result = evaluate(**kwargs, precision="float32")
    _assert_same_bits(result, expected)
    wide64 = evaluate(**{k: v[is_extreme] for k, v in kwargs.items()})
    np.testing.assert_array_equal(result.f50_cyc_per_mm[is_extreme], wide64.f50_cyc_per_mm)


@pytest.mark.parametrize("selection", [("epc", "status"), ("t_mpe_s",)], ids="+".join)
def test_a_selection_streams_by_its_own_bytes(selection):
    """A selection's call streams from the threshold over the bytes of the outputs it computes
    (kernel.h streaming_for): a call of that size gives the bits of its pieces."""
    bytes_per_point = sum(api.OUTPUT_DTYPES[f].itemsize for f in selection)
    n = _core.stream_min_bytes // bytes_per_point + 101
    kwargs = random_designs(n, seed=3)
    expected = _in_pieces(kwargs, n, selection, outputs=selection)
    result = evaluate(**kwargs, outputs=selection)
    for field in selection:
        assert getattr(result, field).tobytes() == expected[field].tobytes(), field
