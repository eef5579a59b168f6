"""The scan's distributions and discrete axes draw what they say, as a scan draws them."""

import math

import numpy as np
import pytest
from mpmath import mp
from scipy import stats

from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (Choice, Empirical, Grid, LogNormal, LogUniform, Normal, Space,
                           Truncated, Uniform)
from epc_fast.scan.sampling import streams

N = 10**6
SEED = 20_240_611
#: Sample moments are checked to 5 standard errors: a false alarm is about a 1-in-10^6 event.
SIGMAS = 5.0
#: Kolmogorov-Smirnov and chi-square p-values must exceed this: a correct draw fails 1 time in
#: 10^4.
P_MIN = 1e-4


def _space_draws(axis, n=N, seed=SEED, name="read_noise_e"):
    """Points 0 .. n - 1 of a scan whose parameter ``name`` is ``axis``: its values, or its
    value indices for a Choice. A law reaching below 0 is drawn for ``field_angle_deg``, whose
    domain holds negative values."""
    points = Space(design=HIGH_TIER, illuminance_lux=100.0, **{name: axis}).points(seed, 0, n)
    if isinstance(axis, (Choice, Grid)):
        return points.indices[name]
    return points.parameters[name]


def _uniforms(n=N, seed=SEED, name="read_noise_e"):
    """The uniforms behind :func:`_space_draws`."""
    return streams.uniforms(seed, streams.stream_id(name), np.arange(n))


def _assert_quantiles(t, cdf, pdf, u, spec):
    """Each draw is the quantile at its uniform: its CDF is u (1 - u where the contract mirrors
    the quantile).

    ``t`` are the draws in the variable the transform computes as ``a + (t - a)`` (the value,
    or its log for the exp kinds), ``cdf`` and ``pdf`` the law's in that variable."""
    # t is a few roundings of the larger of a and t - a from its exact quantile, which moves
    # the probability by pdf(t) (|a| + |t - a|) per ulp; the CDF adds a few ulp of its own:
    # eight ulp of each bound the sum.
    slope = np.max(pdf(t) * (abs(spec["a"]) + np.abs(t - spec["a"])))
    tolerance = 8.0 * 2.0**-52 * (1.0 + slope)
    expected = 1.0 - u if spec["mirror"] else u
    assert np.max(np.abs(cdf(t) - expected)) <= tolerance


def _assert_moments(draws, mean, var, mu4):
    """The sample mean and variance within SIGMAS standard errors of ``mean`` and ``var``: the
    mean's is sqrt(var / n), the variance's sqrt((mu4 - var^2) / n), mu4 the fourth central
    moment."""
    n = draws.size
    assert abs(draws.mean() - mean) <= SIGMAS * math.sqrt(var / n)
    assert abs(draws.var() - var) <= SIGMAS * math.sqrt((mu4 - var**2) / n)


def _assert_follows(draws, expected):
    """``draws`` pass the KS test against the scipy distribution ``expected`` and have its first
    two moments."""
    assert stats.kstest(draws, expected.cdf).pvalue > P_MIN
    mean, var, kurtosis = (float(x) for x in expected.stats(moments="mvk"))
    _assert_moments(draws, mean, var, (kurtosis + 3.0) * var**2)


def _truncnorm(mean, std, low, high):
    return stats.truncnorm((low - mean) / std, (high - mean) / std, loc=mean, scale=std)


CONTINUOUS = [
    (Uniform(2.0, 5.0), stats.uniform(2.0, 3.0)),
    (LogUniform(10.0, 1e5), stats.loguniform(10.0, 1e5)),
    (Normal(4.0, 1.5), stats.norm(4.0, 1.5)),
    (LogNormal(median=4.39, sigma=0.5), stats.lognorm(0.5, scale=4.39)),
    (Truncated(Uniform(2.0, 5.0), 3.0, 7.0), stats.uniform(3.0, 2.0)),
    (Truncated(LogUniform(10.0, 1e5), 1.0, 1e3), stats.loguniform(10.0, 1e3)),
    (Truncated(Normal(4.0, 3.0), 0.0, 6.0), _truncnorm(4.0, 3.0, 0.0, 6.0)),
    (Truncated(Normal(4.0, 3.0), 5.0, math.inf), _truncnorm(4.0, 3.0, 5.0, math.inf)),
    # The farthest tails a truncation may hold (MIN_TRUNCATED_PROBABILITY): 3.5 to 4.5 std,
    # the upper one drawn through the mirrored quantile.
    (Truncated(Normal(4.0, 1.5), 4.0 + 3.5 * 1.5, 4.0 + 4.5 * 1.5),
     _truncnorm(4.0, 1.5, 4.0 + 3.5 * 1.5, 4.0 + 4.5 * 1.5)),
    (Truncated(Normal(4.0, 1.5), 4.0 - 4.5 * 1.5, 4.0 - 3.5 * 1.5),
     _truncnorm(4.0, 1.5, 4.0 - 4.5 * 1.5, 4.0 - 3.5 * 1.5)),
]


@pytest.mark.parametrize("case", range(len(CONTINUOUS)), ids=[repr(d) for d, _ in CONTINUOUS])
def test_a_continuous_distribution_draws_its_law(case):
    distribution, expected = CONTINUOUS[case]
    low, high = expected.support()
    name = "field_angle_deg" if high < 0 else "read_noise_e"
    # A seed per case: each law is tested on its own sample.
    draws = _space_draws(distribution, seed=SEED + case, name=name)
    assert draws.min() >= low and draws.max() <= high
    _assert_follows(draws, expected)
    spec = distribution.stream_spec()
    u = _uniforms(seed=SEED + case, name=name)
    if spec["kind"] in ("exp_affine", "lognormal"):
        # In t = log x: F(exp t), and the density exp(t) f(exp t).
        _assert_quantiles(np.log(draws), lambda t: expected.cdf(np.exp(t)),
                          lambda t: np.exp(t) * expected.pdf(np.exp(t)), u, spec)
    else:
        _assert_quantiles(draws, expected.cdf, expected.pdf, u, spec)


def _truncated_lognormal_moments(median, sigma, low, high):
    """Mean, variance and fourth central moment of LogNormal(median, sigma) on [low, high]:
    E[X^k] = exp(k mu + k^2 sigma^2 / 2) (Phi(b - k sigma) - Phi(a - k sigma)) / (Phi(b) -
    Phi(a)), a and b the bounds' z-scores, at 40 digits (the central moments cancel)."""
    with mp.workdps(40):
        mu = mp.log(median)
        a = (mp.log(low) - mu) / sigma if low > 0 else -mp.inf
        b = (mp.log(high) - mu) / sigma if high < math.inf else mp.inf
        mass = mp.ncdf(b) - mp.ncdf(a)
        raw = [mp.exp(k * mu + k * k * sigma**2 / 2) * (mp.ncdf(b - k * sigma)
                                                        - mp.ncdf(a - k * sigma)) / mass
               for k in range(5)]
        mean = raw[1]
        var = raw[2] - mean**2
        mu4 = raw[4] - 4 * mean * raw[3] + 6 * mean**2 * raw[2] - 3 * mean**4
        return float(mean), float(var), float(mu4)


@pytest.mark.parametrize("low, high, seed", [(2.0, 8.0, 101),
                                             (4.39 * math.exp(0.5 * 3.5), math.inf, 102),
                                             (0.0, 4.39 * math.exp(-0.5 * 3.5), 103)])
def test_a_truncated_lognormal_draws_its_law(low, high, seed):
    median, sigma = 4.39, 0.5
    distribution = Truncated(LogNormal(median, sigma), low, high)
    draws = _space_draws(distribution, seed=seed)
    assert draws.min() >= low and draws.max() <= high
    # KS is invariant under the increasing log: log(draws) against the truncated normal.
    log_low = math.log(low) if low > 0 else -math.inf
    law = _truncnorm(math.log(median), sigma, log_low, math.log(high))
    assert stats.kstest(np.log(draws), law.cdf).pvalue > P_MIN
    _assert_moments(draws, *_truncated_lognormal_moments(median, sigma, low, high))
    _assert_quantiles(np.log(draws), law.cdf, law.pdf, _uniforms(seed=seed),
                      distribution.stream_spec())


def _assert_frequencies(indices, probabilities):
    """Value indices drawn with ``probabilities``: none where it is 0, and the others' counts
    pass the chi-square test."""
    probabilities = np.asarray(probabilities, dtype=np.float64)
    counts = np.bincount(indices, minlength=probabilities.size)
    assert counts.size == probabilities.size
    assert np.all(counts[probabilities == 0.0] == 0)
    drawn = probabilities > 0.0
    assert stats.chisquare(counts[drawn], indices.size * probabilities[drawn]).pvalue > P_MIN


def test_empirical_draws_each_sample_equally_often():
    samples = np.array([8.0, 1.0, 2.0, 4.0, 2.5, -3.0, 0.5])
    draws = _space_draws(Empirical(samples), seed=201, name="field_angle_deg")
    # KS needs a continuous law: a discrete one is tested by its frequencies.
    _assert_frequencies(np.searchsorted(np.sort(samples), draws), np.full(7, 1 / 7))
    mean = samples.mean()
    _assert_moments(draws, mean, np.mean((samples - mean) ** 2), np.mean((samples - mean) ** 4))


def test_truncated_empirical_draws_the_samples_inside():
    samples = np.array([8.0, 1.0, 2.0, 4.0, 2.5, -3.0, 0.5])
    draws = _space_draws(Truncated(Empirical(samples), 1.0, 4.0), seed=202)
    inside = np.array([1.0, 2.0, 2.5, 4.0])
    _assert_frequencies(np.searchsorted(inside, draws), np.full(4, 1 / 4))
    assert set(np.unique(draws)) == set(inside)
    mean = inside.mean()
    _assert_moments(draws, mean, np.mean((inside - mean) ** 2), np.mean((inside - mean) ** 4))


@pytest.mark.parametrize("weights, seed", [(None, 301), ((3, 0, 1, 2.5), 302),
                                           ((0, 1, 1, 0), 303)])
def test_a_choice_draws_its_weights(weights, seed):
    choice = Choice((10.0, 20.0, 30.0, 40.0), weights=weights)
    probabilities = np.full(4, 0.25) if weights is None else np.divide(weights, sum(weights))
    _assert_frequencies(_space_draws(choice, seed=seed), probabilities)


def test_a_choice_indexes_uniforms_by_the_cumulative_weights():
    choice = Choice((10.0, 20.0, 30.0), weights=(3, 0, 1))
    spec = choice.stream_spec()
    assert spec["n"] == 3 and spec["cumulative"].tolist() == [0.75, 0.75]
    # c[j] <= u counts: at u = 0.75 both cumulative weights are at or below u.
    u = np.array([2.0**-53, 0.75 - 2.0**-52, 0.75, 1.0 - 2.0**-53])
    assert choice.indices_from_uniform(u).tolist() == [0, 0, 2, 2]
    plain = Choice((1.0, 2.0, 3.0))
    assert plain.stream_spec() == {"cumulative": None, "n": 3}
    assert plain.indices_from_uniform([2.0**-53, 1 / 3, 2 / 3, 1.0 - 2.0**-53]).tolist() \
        == [0, 1, 2, 2]
    # A zero last weight puts c[n - 2] at exactly 1, above every uniform.
    assert Choice((1.0, 2.0), weights=(0.1, 0.0)).stream_spec()["cumulative"].tolist() == [1.0]


def test_a_grid_visits_each_value_equally_often():
    draws = _space_draws(Grid((0.0, 1.0, 2.0)), n=3 * 1000)
    # No draw: exactly n / 3 points per value, in turn.
    assert np.array_equal(draws, np.tile([0, 1, 2], 1000))


def test_from_uniform_is_the_stream_transform_of_the_spec():
    u = streams.uniforms(1, 2, np.arange(1000))
    for distribution, _ in CONTINUOUS:
        assert np.array_equal(distribution.from_uniform(u),
                              streams.transform(distribution.stream_spec(), u))


def test_specs_give_every_key_the_core_reads():
    keys = {"kind", "a", "b", "pa", "pb", "mirror", "low", "high", "samples"}
    assert Uniform(2.0, 5.0).stream_spec() == {
        "kind": "affine", "a": 2.0, "b": 3.0, "pa": 0.0, "pb": 0.0, "mirror": False,
        "low": 2.0, "high": 5.0, "samples": None}
    assert LogUniform(10.0, 1e5).stream_spec() == {
        "kind": "exp_affine", "a": math.log(10.0), "b": math.log(1e5) - math.log(10.0),
        "pa": 0.0, "pb": 0.0, "mirror": False, "low": 10.0, "high": 1e5, "samples": None}
    assert LogNormal(4.39, 0.5).stream_spec() == {
        "kind": "lognormal", "a": math.log(4.39), "b": 0.5, "pa": 0.0, "pb": 1.0,
        "mirror": False, "low": 0.0, "high": math.inf, "samples": None}
    upper = Truncated(LogNormal(4.39, 0.5), 4.39 * math.exp(0.5 * 3.5)).stream_spec()
    assert upper["mirror"] and upper["pa"] == 0.0
    assert upper["pb"] == pytest.approx(streams.normal_cdf(-3.5), rel=1e-15)
    empirical = Truncated(Empirical([3.0, 1.0, 2.0]), 1.5, 5.0).stream_spec()
    assert empirical["samples"].tolist() == [3.0, 2.0]
    assert {k: v for k, v in empirical.items() if k != "samples"} == {
        "kind": "empirical", "a": 0.0, "b": 0.0, "pa": 0.0, "pb": 0.0, "mirror": False,
        "low": 2.0, "high": 3.0}
    for distribution, _ in CONTINUOUS:
        spec = distribution.stream_spec()
        assert set(spec) == keys and spec["samples"] is None
        assert all(isinstance(spec[k], float) for k in ("a", "b", "pa", "pb", "low", "high"))


def test_sample_still_draws_from_a_generator_inside_a_truncation():
    draws = Truncated(Normal(4.0, 3.0), 0.0, 6.0).sample(np.random.default_rng(0), 10_000)
    assert draws.min() >= 0.0 and draws.max() <= 6.0
    again = Truncated(Normal(4.0, 3.0), 0.0, 6.0).sample(np.random.default_rng(0), 10_000)
    assert np.array_equal(draws, again)


def test_truncation_holding_almost_no_probability_is_refused():
    with pytest.raises(ValueError, match="holds a probability"):
        Truncated(Normal(0.0, 1.0), 10.0, 11.0)
    with pytest.raises(ValueError, match="holds a probability"):
        Truncated(Normal(0.0, 1.0), -11.0, -10.0)
    with pytest.raises(TypeError, match="cannot truncate"):
        Truncated(Grid((1.0, 2.0)), 0.0, 1.0)


@pytest.mark.parametrize("make, message", [
    (lambda: Uniform(2.0, 1.0), "low < high"),
    (lambda: LogUniform(0.0, 1.0), "0 < low < high"),
    (lambda: Normal(0.0, 0.0), "std > 0"),
    (lambda: LogNormal(-1.0, 0.5), "median > 0"),
    (lambda: LogNormal(1.0, math.nan), "finite"),
    (lambda: Empirical([]), "at least one sample"),
    (lambda: Choice((1.0, 2.0), weights=(1.0,)), "2 non-negative weights"),
    (lambda: Choice((1.0, 2.0), weights=(0.0, 0.0)), "positive sum"),
    (lambda: Grid(()), "at least one value"),
])
def test_invalid_distributions_are_refused_with_a_reason(make, message):
    with pytest.raises(ValueError, match=message):
        make()
