"""Each reduction, streamed chunk by chunk, against NumPy on the full arrays of the same points:
the core's fused pass on the points it forms, and the NumPy path on the points NumPy draws.

The space has every status: a normal hand shake goes negative (INVALID) and one PRNU in five
caps the SNR below the target (UNREACHABLE), so the reductions see NaN EPC as well.
"""

import math

import numpy as np
import pytest

from epc_fast import Status, _core, evaluate
from epc_fast.presets import HIGH_TIER
from epc_fast.scan.running.core_plan import CorePlan
from epc_fast.scan.reductions.histograms import _OctaveBins
from epc_fast.scan import (BLOCK_POINTS, Binned, Choice, FractionBelow, Grid, Histogram,
                           LogUniform, Normal, Quantiles, Space, Summary, TopK, run)

SEED = 11
N = 5 * BLOCK_POINTS + 4321
SPACE = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
              shake_deg_per_s=Normal(4.0, 3.0), prnu=Choice((0.0, 0.05), weights=(0.8, 0.2)))
DESIGNS = range(len(HIGH_TIER))


@pytest.fixture(scope="module", params=["core", "numpy"])
def backend(request):
    return request.param


@pytest.fixture(scope="module")
def full(backend):
    """The scan's points, as the backend forms them, and their results, whole."""
    if backend == "core":
        points = CorePlan(SPACE, SEED).points(0, N)
    else:
        points = SPACE.points(SEED, 0, N)
    return points, evaluate(**points.parameters)


def _scan(backend, reduction):
    return run(SPACE, N, seed=SEED, reductions={"r": reduction}, chunk_points=2 * BLOCK_POINTS,
               progress=False, backend=backend)["r"]


def _finite_epc_of(full, design):
    points, result = full
    return result.epc[(points.indices["design"] == design) & np.isfinite(result.epc)]


def test_the_space_gives_every_status_but_blur_unbounded(backend, full):
    assert np.count_nonzero(np.bincount(full[1].status, minlength=4)[:3]) == 3


def test_summary_matches_numpy_per_design(backend, full):
    points, result = full
    summary = _scan(backend, Summary(by="design"))
    assert summary.labels == {"design": [d.name for d in HIGH_TIER]}
    for g in DESIGNS:
        epc = _finite_epc_of(full, g)
        in_design = points.indices["design"] == g
        assert np.array_equal(summary.status_counts[g],
                              np.bincount(result.status[in_design], minlength=len(Status)))
        assert summary.count[g] == epc.size
        # Block-wise Chan merging and NumPy's pairwise sum round differently: ~1e-16 per
        # addition over ~10^5 values stays far inside 1e-12.
        assert summary.mean[g] == pytest.approx(epc.mean(), rel=1e-12)
        # Both are two-pass (deviations from a mean), so they agree nearly as well.
        assert summary.std[g] == pytest.approx(epc.std(), rel=1e-11)
        assert summary.min[g] == epc.min() and summary.max[g] == epc.max()


@pytest.mark.parametrize("share", ["share_diffraction", "share_pixel", "share_motion"])
def test_summaries_and_quantiles_of_a_share_match_numpy_per_design(backend, full, share):
    """A reduction of= an MTF-loss share reads evaluate's share at each point (docs/limits.md):
    its finite values are the OK points' and those whose blur is unbounded (share 0 or 1)."""
    points, _ = full
    values = getattr(evaluate(**points.parameters, outputs=(share,)), share)
    summary = _scan(backend, Summary(of=share, by="design"))
    median = _scan(backend, Quantiles((0.5,), of=share, by="design"))
    for g in DESIGNS:
        v = values[(points.indices["design"] == g) & np.isfinite(values)]
        assert summary.count[g] == v.size
        # the same rounding budget as the EPC summary above
        assert summary.mean[g] == pytest.approx(v.mean(), rel=1e-12)
        assert summary.min[g] == v.min() and summary.max[g] == v.max()
        assert median.exact and median.estimate[g, 0] == np.quantile(v, 0.5)


def test_histogram_matches_numpy_histogram_per_design(backend, full):
    points, result = full
    histogram = _scan(backend, Histogram(1e3, 1e7, 80, by="design"))
    for g in DESIGNS:
        epc = _finite_epc_of(full, g)
        expected, edges = np.histogram(np.log10(epc), bins=80, range=(3.0, 7.0))
        assert np.array_equal(histogram.counts[g], expected)
        assert histogram.below[g] == np.count_nonzero(epc < 1e3)
        assert histogram.above[g] == np.count_nonzero(epc >= 1e7)
        in_design = points.indices["design"] == g
        assert histogram.nonfinite[g] == np.count_nonzero(~np.isfinite(result.epc[in_design]))
    np.testing.assert_allclose(histogram.edges, 10.0 ** edges, rtol=1e-15)


def test_exact_quantiles_equal_numpy_quantile(backend, full):
    q = (0.0, 0.05, 0.5, 0.95, 1.0)
    quantiles = _scan(backend, Quantiles(q, by="design"))
    assert quantiles.exact
    for g in DESIGNS:
        assert np.array_equal(quantiles.estimate[g], np.quantile(_finite_epc_of(full, g), q))


def test_streamed_quantiles_bound_the_exact_ones_within_their_stated_error(backend, full):
    q = (0.01, 0.05, 0.5, 0.95, 0.99)
    reduction = Quantiles(q, by="design", exact_up_to=0)
    quantiles = _scan(backend, reduction)
    assert not quantiles.exact
    # 1000 bins a decade asked (0.23%): 2^9 an octave, 0.195%, the least power of 2 as fine
    resolution = quantiles.relative_resolution
    assert resolution == 2.0 ** -9
    bins = reduction.bin_layout
    edges = np.concatenate(([-np.inf], bins.edges, [np.inf]))
    for g in DESIGNS:
        values = np.sort(_finite_epc_of(full, g))
        exact = np.quantile(values, q)
        # the order statistics around each quantile, and the bins that hold them
        rank = np.asarray(q) * (values.size - 1)
        x_low = values[np.floor(rank).astype(int)]
        x_high = values[np.minimum(np.floor(rank).astype(int) + 1, values.size - 1)]
        low, high = values[0], values[-1]
        # the bounds are those bins' outer edges (exact doubles), clipped to the group's range
        assert np.array_equal(quantiles.lower[g], np.clip(edges[bins.slot(x_low)], low, high))
        assert np.array_equal(quantiles.upper[g],
                              np.clip(edges[bins.slot(x_high) + 1], low, high))
        assert np.all((quantiles.lower[g] <= exact) & (exact <= quantiles.upper[g]))
        assert np.all((quantiles.lower[g] <= quantiles.estimate[g])
                      & (quantiles.estimate[g] <= quantiles.upper[g]))
        # each bound within one bin of its order statistic: a bin is at most 2^-9 wide (the
        # products round once: 1e-15)
        assert np.all(x_low <= quantiles.lower[g] * (1 + resolution) * (1 + 1e-15))
        assert np.all(quantiles.upper[g] <= x_high * (1 + resolution) * (1 + 1e-15))


@pytest.mark.parametrize("bins_per_decade", [1, 3, 10, 100, 200, 1000, 10_000, 10**6])
def test_octave_bins_are_as_fine_as_asked_and_no_finer(bins_per_decade):
    bins = _OctaveBins.covering(1.0, 1e10, bins_per_decade)
    k = 52 - bins.shift
    asked = 10.0 ** (1.0 / bins_per_decade) - 1.0
    assert bins.relative_resolution == 2.0 ** -k <= asked
    assert k == 0 or 2.0 ** -(k - 1) > asked
    edges = bins.edges
    assert edges.size == bins.bins + 1 and np.all(np.diff(edges) > 0)
    assert edges[0] <= 1.0 < edges[1] and edges[-2] <= 1e10 < edges[-1]
    # each bin at most 2^-k wide, relative: the difference of two edges within a factor 2 of
    # each other is exact, and so is a product by a power of 2
    assert np.all(np.diff(edges) <= edges[:-1] * 2.0 ** -k)


def _octave_test_values(bins: _OctaveBins) -> np.ndarray:
    """Every edge and the doubles either side of it, values drawn over and beyond the range,
    and the values the slots single out: 0, negatives, subnormals, the largest double, inf."""
    edges = bins.edges
    rng = np.random.default_rng(5)
    drawn = 10.0 ** rng.uniform(-3.0, 13.0, 100_000)
    special = np.array([0.0, -0.0, -1.0, -np.inf, 5e-324, 2.2e-308, 1.7976931348623157e308,
                        np.inf, 1.0, 1e10])
    return np.concatenate([edges, np.nextafter(edges, 0.0), np.nextafter(edges, np.inf),
                           drawn, special])


@pytest.mark.parametrize("bins_per_decade", [1, 200, 1000, 10**6])
def test_octave_slots_put_every_value_in_the_bin_that_holds_it(bins_per_decade):
    bins = _OctaveBins.covering(1.0, 1e10, bins_per_decade)
    values = _octave_test_values(bins)
    slot = bins.slot(values)
    edges = bins.edges
    inside = (slot >= 1) & (slot <= bins.bins)
    assert np.all(edges[slot[inside] - 1] <= values[inside])
    assert np.all(values[inside] < edges[slot[inside]])
    assert np.array_equal(slot == 0, ~(values >= edges[0]))
    assert np.array_equal(slot == bins.bins + 1, values >= edges[-1])
    # the fused pass bins every value alike, to the slot
    core = _core.testing.octave_slots(values, bins.first_key, bins.bins, bins.shift)
    assert np.array_equal(core, slot)
    assert _core.testing.octave_slots(np.array([np.nan, -np.nan]), bins.first_key, bins.bins,
                                      bins.shift).tolist() == [0, 0]
    assert bins.slot(np.array([np.nan])).tolist() == [0]


@pytest.mark.parametrize("first_key, bins, shift", [(0, 10, 11), (0, 10, 53), (0, 0, 43),
                                                    (-1, 10, 43), (2**21 - 5, 10, 43)])
def test_octave_bins_the_core_cannot_hold_are_refused(first_key, bins, shift):
    # keys must stay below 2^52 (exact doubles) and below 2^(64 - shift) (what a double gives)
    with pytest.raises(ValueError, match="octave bins"):
        _core.testing.octave_slots(np.ones(3), first_key, bins, shift)


def test_fraction_below_matches_numpy_with_its_binomial_error(backend, full):
    fraction = _scan(backend, FractionBelow(2e6, by="design"))
    for g in DESIGNS:
        epc = _finite_epc_of(full, g)
        p = np.mean(epc < 2e6)
        assert fraction.below[g] == np.count_nonzero(epc < 2e6)
        assert fraction.fraction[g] == pytest.approx(p, rel=1e-15)
        assert fraction.standard_error[g] == pytest.approx(math.sqrt(p * (1 - p) / epc.size),
                                                           rel=1e-14)


@pytest.mark.parametrize("largest", [True, False])
def test_top_k_are_the_first_k_of_a_full_sort(backend, full, largest):
    points, result = full
    top = _scan(backend, TopK(7, largest=largest))
    finite = np.flatnonzero(np.isfinite(result.epc))
    value = result.epc[finite]
    order = finite[np.lexsort((finite, -value if largest else value))][:7]
    assert np.array_equal(top.index, order)
    assert np.array_equal(top.value, result.epc[order])
    assert top.parameters["design"] == [HIGH_TIER[i].name for i in points.indices["design"][order]]
    for name in ("illuminance_lux", "shake_deg_per_s", "prnu", "pixel_pitch_um"):
        assert np.array_equal(top.parameters[name], points.parameters[name][order]), name


def test_top_k_breaks_ties_by_the_lower_point_index_for_any_chunking():
    space = Space(design=HIGH_TIER, illuminance_lux=Grid((100.0, 1000.0)))
    best = {chunk: run(space, 3 * BLOCK_POINTS, reductions={"top": TopK(3)},
                       chunk_points=chunk, progress=False)["top"]
            for chunk in (BLOCK_POINTS, 3 * BLOCK_POINTS)}
    # The best of the eight grid cells recurs every 8 points with exactly the same EPC.
    cells = space.points(0, 0, 8)
    best_cell = int(np.argmax(evaluate(**cells.parameters).epc))
    for top in best.values():
        assert np.array_equal(top.index, [best_cell, best_cell + 8, best_cell + 16])
        assert top.value[0] == top.value[1] == top.value[2]


def test_groups_by_a_parameter_the_designs_give(backend, full):
    points, result = full
    fraction = _scan(backend, FractionBelow(2e6, by="pixel_pitch_um"))
    assert fraction.labels == {"pixel_pitch_um": [1.4, 1.75, 2.2, 2.8]}
    pitch = points.parameters["pixel_pitch_um"]
    finite = np.isfinite(result.epc)
    for g, value in enumerate(fraction.labels["pixel_pitch_um"]):
        assert fraction.count[g] == np.count_nonzero(finite & (pitch == value))


@pytest.mark.parametrize("edges", [
    tuple(np.geomspace(10, 1e5, 9)),          # equal in log10: found arithmetically
    (10.0, 50.0, 100.0, 2000.0, 30000.0, 1e5),  # uneven: found by a search
])
def test_groups_by_design_and_binned_illuminance(backend, full, edges):
    points, result = full
    summary = _scan(backend, Summary(by=("design", Binned("illuminance_lux", edges))))
    bins = len(edges) - 1
    assert summary.labels["illuminance_lux low"][:bins] == list(edges[:-1])
    lux_bin = np.searchsorted(edges[1:-1], points.parameters["illuminance_lux"], side="right")
    expected = np.bincount(points.indices["design"] * bins + lux_bin, minlength=4 * bins)
    assert np.array_equal(summary.points, expected)


def test_a_quantile_is_read_by_its_probability_and_group_label():
    from epc_fast.presets import HIGH_TIER
    from epc_fast.scan import LogUniform, Quantiles, Space, run

    space = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10.0, 1e5))
    result = run(space, 4000, progress=False, reductions={
        "q": Quantiles((0.05, 0.5), by="design")})["q"]
    names = [d.name for d in HIGH_TIER]
    assert result.quantile(0.5) == dict(zip(names, result.estimate[:, 1]))
    assert result.quantile(0.05, design=names[3]) == result.estimate[3, 0]
    with pytest.raises(ValueError, match=r"q=0\.25 is not one of .*\[0\.05, 0\.5\]"):
        result.quantile(0.25)
    with pytest.raises(ValueError, match="pitch: not a label column"):
        result.quantile(0.5, pitch=1.4)
    with pytest.raises(ValueError, match="no group match"):
        result.quantile(0.5, design="none")
