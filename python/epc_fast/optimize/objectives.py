"""What :mod:`epc_fast.optimize` maximises over a scene's draws, and its Monte Carlo error.

Each objective reads the EPC of one design at every draw of the scene (pixels, a 1-D float64
array with no NaN: a draw where the design's status is not OK is worth 0 pixels there, see
:class:`epc_fast.optimize.Problem`) and gives one number, and its standard error as an
estimate of the same number over the scene's distribution:

- :class:`Mean`: the mean EPC (pixels); standard error s / sqrt(n), s the sample standard
  deviation.
- :class:`Quantile`: the q-quantile of EPC (pixels), exact: NumPy's default (linear)
  definition over every draw, never a binned estimate (a binned quantile is a step function of
  the design parameter). Standard error: half the distance between the order statistics whose
  ranks are one binomial standard deviation, sqrt(n q (1 - q)), either side of the quantile's
  (a distribution-free interval that holds about 68% of the time).
- :class:`ProbabilityAtLeast`: the fraction of draws with EPC >= a target (1); standard error
  sqrt(p (1 - p) / n). Over a finite sample this is a step function of the design parameter
  (steps of 1/n), far finer than its Monte Carlo error at 10^5 draws and more.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = ["Mean", "Quantile", "ProbabilityAtLeast", "OBJECTIVES", "order_statistics"]

#: Draws of the prefix that locates the band of values holding the wanted order statistics.
PILOT_POINTS = 1 << 16
#: Binomial standard deviations of the pilot's rank fraction kept either side of the band.
PILOT_SIGMAS = 6.0


def order_statistics(values: np.ndarray, ranks) -> np.ndarray:
    """The order statistics of ``values`` at 0-based ``ranks``: ``np.sort(values)[ranks]``.

    The exact answer in a few passes over ``values`` instead of a selection over all of them:
    the quantiles of a prefix of ``PILOT_POINTS`` draws bound a band [a, b] that holds the
    wanted ranks with overwhelming probability; the values below a are counted, the values in
    the band selected among themselves. When the count shows that the band misses a rank, the
    whole array is partitioned instead: the answer is exact either way.

    Parameters
    ----------
    values : 1-D float64 array without NaN (any unit).
    ranks : int array_like, each in [0, values.size).
    """
    ranks = np.asarray(ranks, dtype=np.intp)
    n = values.size
    if n <= 4 * PILOT_POINTS:
        return np.partition(values, ranks)[ranks]
    pilot = np.sort(values[:PILOT_POINTS])
    margin = PILOT_SIGMAS * math.sqrt(0.25 / PILOT_POINTS) + 2.0 / PILOT_POINTS
    low_fraction = ranks.min() / (n - 1) - margin
    high_fraction = ranks.max() / (n - 1) + margin
    low = pilot[int(low_fraction * (PILOT_POINTS - 1))] if low_fraction > 0 else -math.inf
    high = pilot[math.ceil(high_fraction * (PILOT_POINTS - 1))] if high_fraction < 1 else math.inf
    below = int(np.count_nonzero(values < low))
    band = values[(values >= low) & (values <= high)]
    if below <= ranks.min() and ranks.max() < below + band.size:
        return np.partition(band, ranks - below)[ranks - below]
    return np.partition(values, ranks)[ranks]


@dataclass(frozen=True)
class Mean:
    """The mean EPC over the scene's draws (pixels)."""

    unit: ClassVar[str] = "pixels"

    @property
    def label(self) -> str:
        return "mean EPC"

    def value(self, epc: np.ndarray) -> float:
        """pixels: the mean of ``epc`` (pixels per draw)."""
        return float(np.mean(epc))

    def standard_error(self, epc: np.ndarray) -> float:
        """pixels: s / sqrt(n), s the sample standard deviation (0 for one draw)."""
        if epc.size < 2:
            return 0.0
        return float(np.std(epc, ddof=1)) / math.sqrt(epc.size)


@dataclass(frozen=True)
class Quantile:
    """The ``q``-quantile of EPC over the scene's draws (pixels), exact.

    Parameters
    ----------
    q : 1, the probability, in [0, 1]: 0.5 for the median EPC.
    """

    q: float
    unit: ClassVar[str] = "pixels"

    def __post_init__(self):
        if (isinstance(self.q, bool) or not isinstance(self.q, numbers.Real)
                or not 0.0 <= self.q <= 1.0):
            raise ValueError(f"Quantile: q={self.q!r} must be a number in [0, 1]")
        object.__setattr__(self, "q", float(self.q))

    @property
    def label(self) -> str:
        return "median EPC" if self.q == 0.5 else f"{self.q:g}-quantile of EPC"

    def _at(self, epc: np.ndarray, position: float) -> float:
        """The value at a fractional 0-based rank, interpolated linearly between the order
        statistics either side, as NumPy's default quantile does."""
        k = min(int(math.floor(position)), epc.size - 1)
        fraction = position - k
        if fraction == 0.0:
            return float(order_statistics(epc, [k])[0])
        lower, upper = order_statistics(epc, [k, k + 1])
        return float(lower + (upper - lower) * fraction)

    def value(self, epc: np.ndarray) -> float:
        """pixels: the q-quantile of ``epc``, (n - 1) q the fractional rank."""
        return self._at(epc, (epc.size - 1) * self.q)

    def standard_error(self, epc: np.ndarray) -> float:
        """pixels: half the distance between the order statistics one binomial standard
        deviation, sqrt(n q (1 - q)) ranks, below and above the quantile's rank."""
        n = epc.size
        spread = math.sqrt(n * self.q * (1.0 - self.q))
        centre = (n - 1) * self.q
        low, high = max(centre - spread, 0.0), min(centre + spread, n - 1.0)
        return 0.5 * (self._at(epc, high) - self._at(epc, low))


@dataclass(frozen=True)
class ProbabilityAtLeast:
    """The probability that EPC reaches a target, P(EPC >= target_pixels) (1).

    Parameters
    ----------
    target_pixels : pixels, the target EPC, finite and >= 0.
    """

    target_pixels: float
    unit: ClassVar[str] = "1"

    def __post_init__(self):
        value = self.target_pixels
        if (isinstance(value, bool) or not isinstance(value, numbers.Real)
                or not math.isfinite(value) or value < 0):
            raise ValueError(f"ProbabilityAtLeast: target_pixels={value!r} must be a finite "
                             "number >= 0 (pixels)")
        object.__setattr__(self, "target_pixels", float(value))

    @property
    def label(self) -> str:
        return f"P(EPC >= {self.target_pixels:,.6g} pixels)"

    def value(self, epc: np.ndarray) -> float:
        """1: the fraction of ``epc`` at or above the target."""
        return np.count_nonzero(epc >= self.target_pixels) / epc.size

    def standard_error(self, epc: np.ndarray) -> float:
        """1: sqrt(p (1 - p) / n)."""
        p = self.value(epc)
        return math.sqrt(p * (1.0 - p) / epc.size)


#: The objectives by the name a config gives them (``kind``).
OBJECTIVES = {"mean": Mean, "quantile": Quantile, "probability_at_least": ProbabilityAtLeast}
