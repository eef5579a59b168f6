"""evaluate(outputs=...): only the named Result fields are computed and returned.

What is asked for must be bit for bit what the full call gives (the kernel skips the other
outputs, and f50 itself when neither f50 nor EPC is asked for, but never changes a computed
value); what is not asked for is None; bad selections are errors naming ``outputs``.
"""
from __future__ import annotations

import numpy as np
import pytest

import epc_fast
from epc_fast import Result, Status, _limits, api, footprint
from helpers.designs import random_design_points

ALL_FIELDS = tuple(api.OUTPUT_DTYPES)
#: Selections that exercise each kernel path: without f50 (exposure only), f50 without the
#: exposure outputs, EPC alone (f50 solved, not written), status alone, every single field.
SELECTIONS = [("t_mpe_s",), ("t_mpe_s", "status", "cause"), ("f50_cyc_per_mm",), ("epc",),
              ("epc", "status"), ("status",), ("electron_rate_e_per_s", "electrons", "blur_mm"),
              ("cause", "f50_cyc_per_mm")] + [(name,) for name in ALL_FIELDS]


@pytest.fixture(scope="module")
def designs():
    # every status occurs (invalid points, unreachable targets, unbounded blur)
    return random_design_points(6000, seed=41)


def _same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("selection", SELECTIONS, ids="+".join)
@pytest.mark.parametrize("options", [{}, {"precision": "float32"}, {"f50_solver": "bisection"},
                                     {"t_mpe_solver": "brent", "threads": 1}],
                         ids=["default", "float32", "bisection", "brent-1-thread"])
def test_selected_fields_are_those_of_the_full_call_and_the_rest_are_none(designs, selection,
                                                                          options):
    full = epc_fast.evaluate(**designs, **options)
    statuses = set(np.unique(full.status).tolist())
    # every status but BEYOND_TABLE, which needs a lens table (lens_mtf: the reference only),
    # and EXPOSURE_LIMIT, which needs a frame cap (max_exposure_s)
    assert statuses == {int(s) for s in Status} - {Status.BEYOND_TABLE,
                                                   Status.EXPOSURE_LIMIT}, \
        "the designs must exercise every status"
    part = epc_fast.evaluate(**designs, **options, outputs=selection)
    assert isinstance(part, Result)
    for name in ALL_FIELDS:
        if name in selection:
            assert _same_bits(getattr(part, name), getattr(full, name)), name
        else:
            assert getattr(part, name) is None, name


@pytest.mark.parametrize("selection", [("epc",), ("t_mpe_s", "status")], ids="+".join)
def test_reference_backend_returns_the_same_selection(designs, selection):
    few = {k: v[:300] for k, v in designs.items()}
    full = epc_fast.evaluate(**few, backend="reference")
    part = epc_fast.evaluate(**few, backend="reference", outputs=selection)
    for name in ALL_FIELDS:
        if name in selection:
            assert _same_bits(getattr(part, name), getattr(full, name)), name
        else:
            assert getattr(part, name) is None


def test_thread_count_does_not_change_a_selection(designs):
    one = epc_fast.evaluate(**designs, threads=1, outputs=("epc", "status"))
    two = epc_fast.evaluate(**designs, threads=2, outputs=("epc", "status"))
    assert _same_bits(one.epc, two.epc) and _same_bits(one.status, two.status)


def test_scalar_input_gives_scalars_for_the_selection_and_none_elsewhere():
    full = epc_fast.evaluate(1000.0, 1.0, 2.0, 4.0, pixel_count=1.2e7)
    part = epc_fast.evaluate(1000.0, 1.0, 2.0, 4.0, pixel_count=1.2e7, outputs=("epc", "status"))
    assert part.epc == full.epc and isinstance(part.epc, float)
    assert part.status is Status.OK
    assert part.f50_cyc_per_mm is None and part.cause is None


def test_broadcast_shape_is_kept():
    lux = np.logspace(0, 4, 7)[:, None]
    pitch = np.linspace(0.8, 2.0, 5)[None, :]
    full = epc_fast.evaluate(lux, pitch, 2.0, 4.0, pixel_count=1e7)
    part = epc_fast.evaluate(lux, pitch, 2.0, 4.0, pixel_count=1e7, outputs=["f50_cyc_per_mm"])
    assert part.f50_cyc_per_mm.shape == (7, 5)
    assert _same_bits(part.f50_cyc_per_mm, full.f50_cyc_per_mm)


def test_a_single_name_may_be_given_as_a_string(designs):
    assert _same_bits(epc_fast.evaluate(**designs, outputs="epc").epc,
                      epc_fast.evaluate(**designs).epc)


def test_order_and_repeats_do_not_matter(designs):
    a = epc_fast.evaluate(**designs, outputs=("status", "epc", "epc"))
    b = epc_fast.evaluate(**designs, outputs=("epc", "status"))
    assert _same_bits(a.epc, b.epc) and _same_bits(a.status, b.status)


@pytest.mark.parametrize("outputs, error, match", [
    (("epc", "f50"), ValueError, r"outputs must name .*unknown field\(s\) \['f50'\]"),
    ((), ValueError, r"outputs must name at least one .*got none"),
    (5, TypeError, r"outputs must be a field name or an iterable of them, got 5"),
])
def test_a_bad_selection_is_an_error_naming_outputs(designs, outputs, error, match):
    with pytest.raises(error, match=match):
        epc_fast.evaluate(**designs, outputs=outputs)


def test_invalid_raise_still_checks_without_status_in_the_selection():
    bad = random_design_points(50, seed=3, invalid_fraction=0.0)
    bad["f_number"] = np.where(np.arange(bad["f_number"].size) == 3, -1.0, bad["f_number"])
    with pytest.raises(ValueError, match=r"f_number=-1.0 at index \(3,\)"):
        epc_fast.evaluate(**bad, outputs=("epc",), invalid="raise")


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_out_holds_exactly_the_selection_and_is_written_in_place(designs, backend):
    few = {k: v[:500] for k, v in designs.items()}
    out = {"epc": np.full(500, -1.0), "status": np.full(500, 255, np.uint8)}
    r = epc_fast.evaluate(**few, outputs=("epc", "status"), out=out, backend=backend)
    full = epc_fast.evaluate(**few, backend=backend)
    assert r.epc is out["epc"] and r.status is out["status"]
    assert _same_bits(out["epc"], full.epc) and _same_bits(out["status"], full.status)
    assert r.t_mpe_s is None
    # a Result of an earlier call with the same selection can be passed back as out=
    again = epc_fast.evaluate(**few, outputs=("epc", "status"), out=r, backend=backend)
    assert again.epc is out["epc"]


def test_out_with_other_fields_than_the_selection_is_an_error(designs):
    few = {k: v[:10] for k, v in designs.items()}
    with pytest.raises(ValueError, match=r"out must have exactly the fields epc; missing: "
                                         r"\[\], unknown: \['status'\]"):
        epc_fast.evaluate(**few, outputs=("epc",),
                          out={"epc": np.empty(10), "status": np.empty(10, np.uint8)})
    with pytest.raises(ValueError, match=r"missing: \['status'\]"):
        epc_fast.evaluate(**few, outputs=("epc", "status"), out={"epc": np.empty(10)})


def test_the_memory_estimate_counts_only_the_selected_outputs(monkeypatch):
    # 1e9 points of a broadcast design: 50 bytes a point for every output (50 GB), 8 for EPC
    # alone (8 GB); with a 20 GB limit only the full selection is refused before allocating.
    monkeypatch.setattr(_limits, "memory_limit_bytes", lambda: 20 * 10**9)
    scalars = [np.asarray(1.0)] * len(epc_fast.params.PARAMETER_NAMES)
    with pytest.raises(MemoryError, match="needs about 46.6 GiB"):
        footprint.check_memory((10**9,), scalars, "core", False, ALL_FIELDS)
    footprint.check_memory((10**9,), scalars, "core", False, ("epc",))
    monkeypatch.setattr(_limits, "memory_limit_bytes", lambda: 8 * 10**9)
    with pytest.raises(MemoryError, match="needs about 8.4 GiB"):  # 9 bytes a point
        footprint.check_memory((10**9,), scalars, "core", False, ("epc", "status"))


def test_out_may_reuse_input_arrays_each_point_is_read_before_it_is_written(designs):
    # The kernel reads full blocks of contiguous input columns in place (gather.h) and
    # writes a block's outputs one after another, so core_call.run_core copies an input column that
    # shares memory with an output. Here the rate overwrites the pitch, which the EPC of pixel
    # counts reads after the rate is written, and f50 the pixel count, read for the EPC too.
    few = {k: np.array(v[:3000]) for k, v in designs.items() if k != "sensor_area_mm2"}
    few["pixel_count"] = np.random.default_rng(3).uniform(1e6, 5e7, 3000)
    expected = epc_fast.evaluate(**few)
    out = {name: np.empty(3000, api.OUTPUT_DTYPES[name]) for name in ALL_FIELDS}
    out["electron_rate_e_per_s"] = few["pixel_pitch_um"]
    out["f50_cyc_per_mm"] = few["pixel_count"]
    out["t_mpe_s"] = few["illuminance_lux"]
    result = epc_fast.evaluate(**few, out=out)
    for name in ALL_FIELDS:
        assert _same_bits(getattr(result, name), getattr(expected, name)), name
    assert result.electron_rate_e_per_s is few["pixel_pitch_um"]


def test_a_broadcast_input_that_is_an_output_element_is_read_as_it_was(designs):
    # A 0-d input column is read by every block, so the core copies it too when it shares
    # memory with an output (register_evaluate.cpp, copy_overlapping): here the f-number is
    # a view of the first point's EPC, which the first block writes before the others read.
    few = {k: np.array(v[:3000]) for k, v in designs.items() if k != "f_number"}
    expected = epc_fast.evaluate(**few, f_number=2.8, outputs=("epc",), threads=1)
    epc = np.full(3000, 2.8)
    result = epc_fast.evaluate(**few, f_number=epc[0, ...], outputs=("epc",), out={"epc": epc},
                               threads=1)
    assert result.epc is epc
    assert _same_bits(epc, expected.epc)


def test_an_input_shifted_against_an_output_in_one_buffer_is_read_as_it_was(designs):
    # a partial overlap: the illuminance column is buffer[1:] and the
    # f50 output buffer[:-1], so that every point's f50 overwrites the next point's light
    few = {k: np.array(v[:3000]) for k, v in designs.items()}
    expected = epc_fast.evaluate(**few, outputs=("f50_cyc_per_mm",))
    buffer = np.empty(3001)
    buffer[1:] = few["illuminance_lux"]
    few["illuminance_lux"] = buffer[1:]
    result = epc_fast.evaluate(**few, outputs=("f50_cyc_per_mm",),
                               out={"f50_cyc_per_mm": buffer[:-1]})
    assert _same_bits(buffer[:-1], expected.f50_cyc_per_mm)
    assert np.shares_memory(result.f50_cyc_per_mm, buffer)


@pytest.fixture
def no_kept_memory():
    """Every new output array on new pages: the output cache (epc_fast.memory) keeps nothing."""
    before = epc_fast.output_cache().limit_bytes
    epc_fast.output_cache(0)
    yield
    epc_fast.output_cache(before)


@pytest.mark.parametrize("selection", [None, ("f50_cyc_per_mm", "epc", "status")],
                         ids=["all", "lean"])
def test_fresh_outputs_faulted_in_first_hold_the_bits_of_out_and_of_one_thread(monkeypatch,
                                                                               selection,
                                                                               no_kept_memory):
    # Arrays the core allocates on new pages get a 0 written into every page on both threads
    # before the kernel runs (parallel.h first_touch), for chunks of at least 2^16 points.
    # Chunks of 2^16 + 3 points over 3 * 2^16 + 5 put some chunks above that size and the last
    # one below it, at offsets that are not page-aligned: a touch at a wrong offset, or after
    # the kernel, would leave a 0 byte in some result.
    monkeypatch.setattr(api, "CHUNK_POINTS", (1 << 16) + 3)
    n = 3 * (1 << 16) + 5
    designs = random_design_points(n, seed=43)
    fresh = epc_fast.evaluate(**designs, outputs=selection, threads=2)
    assert fresh.epc.base is None  # NumPy's own new memory, not kept memory
    names = ALL_FIELDS if selection is None else selection
    out = {name: np.full(n, 0x5A, dtype=api.OUTPUT_DTYPES[name]) for name in names}
    given = epc_fast.evaluate(**designs, outputs=selection, threads=2, out=out)
    serial = epc_fast.evaluate(**designs, outputs=selection, threads=1)
    # every status but BEYOND_TABLE and EXPOSURE_LIMIT (no lens table, no frame cap)
    assert len(set(np.unique(fresh.status).tolist())) == len(Status) - 2
    for name in names:
        assert _same_bits(getattr(fresh, name), getattr(given, name)), name
        assert _same_bits(getattr(fresh, name), getattr(serial, name)), name


def test_a_call_below_the_unchecked_size_reads_no_limit(monkeypatch):
    # Reading the limits (cgroup files, /proc) costs more than a small call's points: a call
    # that needs at most UNCHECKED_BYTES is not checked, one byte a point more is.
    def limit():
        raise AssertionError("the limit was read")

    monkeypatch.setattr(_limits, "memory_limit_bytes", limit)
    scalars = [np.asarray(1.0)] * len(epc_fast.params.PARAMETER_NAMES)
    points = footprint.UNCHECKED_BYTES // 8  # EPC alone: 8 bytes a point
    footprint.check_memory((points,), scalars, "core", False, ("epc",))
    with pytest.raises(AssertionError, match="the limit was read"):
        footprint.check_memory((points + 1,), scalars, "core", False, ("epc",))


def test_new_result_is_the_dataclass_s_own_result():
    from dataclasses import FrozenInstanceError

    from epc_fast.outputs import new_result

    fields = dict.fromkeys(api.OUTPUT_DTYPES)
    made = new_result({"epc": 2.5, "status": Status.OK})
    assert made == Result(**(fields | {"epc": 2.5, "status": Status.OK}))
    assert made.share_lens is None and made.elasticities is None and made.mode is None
    with pytest.raises(FrozenInstanceError):
        made.epc = 1.0
    with pytest.raises(TypeError, match=r"Result has no field\(s\) \['f50'\]"):
        new_result({"f50": 1.0})
