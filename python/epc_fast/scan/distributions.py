"""How a scan's parameter varies: the random distributions, and the grid and choice axes.

A distribution draws float64 samples from a ``numpy.random.Generator``; every value is in the
unit of the parameter it describes (lux for ``illuminance_lux``, degree/s for
``shake_deg_per_s``, ...). :class:`Grid` and :class:`Choice` are the discrete axes: their
values are numbers, or designs on the ``design`` axis, and the index of a point's value is a
group key for per-group reductions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Uniform", "LogUniform", "Normal", "LogNormal", "Truncated", "Empirical", "Grid",
           "Choice"]

#: Smallest probability a :class:`Truncated` interval may hold: below it, rejection sampling
#: would draw more than 10^4 samples per kept one.
MIN_TRUNCATED_PROBABILITY = 1e-4


def _finite(name: str, value) -> float:
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return number


def _normal_cdf(z: float) -> float:
    return 0.5 * (1.0 + math.erf(z / math.sqrt(2.0)))


@dataclass(frozen=True)
class Uniform:
    """Uniform on [low, high).

    Parameters
    ----------
    low, high : the parameter's unit; low < high.
    """

    low: float
    high: float

    def __post_init__(self):
        if not _finite("low", self.low) < _finite("high", self.high):
            raise ValueError(f"Uniform needs low < high, got {self.low!r}, {self.high!r}")

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(self.low, self.high, n)

    def probability_within(self, low: float, high: float) -> float:
        """1: the probability of a draw in [low, high]."""
        overlap = min(high, self.high) - max(low, self.low)
        return max(overlap, 0.0) / (self.high - self.low)


@dataclass(frozen=True)
class LogUniform:
    """Log-uniform on [low, high): uniform in log(value), as illuminance often is.

    Parameters
    ----------
    low, high : the parameter's unit; 0 < low < high.
    """

    low: float
    high: float

    def __post_init__(self):
        if not 0.0 < _finite("low", self.low) < _finite("high", self.high):
            raise ValueError(f"LogUniform needs 0 < low < high, got {self.low!r}, {self.high!r}")

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return np.exp(rng.uniform(math.log(self.low), math.log(self.high), n))

    def probability_within(self, low: float, high: float) -> float:
        """1: the probability of a draw in [low, high]."""
        lo, hi = max(low, self.low), min(high, self.high)
        if hi <= lo:
            return 0.0
        return math.log(hi / lo) / math.log(self.high / self.low)


@dataclass(frozen=True)
class Normal:
    """Normal (Gaussian).

    Parameters
    ----------
    mean, std : the parameter's unit; std > 0.
    """

    mean: float
    std: float

    def __post_init__(self):
        _finite("mean", self.mean)
        if not _finite("std", self.std) > 0.0:
            raise ValueError(f"Normal needs std > 0, got {self.std!r}")

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.normal(self.mean, self.std, n)

    def probability_within(self, low: float, high: float) -> float:
        """1: the probability of a draw in [low, high]."""
        return max(_normal_cdf((high - self.mean) / self.std)
                   - _normal_cdf((low - self.mean) / self.std), 0.0)


@dataclass(frozen=True)
class LogNormal:
    """Log-normal: log(value) is normal with median ``median`` and standard deviation ``sigma``.

    Parameters
    ----------
    median : the parameter's unit, > 0; also exp(mean of log(value)).
    sigma : 1, the standard deviation of the natural log of the value, > 0.
    """

    median: float
    sigma: float

    def __post_init__(self):
        if not _finite("median", self.median) > 0.0:
            raise ValueError(f"LogNormal needs median > 0, got {self.median!r}")
        if not _finite("sigma", self.sigma) > 0.0:
            raise ValueError(f"LogNormal needs sigma > 0, got {self.sigma!r}")

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.lognormal(math.log(self.median), self.sigma, n)

    def probability_within(self, low: float, high: float) -> float:
        """1: the probability of a draw in [low, high]."""
        def cdf(x):
            return 0.0 if x <= 0.0 else _normal_cdf(math.log(x / self.median) / self.sigma)
        return max(cdf(high) - cdf(low), 0.0)


@dataclass(frozen=True, eq=False)
class Empirical:
    """Draws with replacement from measured samples (a bootstrap of, e.g., logged hand shake).

    Parameters
    ----------
    samples : array_like, the parameter's unit; finite, at least one.
    """

    samples: np.ndarray

    def __post_init__(self):
        samples = np.asarray(self.samples, dtype=np.float64).reshape(-1)
        if samples.size == 0 or not np.isfinite(samples).all():
            raise ValueError("Empirical needs at least one sample, all finite")
        object.__setattr__(self, "samples", samples)

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return self.samples[rng.integers(0, self.samples.size, n)]

    def probability_within(self, low: float, high: float) -> float:
        """1: the fraction of the samples in [low, high]."""
        return float(np.mean((self.samples >= low) & (self.samples <= high)))


@dataclass(frozen=True)
class Truncated:
    """Another distribution restricted to [low, high] (rejection sampling).

    Parameters
    ----------
    distribution : Uniform, LogUniform, Normal, LogNormal or Empirical
    low, high : the parameter's unit; the interval must hold a probability of at least
        :data:`MIN_TRUNCATED_PROBABILITY`. Either end may be infinite.
    """

    distribution: Uniform | LogUniform | Normal | LogNormal | Empirical
    low: float = -math.inf
    high: float = math.inf
    probability: float = field(init=False, repr=False)

    def __post_init__(self):
        if not hasattr(self.distribution, "probability_within"):
            raise TypeError(f"cannot truncate {self.distribution!r}")
        if not float(self.low) < float(self.high):
            raise ValueError(f"Truncated needs low < high, got {self.low!r}, {self.high!r}")
        probability = self.distribution.probability_within(float(self.low), float(self.high))
        if probability < MIN_TRUNCATED_PROBABILITY:
            raise ValueError(f"[{self.low}, {self.high}] holds a probability of {probability:.2g}"
                             f" under {self.distribution!r}; at least "
                             f"{MIN_TRUNCATED_PROBABILITY:g} is needed")
        object.__setattr__(self, "probability", probability)

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        out = np.empty(n)
        filled = 0
        while filled < n:
            wanted = n - filled
            draws = self.distribution.sample(rng, math.ceil(1.1 * wanted / self.probability) + 16)
            kept = draws[(draws >= self.low) & (draws <= self.high)][:wanted]
            out[filled:filled + kept.size] = kept
            filled += kept.size
        return out


@dataclass(frozen=True)
class Grid:
    """A grid axis: point i takes value ``(i mod grid size)`` in mixed radix over every grid axis.

    Every combination of the grid axes is visited once per ``grid size`` consecutive points;
    the product is never materialised.

    Parameters
    ----------
    values : sequence of numbers (the parameter's unit), or of designs on the ``design`` axis.
    """

    values: tuple

    def __post_init__(self):
        object.__setattr__(self, "values", tuple(self.values))
        if not self.values:
            raise ValueError("Grid needs at least one value")


@dataclass(frozen=True)
class Choice:
    """A random choice among values, with optional weights.

    Parameters
    ----------
    values : sequence of numbers (the parameter's unit), or of designs on the ``design`` axis.
    weights : sequence of non-negative numbers, optional; normalised to sum 1. None: equal.
    """

    values: tuple
    weights: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "values", tuple(self.values))
        if not self.values:
            raise ValueError("Choice needs at least one value")
        if self.weights is not None:
            weights = tuple(float(w) for w in self.weights)
            if (len(weights) != len(self.values) or not all(math.isfinite(w) and w >= 0
                                                            for w in weights)
                    or sum(weights) <= 0):
                raise ValueError(f"Choice needs {len(self.values)} non-negative weights with a "
                                 f"positive sum, got {self.weights!r}")
            object.__setattr__(self, "weights", weights)

    def sample_indices(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """Indices into ``values`` of ``n`` draws."""
        if self.weights is None:
            return rng.integers(0, len(self.values), n)
        cumulative = np.cumsum(self.weights) / sum(self.weights)
        indices = np.searchsorted(cumulative, rng.random(n), side="right")
        return np.minimum(indices, len(self.values) - 1)
