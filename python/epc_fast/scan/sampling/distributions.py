"""How a scan's parameter varies: the random distributions, and the grid and choice axes.

A distribution turns uniforms in (0, 1) into float64 values by the inverse of its CDF
(``from_uniform``), following the scan's draw contract (:mod:`epc_fast.scan.sampling.streams`); its
``stream_spec()`` is that inverse as the few numbers the C++ core reads. Every value is in the
unit of the parameter it describes (lux for ``illuminance_lux``, degree/s for
``shake_deg_per_s``, ...). ``sample(rng, n)`` draws from a ``numpy.random.Generator`` instead,
outside scans. :class:`Grid` and :class:`Choice` are the discrete axes: their values are
numbers, or designs on the ``design`` axis, and the index of a point's value is a group key for
per-group reductions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import streams

__all__ = ["Uniform", "LogUniform", "Normal", "LogNormal", "Truncated", "Empirical", "Grid",
           "Choice"]

#: Smallest probability a :class:`Truncated` interval may hold: below it, ``sample``'s
#: rejection sampling would draw more than 10^4 samples per kept one.
MIN_TRUNCATED_PROBABILITY = 1e-4


def _finite(name: str, value) -> float:
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return number


def _spec(kind: str, low: float, high: float, a: float = 0.0, b: float = 0.0, pa: float = 0.0,
          pb: float = 0.0, mirror: bool = False, samples: np.ndarray | None = None) -> dict:
    """A stream spec (:func:`epc_fast.scan.sampling.streams.transform`); unused keys are 0.0, False
    and None."""
    return {"kind": kind, "a": float(a), "b": float(b), "pa": float(pa), "pb": float(pb),
            "mirror": bool(mirror), "low": float(low), "high": float(high), "samples": samples}


def _normal_probabilities(z_low: float, z_high: float) -> tuple[float, float, bool]:
    """(pa, pb, mirror) of a normal truncated to z-bounds [z_low, z_high]: Phi of the bounds,
    or, when the interval is in the upper half (z_low >= 0), Phi of the negated bounds and the
    quantile mirrored, so that both probabilities are small numbers computed to full relative
    precision instead of 1 - tiny."""
    if z_low >= 0.0:
        return streams.normal_cdf(-z_high), streams.normal_cdf(-z_low), True
    return streams.normal_cdf(z_low), streams.normal_cdf(z_high), False


def _normal_mass(z_low: float, z_high: float) -> float:
    """1: the standard normal's probability in [z_low, z_high]."""
    pa, pb, _ = _normal_probabilities(z_low, z_high)
    return max(pb - pa, 0.0)


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

    def _spec_within(self, low: float, high: float) -> dict:
        lo, hi = max(low, self.low), min(high, self.high)
        return _spec("affine", lo, hi, a=lo, b=hi - lo)

    def stream_spec(self) -> dict:
        """The draw contract's spec: ``low + u (high - low)``."""
        return self._spec_within(-math.inf, math.inf)

    def from_uniform(self, u) -> np.ndarray:
        """The values at uniforms ``u`` in (0, 1), in the parameter's unit."""
        return streams.transform(self.stream_spec(), u)

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

    def _spec_within(self, low: float, high: float) -> dict:
        lo, hi = max(low, self.low), min(high, self.high)
        return _spec("exp_affine", lo, hi, a=math.log(lo), b=math.log(hi) - math.log(lo))

    def stream_spec(self) -> dict:
        """The draw contract's spec: ``exp(log low + u (log high - log low))``, clamped to
        [low, high]."""
        return self._spec_within(-math.inf, math.inf)

    def from_uniform(self, u) -> np.ndarray:
        """The values at uniforms ``u`` in (0, 1), in the parameter's unit."""
        return streams.transform(self.stream_spec(), u)

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
        return _normal_mass((low - self.mean) / self.std, (high - self.mean) / self.std)

    def _spec_within(self, low: float, high: float) -> dict:
        pa, pb, mirror = _normal_probabilities((low - self.mean) / self.std,
                                               (high - self.mean) / self.std)
        return _spec("normal", low, high, a=self.mean, b=self.std, pa=pa, pb=pb, mirror=mirror)

    def stream_spec(self) -> dict:
        """The draw contract's spec: ``mean + std Phi^-1(u)`` (pa = 0, pb = 1)."""
        return self._spec_within(-math.inf, math.inf)

    def from_uniform(self, u) -> np.ndarray:
        """The values at uniforms ``u`` in (0, 1), in the parameter's unit."""
        return streams.transform(self.stream_spec(), u)


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

    def _z(self, value: float) -> float:
        """1: the z-score of log(value); -inf at value <= 0."""
        if value <= 0.0:
            return -math.inf
        return (math.log(value) - math.log(self.median)) / self.sigma

    def probability_within(self, low: float, high: float) -> float:
        """1: the probability of a draw in [low, high]."""
        return _normal_mass(self._z(low), self._z(high))

    def _spec_within(self, low: float, high: float) -> dict:
        pa, pb, mirror = _normal_probabilities(self._z(low), self._z(high))
        return _spec("lognormal", max(low, 0.0), high, a=math.log(self.median), b=self.sigma,
                     pa=pa, pb=pb, mirror=mirror)

    def stream_spec(self) -> dict:
        """The draw contract's spec: ``exp(log median + sigma Phi^-1(u))`` (pa = 0, pb = 1)."""
        return self._spec_within(-math.inf, math.inf)

    def from_uniform(self, u) -> np.ndarray:
        """The values at uniforms ``u`` in (0, 1), in the parameter's unit."""
        return streams.transform(self.stream_spec(), u)


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

    def _spec_within(self, low: float, high: float) -> dict:
        kept = self.samples[(self.samples >= low) & (self.samples <= high)]
        # low and high are the kept samples' range: a clamp to them changes no value.
        return _spec("empirical", kept.min(), kept.max(), samples=kept)

    def stream_spec(self) -> dict:
        """The draw contract's spec: ``samples[min(floor(u m), m - 1)]`` of the m samples."""
        return self._spec_within(-math.inf, math.inf)

    def from_uniform(self, u) -> np.ndarray:
        """The values at uniforms ``u`` in (0, 1), in the parameter's unit."""
        return streams.transform(self.stream_spec(), u)


@dataclass(frozen=True)
class Truncated:
    """Another distribution restricted to [low, high].

    ``from_uniform`` inverts the truncated CDF (uniform and log-uniform: the same distribution
    on the intersection of the ranges; normal and log-normal: the quantile between the bounds'
    probabilities, in the lower tail's terms for an interval in the upper half; empirical: the
    samples inside [low, high]); ``sample`` rejects the parent's draws outside [low, high].

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
        if not hasattr(self.distribution, "_spec_within"):
            raise TypeError(f"cannot truncate {self.distribution!r}")
        if not float(self.low) < float(self.high):
            raise ValueError(f"Truncated needs low < high, got {self.low!r}, {self.high!r}")
        probability = self.distribution.probability_within(float(self.low), float(self.high))
        if probability < MIN_TRUNCATED_PROBABILITY:
            raise ValueError(f"[{self.low}, {self.high}] holds a probability of {probability:.2g}"
                             f" under {self.distribution!r}; at least "
                             f"{MIN_TRUNCATED_PROBABILITY:g} is needed")
        object.__setattr__(self, "probability", probability)

    def stream_spec(self) -> dict:
        """The draw contract's spec of the truncated distribution."""
        return self.distribution._spec_within(float(self.low), float(self.high))

    def from_uniform(self, u) -> np.ndarray:
        """The values at uniforms ``u`` in (0, 1), in the parameter's unit, in [low, high]."""
        return streams.transform(self.stream_spec(), u)

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

    def stream_spec(self) -> dict:
        """The draw contract's spec: ``n`` values and, when weighted, ``cumulative``, the
        float64 cumulative weights c[0 .. n - 2] (``cumsum(w) / sum(w)`` without its last
        entry, 1); None when unweighted."""
        if self.weights is None:
            return {"cumulative": None, "n": len(self.values)}
        cumulative = np.cumsum(np.asarray(self.weights, dtype=np.float64))
        # Divided by the cumsum's own last entry: a zero last weight makes c[n - 2] exactly 1,
        # above every uniform.
        return {"cumulative": cumulative[:-1] / cumulative[-1], "n": len(self.values)}

    def indices_from_uniform(self, u) -> np.ndarray:
        """Indices into ``values`` at uniforms ``u`` in (0, 1): ``min(floor(u n), n - 1)``, or,
        weighted, the number of cumulative weights c[0 .. n - 2] at or below u."""
        u = np.asarray(u, dtype=np.float64)
        spec = self.stream_spec()
        if spec["cumulative"] is None:
            n = spec["n"]
            return np.minimum(np.floor(u * n).astype(np.intp), n - 1)
        return np.searchsorted(spec["cumulative"], u, side="right").astype(np.intp)

    def sample_indices(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """Indices into ``values`` of ``n`` draws."""
        if self.weights is None:
            return rng.integers(0, len(self.values), n)
        cumulative = np.cumsum(self.weights) / sum(self.weights)
        indices = np.searchsorted(cumulative, rng.random(n), side="right")
        return np.minimum(indices, len(self.values) - 1)
