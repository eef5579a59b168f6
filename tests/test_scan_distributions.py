"""The scan's distributions and discrete axes draw what they say."""

import math

import numpy as np
import pytest

from epc_fast.scan import (Choice, Empirical, Grid, LogNormal, LogUniform, Normal, Truncated,
                           Uniform)

N = 200_000
#: Sample means are checked to 5 standard errors: a false alarm is a 1-in-10^6 event.
SIGMAS = 5.0


def _rng(seed=0):
    return np.random.default_rng(seed)


def _assert_mean(samples, expected_mean, expected_std):
    assert abs(samples.mean() - expected_mean) <= SIGMAS * expected_std / math.sqrt(samples.size)


def test_uniform_draws_lie_in_range_with_the_middle_as_mean():
    draws = Uniform(2.0, 5.0).sample(_rng(), N)
    assert draws.min() >= 2.0 and draws.max() < 5.0
    _assert_mean(draws, 3.5, 3.0 / math.sqrt(12.0))


def test_log_uniform_is_uniform_in_the_log():
    draws = LogUniform(10.0, 1e5).sample(_rng(), N)
    # exp(log) may round one ulp beyond an end.
    assert draws.min() >= 10.0 * (1 - 1e-15) and draws.max() <= 1e5 * (1 + 1e-15)
    logs = np.log10(draws)
    _assert_mean(logs, 3.0, 4.0 / math.sqrt(12.0))


def test_normal_has_its_mean_and_standard_deviation():
    draws = Normal(4.0, 1.5).sample(_rng(), N)
    _assert_mean(draws, 4.0, 1.5)
    # The sample std of N normal draws has a standard error of sigma / sqrt(2 N).
    assert abs(draws.std() - 1.5) <= SIGMAS * 1.5 / math.sqrt(2 * N)


def test_lognormal_has_its_median_and_log_spread():
    draws = LogNormal(median=4.39, sigma=0.5).sample(_rng(), N)
    _assert_mean(np.log(draws), math.log(4.39), 0.5)
    # The sample median's standard error is about 1.25 sigma / sqrt(N) in the log.
    assert abs(math.log(np.median(draws) / 4.39)) <= SIGMAS * 1.25 * 0.5 / math.sqrt(N)


def test_truncated_normal_stays_inside_and_has_the_truncated_mean():
    mean, std, low, high = 4.0, 3.0, 0.0, 6.0
    draws = Truncated(Normal(mean, std), low, high).sample(_rng(), N)
    assert draws.min() >= low and draws.max() <= high
    a, b = (low - mean) / std, (high - mean) / std
    pdf = [math.exp(-z * z / 2) / math.sqrt(2 * math.pi) for z in (a, b)]
    mass = 0.5 * (math.erf(b / math.sqrt(2)) - math.erf(a / math.sqrt(2)))
    expected = mean + std * (pdf[0] - pdf[1]) / mass
    # The truncated distribution's std is below the parent's: the parent's is a safe bound.
    _assert_mean(draws, expected, std)


def test_truncation_holding_almost_no_probability_is_refused():
    with pytest.raises(ValueError, match="holds a probability"):
        Truncated(Normal(0.0, 1.0), 10.0, 11.0)


def test_empirical_draws_only_its_samples_equally_often():
    samples = np.array([1.0, 2.0, 4.0, 8.0])
    draws = Empirical(samples).sample(_rng(), N)
    values, counts = np.unique(draws, return_counts=True)
    assert np.array_equal(values, samples)
    # Each count is binomial(N, 1/4): standard error sqrt(N p (1 - p)).
    assert np.all(np.abs(counts - N / 4) <= SIGMAS * math.sqrt(N * 0.25 * 0.75))


def test_choice_weights_set_the_frequencies_and_a_zero_weight_is_never_drawn():
    choice = Choice((10.0, 20.0, 30.0), weights=(3, 0, 1))
    counts = np.bincount(choice.sample_indices(_rng(), N), minlength=3)
    assert counts[1] == 0
    assert abs(counts[0] - 0.75 * N) <= SIGMAS * math.sqrt(N * 0.75 * 0.25)


def test_draws_are_reproducible_from_the_generator_seed():
    for distribution in (Uniform(0, 1), LogUniform(1, 10), Normal(0, 1), LogNormal(1, 1),
                         Truncated(Normal(0, 1), -1, 1), Empirical([1.0, 2.0])):
        first, again = (distribution.sample(_rng(3), 1000) for _ in range(2))
        assert np.array_equal(first, again)


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
