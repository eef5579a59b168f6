"""Standard errors from replicates and the stopping rules (epc_fast/scan/replicates.py): the
pooled statistics are the statistics of every point, the errors are honest (coverage against
a reference 1024 times larger), and a scan stops at the first power of two where its targets
hold, with the same numbers as a scan of that many points."""

import numpy as np
import pytest

from epc_fast.scan import (FractionBelow, Histogram, LogNormal, LogUniform, Quantiles, Space,
                           Summary, TopK, Uniform, run)
from epc_fast.scan.reductions.targets import Target
from helpers.scan import SPACE, assert_same_numbers

#: A smooth space of five random parameters, one design: its mean, median and fraction below
#: are the integrals the error bars are tested on.
SMOOTH = Space(illuminance_lux=LogUniform(10, 1e4), pixel_pitch_um=Uniform(1.0, 2.5),
               f_number=Uniform(1.8, 2.8), focal_length_mm=4.0, pixel_count=12e6,
               shake_deg_per_s=LogNormal(2.0, 0.5), read_noise_e=Uniform(0.5, 3.0))
REDUCTIONS = {"summary": Summary(), "median": Quantiles((0.5,)),
              "below": FractionBelow(2e6)}


def _statistics(result) -> dict:
    return {"mean": (result["summary"].mean[0], result["summary"].mean_error[0]),
            "median": (result["median"].estimate[0, 0], result["median"].standard_error[0, 0]),
            "below": (result["below"].fraction[0], result["below"].standard_error[0])}


@pytest.fixture(scope="module")
def reference():
    """The statistics of 2^22 Sobol' points: errors ~1000x below those of the runs tested."""
    result = run(SMOOTH, 1 << 22, seed=123456, sampling="sobol", replicates=16,
                 reductions=REDUCTIONS, progress=False)
    return {name: value for name, (value, _) in _statistics(result).items()}


@pytest.mark.parametrize("sampling, replicates", [("sobol", 16), ("monte_carlo", 1),
                                                  ("monte_carlo", 16)])
def test_the_true_error_lies_within_two_standard_errors_in_at_least_90_of_100_runs(
        reference, sampling, replicates):
    inside = {name: 0 for name in reference}
    for seed in range(100):
        result = run(SMOOTH, 1 << 12, seed=seed, sampling=sampling, replicates=replicates,
                     reductions=REDUCTIONS, progress=False)
        for name, (value, error) in _statistics(result).items():
            assert np.isfinite(error) and error > 0, (name, seed)
            inside[name] += abs(value - reference[name]) <= 2 * error
    # 2 standard errors hold ~94% of a t-distribution with 15 degrees of freedom, ~95% of a
    # normal one
    assert all(count >= 90 for count in inside.values()), inside


def test_sobol_errors_are_smaller_than_monte_carlos_at_equal_points():
    errors = {}
    for sampling in ("sobol", "monte_carlo"):
        result = run(SMOOTH, 1 << 18, seed=3, sampling=sampling, replicates=16,
                     reductions=REDUCTIONS, progress=False)
        errors[sampling] = {name: e for name, (_, e) in _statistics(result).items()}
    # measured: the mean's 40-70x smaller, the median's and the fraction's 3-5x
    assert errors["sobol"]["mean"] < errors["monte_carlo"]["mean"] / 10
    assert errors["sobol"]["below"] < errors["monte_carlo"]["below"] / 2
    assert errors["sobol"]["median"] < errors["monte_carlo"]["median"] / 2


def test_pooled_replicates_give_the_statistics_of_every_point():
    reductions = {"summary": Summary(by="design"),
                  "q": Quantiles((0.05, 0.5), by="design", exact_up_to=0),
                  "exact": Quantiles((0.05, 0.5), by="design"),
                  "below": FractionBelow(2e6, by=("design", "read_noise_e"))}
    one = run(SPACE, 3 << 16, seed=4, reductions=reductions, progress=False)
    many = run(SPACE, 3 << 16, seed=4, reductions=reductions, replicates=16, progress=False)
    for name in ("points", "status_counts", "count", "min", "max"):
        assert np.array_equal(getattr(one["summary"], name), getattr(many["summary"], name))
    # the same values merged in another order: the sums' rounding
    np.testing.assert_allclose(many["summary"].mean, one["summary"].mean, rtol=1e-13)
    np.testing.assert_allclose(many["summary"].std, one["summary"].std, rtol=1e-12)
    np.testing.assert_allclose(many["summary"].mean_error, one["summary"].mean_error,
                               rtol=1e-12)
    for name in ("q", "exact"):
        assert np.array_equal(many[name].estimate, one[name].estimate)
    assert np.array_equal(many["below"].fraction, one["below"].fraction)
    assert np.array_equal(many["below"].standard_error, one["below"].standard_error)
    assert one["summary"].std_error is None and np.all(many["summary"].std_error > 0)


def test_monte_carlo_errors_are_their_own_formulas_in_one_replicate():
    result = run(SMOOTH, 1 << 16, seed=2, reductions=REDUCTIONS, progress=False)
    summary, below = result["summary"], result["below"]
    assert summary.mean_error[0] == summary.std[0] / np.sqrt(summary.count[0])
    p = below.fraction[0]
    assert below.standard_error[0] == np.sqrt(p * (1 - p) / below.count[0])
    # the order statistics' error agrees with the 16 replicates' spread over the same points
    # (which scatters by ~1 / sqrt(2 x 15), 18%, about it)
    replicated = run(SMOOTH, 1 << 16, seed=2, reductions=REDUCTIONS, replicates=16,
                     progress=False)
    ratio = result["median"].standard_error[0, 0] / replicated["median"].standard_error[0, 0]
    assert 0.6 < ratio < 1.6, ratio


def test_a_sobol_scan_in_one_replicate_says_it_cannot_tell_its_error():
    result = run(SMOOTH, 1 << 16, seed=2, sampling="sobol", replicates=1,
                 reductions=REDUCTIONS, progress=False)
    assert all(np.isnan(e) for _, e in _statistics(result).values())


# -- stopping rules ----------------------------------------------------------------------------

def _targeted(target, points=1 << 22, **kwargs):
    reductions = {"summary": Summary(target=target),
                  "q": Quantiles((0.5,), exact_up_to=0), "below": FractionBelow(2e6)}
    return run(SMOOTH, points, seed=11, sampling="sobol", replicates=16,
               reductions=reductions, progress=False, **kwargs)


def test_a_scan_stops_at_the_first_power_of_two_where_its_target_holds():
    result = _targeted({"relative": 2e-5})
    assert result.points < result.points_requested and not result.unmet_targets
    per_replicate = result.points // 16
    assert per_replicate & (per_replicate - 1) == 0
    summary = result["summary"]
    assert summary.mean_error[0] <= 2e-5 * summary.mean[0]
    # the same numbers as a scan of that many points, and half as many fall short
    plain = _targeted(None, points=result.points)
    assert_same_numbers(plain, result)
    half = _targeted(None, points=result.points // 2)["summary"]
    assert half.mean_error[0] > 2e-5 * half.mean[0]
    # a looser target stops no later
    assert _targeted({"relative": 1e-3}).points <= result.points


def test_a_target_not_met_at_the_cap_is_named():
    result = _targeted({"standard_error": 1e-9}, points=1 << 17)
    assert result.points == 1 << 17 and not result.partial
    assert len(result.unmet_targets) == 1
    assert result.unmet_targets[0].startswith("summary: mean has standard error")
    assert "target standard error <= 1e-09" in result.unmet_targets[0]


def test_every_target_must_hold_and_each_group_counts():
    reductions = {"summary": Summary(by="design", target={"relative": 1e-3}),
                  "below": FractionBelow(2e6, by="design", target={"standard_error": 1e-9})}
    result = run(SPACE, 8 * 16 * 2**11, seed=1, sampling="sobol", reductions=reductions,
                 progress=False)
    assert [line.split(":")[0] for line in result.unmet_targets] == ["below"]
    assert "(design=" in result.unmet_targets[0]


def test_a_monte_carlo_scan_stops_by_its_targets_too():
    reductions = {"summary": Summary(target={"relative": 5e-3})}
    result = run(SMOOTH, 1 << 24, seed=1, replicates=8, reductions=reductions, progress=False)
    assert result.points < 1 << 24 and not result.unmet_targets
    summary = result["summary"]
    assert summary.mean_error[0] <= 5e-3 * summary.mean[0]


@pytest.mark.parametrize("target, error, match", [
    ({"relative": 0}, ValueError, "relative must be a finite number > 0, got 0"),
    ({"standard_error": float("nan")}, ValueError, "standard_error must be a finite number"),
    ({"relative": -1e-3}, ValueError, "relative must be a finite number > 0"),
    ({"relative": "1e-3"}, TypeError, "relative must be a number"),
    ({}, ValueError, "gives standard_error, relative or both"),
    ({"absolute": 1.0}, ValueError, "unknown key.s. absolute"),
    (1e-3, TypeError, "target must be a mapping")])
def test_a_bad_target_is_refused_naming_it(target, error, match):
    with pytest.raises(error, match=match):
        Summary(target=target)


def test_a_target_the_scan_cannot_check_is_refused_before_the_first_point():
    with pytest.raises(ValueError, match="a target needs replicates >= 2"):
        run(SMOOTH, 1 << 16, reductions={"s": Summary(target={"relative": 1e-3})},
            progress=False)
    histogram = Histogram(1, 1e8)
    object.__setattr__(histogram, "target", Target(relative=1e-3))
    with pytest.raises(ValueError, match="a Histogram takes no target"):
        run(SMOOTH, 1 << 16, replicates=4, reductions={"h": histogram, "best": TopK(2)},
            progress=False)


def test_a_targeted_scan_on_dask_gives_the_local_numbers():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        on_cluster = _targeted({"relative": 2e-5}, client=client)
    local = _targeted({"relative": 2e-5})
    assert on_cluster.points == local.points < local.points_requested
    assert_same_numbers(on_cluster, local)
