"""epc_fast.memory: the output memory the core keeps between calls, and its limit.

A kept block must give the next call exactly the bits a new array gives (every point is
written, nothing of the last call survives), must never be handed out while any view of its
last array is alive, must stay within the limit, and is only reused for a request of about its
own size.
"""
from __future__ import annotations

import gc
import pickle

import numpy as np
import pytest

import epc_fast
from epc_fast import _core, _limits, _validation, api, memory, params
from helpers.designs import random_design_points

MIB = 2**20
#: Enough points for every float64 output (8 B a point) to pass the cache's 1 MiB threshold;
#: the uint8 status and cause (200 kB) stay below it and are NumPy's own arrays.
N = 200_003
FLOAT_FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc")


@pytest.fixture
def cache():
    """An empty cache with a 64 MiB limit for the test; the previous limit after it."""
    before = epc_fast.output_cache().limit_bytes
    epc_fast.output_cache(0)
    epc_fast.output_cache(64 * MIB)
    yield
    epc_fast.output_cache(0)
    epc_fast.output_cache(before)


@pytest.fixture(scope="module")
def designs():
    return random_design_points(N, seed=52)


def _owner(array):
    """The end of an array's base chain: None for memory NumPy owns, else what owns it."""
    while isinstance(array.base, np.ndarray):
        array = array.base
    return array.base


def _address(array):
    return array.__array_interface__["data"][0]


def _same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def test_a_dropped_result_s_memory_serves_the_next_call_with_the_bits_of_new_memory(cache,
                                                                                    designs):
    # The first call leaves other designs' values in the blocks the second call reuses; a
    # point the kernel did not write would show them.
    other = random_design_points(N, seed=53)
    first = epc_fast.evaluate(**other)
    addresses = {name: _address(getattr(first, name)) for name in FLOAT_FIELDS}
    del first
    gc.collect()
    assert epc_fast.output_cache().retained_bytes >= 6 * N * 8
    second = epc_fast.evaluate(**designs)
    # each output got a block back (the six blocks are of one size: any of them may serve)
    assert {_address(getattr(second, name)) for name in FLOAT_FIELDS} == set(addresses.values())
    assert epc_fast.output_cache().retained_bytes == 0
    epc_fast.output_cache(0)
    new = epc_fast.evaluate(**designs)
    # every status but BEYOND_TABLE and EXPOSURE_LIMIT (no lens table, no frame cap)
    assert len(set(np.unique(new.status).tolist())) == len(epc_fast.Status) - 2
    for name in api.OUTPUT_DTYPES:
        assert _same_bits(getattr(second, name), getattr(new, name)), name


def test_memory_is_not_reused_while_a_view_of_its_array_lives(cache, designs):
    first = epc_fast.evaluate(**designs)
    view = first.f50_cyc_per_mm[10:20]
    kept = view.copy()
    del first
    gc.collect()
    # five blocks came back; the one under `view` did not
    assert epc_fast.output_cache().retained_bytes == 5 * _capacity(N * 8)
    second = epc_fast.evaluate(**random_design_points(N, seed=54))
    assert not any(np.shares_memory(view, getattr(second, name)) for name in FLOAT_FIELDS)
    assert _same_bits(view, kept)
    del view
    gc.collect()
    assert epc_fast.output_cache().retained_bytes == _capacity(N * 8)


def _capacity(nbytes):
    """A block's size for a request (output_cache.h): whole 2 MiB for 4 MiB and more, else
    whole 64 B."""
    align = 2 * MIB if nbytes >= 4 * MIB else 64
    return -(-nbytes // align) * align


def test_the_kept_memory_stays_within_the_limit(cache, designs):
    # 3.5 blocks' worth: three are kept of the six, the oldest freed first
    limit = 3 * _capacity(N * 8) + _capacity(N * 8) // 2
    epc_fast.output_cache(limit)
    result = epc_fast.evaluate(**designs)
    del result
    gc.collect()
    state = epc_fast.output_cache()
    assert state == (limit, 3 * _capacity(N * 8))
    # lowering the limit frees the oldest beyond it; 0 frees everything and keeps nothing
    assert epc_fast.output_cache(_capacity(N * 8)) == (_capacity(N * 8), _capacity(N * 8))
    assert epc_fast.output_cache(0) == (0, 0)
    result = epc_fast.evaluate(**designs)
    assert _owner(result.f50_cyc_per_mm) is None  # NumPy's own memory when nothing is kept
    del result
    gc.collect()
    assert epc_fast.output_cache().retained_bytes == 0


def test_a_block_serves_only_a_request_within_a_quarter_of_its_size(cache, designs):
    result = epc_fast.evaluate(**designs)
    del result
    gc.collect()
    kept = epc_fast.output_cache().retained_bytes
    assert kept == 6 * _capacity(N * 8)
    # 1.6 MB blocks for 1.12 MB arrays (0.7 N points, above the 1 MiB threshold): more than a
    # quarter too large, so new memory; for 1.33 MB arrays (5/6 N): within a quarter, reused
    small, near = N * 7 // 10, N * 5 // 6
    not_served = epc_fast.evaluate(**{k: v[:small] for k, v in designs.items()})
    assert epc_fast.output_cache().retained_bytes == kept
    served = epc_fast.evaluate(**{k: v[:near] for k, v in designs.items()})
    assert epc_fast.output_cache().retained_bytes == 0
    epc_fast.output_cache(0)
    full = epc_fast.evaluate(**designs)
    for name in api.OUTPUT_DTYPES:
        assert _same_bits(getattr(served, name), getattr(full, name)[:near]), name
        assert _same_bits(getattr(not_served, name), getattr(full, name)[:small]), name


def test_a_selection_of_outputs_and_out_arrays_mix_with_kept_memory(cache, designs,
                                                                   monkeypatch):
    epc_fast.output_cache(0)
    expected = epc_fast.evaluate(**designs)
    epc_fast.output_cache(64 * MIB)
    lean = epc_fast.evaluate(**designs, outputs=("f50_cyc_per_mm", "epc", "status"))
    del lean  # its f50 and EPC blocks are kept
    gc.collect()
    again = epc_fast.evaluate(**designs, outputs=("f50_cyc_per_mm", "epc", "status"))
    for name in ("f50_cyc_per_mm", "epc", "status"):
        assert _same_bits(getattr(again, name), getattr(expected, name)), name
    del again
    gc.collect()
    # beneath the API: a caller's array and kept memory in one call, with the API's arguments
    calls = []
    real = _core.evaluate
    monkeypatch.setattr(_core, "evaluate",
                        lambda *args, **kwargs: calls.append((args, kwargs)) or real(*args, **kwargs))
    epc_fast.evaluate(**designs, outputs=("t_mpe_s",))
    out = {"t_mpe_s": np.full(N, np.nan)}
    # (the API's last six positional arguments: out, allocate, the two tables, epc_both and
    # the modes)
    args, kwargs = calls[0]
    result = real(*args[:-6], out, ["epc", "f50_cyc_per_mm"], *args[-4:], **kwargs)
    assert epc_fast.output_cache().retained_bytes == 0  # both came from the cache
    assert result["t_mpe_s"] is out["t_mpe_s"]
    for name in ("t_mpe_s", "epc", "f50_cyc_per_mm"):
        assert _same_bits(result[name], getattr(expected, name)), name


def test_arrays_on_kept_memory_pickle_and_copy_as_any_array(cache, designs):
    result = epc_fast.evaluate(**designs)
    assert type(_owner(result.epc)).__name__ == "PyCapsule"  # the block's owner
    restored = pickle.loads(pickle.dumps(result.epc))
    assert _same_bits(restored, result.epc)
    copied = result.epc.copy()
    del result
    gc.collect()
    assert _same_bits(copied, restored)


def test_output_cache_refuses_a_bad_limit_naming_it():
    for bad, error in [(-1, ValueError), (1.5, TypeError), (True, TypeError), ("1", TypeError)]:
        with pytest.raises(error, match="limit_bytes"):
            epc_fast.output_cache(bad)
    with pytest.raises(ValueError, match="limit_bytes must be >= 0"):
        _core.output_cache(-5)


@pytest.mark.parametrize("text, expected", [("0", 0), ("1.5", 3 * MIB // 2), (" 64 ", 64 * MIB)])
def test_the_environment_sets_the_default_limit_in_mib(monkeypatch, text, expected):
    monkeypatch.setenv(memory.CACHE_ENV, text)
    assert memory.default_cache_bytes() == expected


@pytest.mark.parametrize("text", ["-1", "abc", "nan", "inf"])
def test_a_bad_environment_limit_is_an_error_naming_the_variable_and_value(monkeypatch, text):
    monkeypatch.setenv(memory.CACHE_ENV, text)
    with pytest.raises(ValueError, match=f"EPC_FAST_OUTPUT_CACHE_MB='{text}'"):
        memory.default_cache_bytes()


def test_the_default_limit_is_a_sixteenth_of_memory_up_to_1_gib(monkeypatch):
    monkeypatch.delenv(memory.CACHE_ENV, raising=False)
    for total, expected in [(4 * 2**30, 2**28), (64 * 2**30, 2**30), (None, 2**30)]:
        monkeypatch.setattr(_limits, "memory_limit_bytes", lambda total=total: total)
        assert memory.default_cache_bytes() == expected


def test_the_core_s_allocate_argument_is_checked():
    columns, domains = [np.zeros(1)] * len(params.PARAMETERS), params.domain_table()
    none = np.empty(0)
    args = (columns, False, domains, none, none, 3, "halley", 1e-14,
            "closed_form", 1e-15, "float64", 1, 1 << 18)
    with pytest.raises(ValueError, match="allocate: 'f50' is not an output"):
        _core.evaluate(*args, None, ["f50"])
    with pytest.raises(ValueError, match="allocate: 'epc' is in out already"):
        _core.evaluate(*args, {"epc": np.empty(3)}, ["epc"])
    with pytest.raises(TypeError, match="allocate must hold output names"):
        _core.evaluate(*args, None, [3])
    with pytest.raises(ValueError, match="out must be a dict or None"):
        _core.evaluate(*args, [np.empty(3)])
    # allocate=None: every output without out, none with it
    assert set(_core.evaluate(*args)) == set(api.OUTPUT_DTYPES)
    assert set(_core.evaluate(*args, {"epc": np.empty(3)})) == {"epc"}
    assert set(_core.evaluate(*args, {}, ["status"])) == {"status"}


def _package_imports(module) -> set[str]:
    """The package's modules that a module's source imports (relative imports, anywhere in it)."""
    import ast
    import inspect

    names = set()
    for node in ast.walk(ast.parse(inspect.getsource(module))):
        if isinstance(node, ast.ImportFrom) and node.level > 0:
            names.update([node.module] if node.module else [a.name for a in node.names])
    return names


def test_the_core_s_loader_and_memory_do_not_import_each_other():
    # the limits the loader needs at load time live in a leaf module that both import
    assert _package_imports(_limits) == set()
    assert "memory" not in _package_imports(_core)
    assert _package_imports(memory) == {"_core", "_limits"}


def test_the_core_s_loader_imports_leaf_modules_only():
    # the thread bound lives in a leaf that the loader and the argument checks both import, so
    # that importing api does not load the compiled core (the reference backend runs without it)
    assert _package_imports(_core) == {"_limits"}
    assert _package_imports(_validation) == {"_limits", "_core"}  # the core only for a default
    assert api.MAX_THREADS is _core.MAX_THREADS is _limits.MAX_THREADS
