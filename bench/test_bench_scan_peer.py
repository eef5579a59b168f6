"""The Numba scan peer (``peers/numba_scan_peer.py``): its draws and reductions checked against
NumPy, and its speed in the scan's benchmark group:

    python -m pytest bench/test_bench_scan_peer.py --benchmark-only

The NumPy side of every check draws the same points by the stream contract with the package's
reference of it (``epc_fast.scan.sampling.streams``: uniforms, AS 241, then the log-uniform and
log-normal transforms written out here), evaluates them with ``epc_fast.evaluate`` (the core)
and reduces them with plain NumPy (``np.histogram``, ``np.mean``, ...). Integer results (points,
status counts, finite counts, both histograms, the count below 2e6) must be equal; the float
ones agree within the tolerances below, each with its reason. The benchmark (group
``scan 2^21 points``, beside ``test_bench_scan.py``'s scan and raw core; 2^17 points in quick
mode) checks its own answer the same way, with the kernel compiled outside the timing.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from engine_suite import QUICK, THREADS, blur_condition
from epc_fast import Status, evaluate
from epc_fast.scan import Quantiles
from epc_fast.scan.config import default_config
from epc_fast.scan.reductions.histograms import _histogram_quantiles

numba = pytest.importorskip("numba")
streams = pytest.importorskip("epc_fast.scan.sampling.streams")

from peers import numba_scan_peer as peer  # noqa: E402  (needs Numba)

SEED = 2009
#: Points of the correctness test (2^14 per design and thread on 2 threads).
CHECK_POINTS = 1 << 17
#: Points of the benchmark: the scan group's 2^21, or 2^17 in quick mode.
POINTS = 1 << 17 if QUICK else 1 << 21
GROUP = "scan 2^21 points" + (" (quick)" if QUICK else "")
UNIT_ROUNDOFF = 2.0 ** -53
#: ulp: how far the peer's drawn values and AS 241 may be from the NumPy reference's. The
#: uniforms are the same bits; exp and log differ in the last bit between NumPy's and the C
#: library's implementations, and ndtri's tail r = sqrt(-log p) carries one ulp of log into
#: up to 3 ulp of its value (measured 3 over 10^6 uniforms; 1 for the illuminance, 2 for the
#: shake over 2^17 points).
DRAW_ULPS = 4
#: Per-point relative agreement of the peer's EPC with the core's, per unit of the blur's
#: condition number kappa (engine_suite.blur_condition). The Numba model agrees with the
#: reference to 2.4e-15 x kappa (the engine suites' max_rel_error over 10^7 designs), and the
#: inputs differ by the few ulp above, which EPC (at most ~ illuminance^2 where blur sets f50)
#: turns into a few more: 1e-13 leaves a factor of ten over both together.
POINT_RTOL = 1e-13


def moments_rtol(points: int, threads: int = THREADS, designs: int = 4) -> float:
    """The relative tolerance on a design's mean and std over ``points`` points.

    Each thread runs Welford's update over its m = points / (designs threads) values of a
    design: every step rounds the new mean by at most one unit roundoff u of it, and the error
    carries forward with a weight below 1, so the mean is within m u of the exact mean of the
    peer's values (typically sqrt(m) u); the sum of squared deviations adds positive terms
    each rounded by a few u, so it too is within about m u, and its square root half that.
    Chan's merge of the threads and NumPy's pairwise sums add O(log n) u, covered by 64 u. The
    peer's values themselves are within POINT_RTOL of the core's (kappa is ~1 wherever EPC
    carries weight in a mean). At 2^17 points: 1.9e-12; at 2^21: 2.9e-11."""
    m = points // (designs * threads)
    return POINT_RTOL + (m + 64) * UNIT_ROUNDOFF


def ulps(got: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """|got - expected| in units in the last place of expected."""
    return np.abs(got - expected) / np.spacing(np.abs(expected))


def contract_draws(index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Illuminance (lux) and shake (degree/s) at ``index`` by the stream contract, in NumPy:
    exp(log lo + u (log hi - log lo)) clamped, and exp(log median + sigma ndtri(u))."""
    space = default_config().space
    lux, shake = space.axes["illuminance_lux"], space.axes["shake_deg_per_s"]
    u = streams.uniforms(SEED, streams.stream_id("illuminance_lux"), index)
    log_low, log_high = math.log(lux.low), math.log(lux.high)
    illuminance = np.clip(np.exp(log_low + u * (log_high - log_low)), lux.low, lux.high)
    u = streams.uniforms(SEED, streams.stream_id("shake_deg_per_s"), index)
    return illuminance, np.exp(math.log(shake.median) + shake.sigma * streams.ndtri(u))


@functools.lru_cache(maxsize=2)
def numpy_scan(points: int) -> dict:
    """The default scan's first ``points`` points drawn by ``epc_fast.scan.sampling.streams``,
    evaluated by the core and reduced by NumPy, per design (the peer's keys, plus
    ``min_kappa`` and ``max_kappa``: the blur's condition number at the least and greatest
    EPC)."""
    space = default_config().space
    designs = len(space.design_names)
    index = np.arange(points, dtype=np.int64)
    design = index % designs  # the design grid: point i has design i mod 4
    illuminance, shake = contract_draws(index)
    parameters = {name: values[design] for name, values in space.design_table.items()}
    parameters.update(illuminance_lux=illuminance, shake_deg_per_s=shake)
    result = evaluate(**parameters, threads=THREADS)
    kappa = blur_condition(parameters, result)
    epc = result.epc
    out = {name: [] for name in ("count", "mean", "std", "min", "max", "min_kappa",
                                 "max_kappa", "histogram", "histogram_below",
                                 "histogram_above", "below", "quantile_counts",
                                 "exact_quantiles")}
    out["points"] = np.bincount(design, minlength=designs)
    out["status_counts"] = np.bincount(design * len(Status) + result.status,
                                       minlength=designs * len(Status)).reshape(designs, -1)
    for g in range(designs):
        mine = (design == g) & np.isfinite(epc)
        values, kappas = epc[mine], kappa[mine]
        with np.errstate(divide="ignore"):
            t = np.log10(values)  # -inf for EPC 0 (blur unbounded): below every histogram
        out["count"].append(values.size)
        out["mean"].append(values.mean())
        out["std"].append(values.std())
        out["min"].append(values.min())
        out["max"].append(values.max())
        out["min_kappa"].append(kappas[np.argmin(values)])
        out["max_kappa"].append(kappas[np.argmax(values)])
        out["histogram"].append(np.histogram(t, bins=80, range=(3.0, 7.0))[0])
        out["histogram_below"].append(np.count_nonzero(t < 3.0))
        out["histogram_above"].append(np.count_nonzero(t >= 7.0))
        out["below"].append(np.count_nonzero(values < 2e6))
        bins = peer.QUANTILE_HISTOGRAM
        keys = (values.view(np.uint64) >> np.uint64(52 - bins.k)).astype(np.int64)
        slots = np.where(values > 0.0, np.clip(keys - bins.first_key + 1, 0, bins.bins + 1), 0)
        out["quantile_counts"].append(np.bincount(slots, minlength=bins.bins + 2))
        out["exact_quantiles"].append(np.quantile(values, peer.QUANTILES))
    return {name: np.asarray(value) for name, value in out.items()}


@pytest.fixture(scope="module")
def compiled():
    """The peer, compiled and its thread pool started on a few points: no timing includes
    the JIT."""
    peer.warm_up(THREADS)
    return peer


def check_against_numpy(got: dict, expected: dict, points: int) -> None:
    """The peer's reductions against numpy_scan's on the same points (see the module)."""
    for name in ("points", "status_counts", "count", "histogram", "histogram_below",
                 "histogram_above", "below", "quantile_counts"):
        np.testing.assert_array_equal(got[name], expected[name], err_msg=name)
    assert got["points"].sum() == points
    rtol = moments_rtol(points)
    np.testing.assert_allclose(got["mean"], expected["mean"], rtol=rtol, atol=0, err_msg="mean")
    np.testing.assert_allclose(got["std"], expected["std"], rtol=rtol, atol=0, err_msg="std")
    for name in ("min", "max"):
        # One point's EPC each: the per-point tolerance times that point's kappa.
        error = np.abs(got[name] / expected[name] - 1.0)
        assert np.all(error <= POINT_RTOL * expected[f"{name}_kappa"]), (name, error)
    np.testing.assert_array_equal(got["fraction_below"], expected["below"] / expected["count"])
    # Quantiles: read from the counts (equal above) by the rule of the package's streamed
    # Quantiles (its own function gives the same bits), and the exact sample quantile lies
    # within the bounds they state.
    bins = Quantiles().bin_layout  # the peer counts on the package's default bins
    assert (bins.first_key, bins.bins, bins.shift) == (peer.FINE_FIRST_KEY, peer.FINE_BINS,
                                                        52 - peer.FINE_K)
    state = {"counts": got["quantile_counts"], "min": got["min"], "max": got["max"]}
    package = _histogram_quantiles(bins, state, np.asarray(peer.QUANTILES))
    for name, value in zip(("quantiles", "quantiles_lower", "quantiles_upper"), package):
        np.testing.assert_array_equal(got[name], value, err_msg=name)
    assert np.all(got["quantiles_lower"] <= expected["exact_quantiles"])
    assert np.all(expected["exact_quantiles"] <= got["quantiles_upper"])
    assert np.all((got["quantiles_lower"] <= got["quantiles"])
                  & (got["quantiles"] <= got["quantiles_upper"]))


def test_philox_known_answers():
    """Random123's known-answer vectors for Philox4x32-10."""
    vectors = [((0, 0, 0, 0), (0, 0), (0x6627E8D5, 0xE169C58D, 0xBC57AC4C, 0x9B00DBD8)),
               ((0xFFFFFFFF,) * 4, (0xFFFFFFFF,) * 2,
                (0x408F276D, 0x41C83B0E, 0xA20BC7C6, 0x6D5451FD)),
               ((0x243F6A88, 0x85A308D3, 0x13198A2E, 0x03707344), (0xA4093822, 0x299F31D0),
                (0xD16CFE09, 0x94FDCCEB, 0x5001E420, 0x24126EA1))]
    for counter, key, expected in vectors:
        assert tuple(int(w) for w in peer.philox4x32_10(counter, key)) == expected


def test_uniforms_bit_for_bit():
    """The peer's uniforms are streams.uniforms' bits: 4096 indices (the first 2048, then both
    halves of the counter, up to 2^64 - 1) x three seeds x three streams."""
    rng = np.random.default_rng(7)
    index = np.concatenate([np.arange(2048, dtype=np.uint64),
                            np.array([2**32 - 1, 2**32, 2**32 + 1, 2**63, 2**64 - 1],
                                     dtype=np.uint64),
                            rng.integers(0, 2**64 - 1, 2043, dtype=np.uint64, endpoint=True)])
    for seed in (0, SEED, 2**64 - 1):
        for name in ("illuminance_lux", "shake_deg_per_s", "design"):
            assert peer.stream_id(name) == streams.stream_id(name)
            got = peer.uniforms(seed, peer.stream_id(name), index)
            expected = streams.uniforms(seed, streams.stream_id(name), index)
            np.testing.assert_array_equal(got.view(np.uint64), expected.view(np.uint64))


def test_ndtri_and_draws_match_the_contract():
    """AS 241 and the drawn values within DRAW_ULPS of the NumPy reference of the contract,
    over the central range and both tails (p down to 1e-300)."""
    p = streams.uniforms(SEED, 12345, np.arange(100_000))
    p = np.concatenate([p, [1e-300, 1e-20, 2.0**-53, 1.0 - 2.0**-53, 0.075, 0.925, 0.5]])
    assert ulps(peer.ndtri(p), streams.ndtri(p)).max() <= DRAW_ULPS
    index = np.arange(4096)
    got, expected = peer.draws(SEED, index), contract_draws(index)
    for name, g, e in zip(("illuminance", "shake"), got, expected):
        assert ulps(g, e).max() <= DRAW_ULPS, name


def test_scan_matches_numpy(compiled):
    """2^17 points: integer results equal, float ones within their tolerances (module)."""
    got = compiled.scan(CHECK_POINTS, SEED, THREADS)
    check_against_numpy(got, numpy_scan(CHECK_POINTS), CHECK_POINTS)


def test_scan_does_not_depend_on_threads(compiled):
    """One thread and two: the same counts, min and max; mean and std within rounding."""
    one = compiled.scan(1 << 15, SEED, 1)
    two = compiled.scan(1 << 15, SEED, min(2, numba.config.NUMBA_NUM_THREADS))
    for name in ("status_counts", "count", "min", "max", "histogram", "quantile_counts",
                 "below", "quantiles"):
        np.testing.assert_array_equal(one[name], two[name], err_msg=name)
    for name in ("mean", "std"):
        np.testing.assert_allclose(one[name], two[name], rtol=moments_rtol(1 << 15, 1))


@pytest.mark.parametrize("same_algorithm", [False, True], ids=["halley", "core algorithm"])
@pytest.mark.benchmark(group=GROUP)
def test_numba_scan_peer(benchmark, compiled, same_algorithm):
    """The peer's scan of POINTS points on THREADS threads: draws, evaluation and the
    reductions in one prange loop. f50 by the Numba peer's Halley iteration, or by the core's
    own algorithm (its accurate start: about one MTF evaluation a point)."""
    threads = min(THREADS, numba.config.NUMBA_NUM_THREADS)
    # No "points" key: report.py then lists the scan group's medians side by side.
    benchmark.extra_info.update(peer="numba_scan", scan_points=POINTS, threads=threads,
                                same_algorithm=same_algorithm)
    got = benchmark.pedantic(compiled.scan, args=(POINTS, SEED, threads),
                             kwargs={"same_algorithm": same_algorithm}, rounds=3,
                             iterations=1)
    stats = getattr(benchmark, "stats", None)
    if stats:
        benchmark.extra_info["scan_points_per_s"] = POINTS / stats.stats.median
    check_against_numpy(got, numpy_scan(POINTS), POINTS)
