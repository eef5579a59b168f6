"""The optimiser's objectives (epc_fast.optimize.Mean, Quantile, ProbabilityAtLeast): exact
order statistics, NumPy's quantile, the textbook standard errors."""

import math

import numpy as np
import pytest

from epc_fast import optimize
from epc_fast.optimize.objectives import order_statistics


@pytest.mark.parametrize("n", [1, 7, 1000, 300_000, 1_000_000])
def test_order_statistics_are_exact(n):
    rng = np.random.default_rng(n)
    values = rng.lognormal(size=n)
    values[: n // 5] = 0.0  # ties, as the draws that are not OK give
    rng.shuffle(values)
    ranks = np.unique(np.array([0, n // 3, n // 2, n - 1]))
    assert np.array_equal(order_statistics(values, ranks), np.sort(values)[ranks])


def test_order_statistics_stay_exact_when_the_first_draws_mislead():
    values = np.sort(np.random.default_rng(1).normal(size=1_000_000))  # the prefix: the smallest
    assert order_statistics(values, [500_000])[0] == values[500_000]


@pytest.mark.parametrize("q", [0.0, 0.05, 0.5, 1 / 3, 0.95, 1.0])
def test_the_quantile_is_numpys(q):
    values = np.random.default_rng(2).lognormal(size=400_000)
    # NumPy writes the same interpolation with the weights the other way round above 0.5:
    # a few ulp apart
    assert optimize.Quantile(q).value(values) == pytest.approx(np.quantile(values, q), rel=1e-14)


def test_the_standard_errors_are_the_textbook_ones():
    rng = np.random.default_rng(3)
    uniform = rng.uniform(size=100_000)
    # the median of n uniforms: sqrt(1/4 / n) / density 1 = 0.00158; the interval's ends are
    # order statistics, themselves known to ~1/sqrt(n q (1 - q)) = 0.6% each
    assert optimize.Quantile(0.5).standard_error(uniform) == pytest.approx(0.5 / math.sqrt(1e5),
                                                                          rel=0.03)
    assert optimize.Mean().standard_error(uniform) == np.std(uniform, ddof=1) / math.sqrt(1e5)
    p = np.mean(uniform >= 0.3)
    assert optimize.ProbabilityAtLeast(0.3).standard_error(uniform) == math.sqrt(p * (1 - p) / 1e5)
