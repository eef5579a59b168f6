"""A reduction's stopping target: how accurate its statistics must be for a scan to stop
(:mod:`epc_fast.scan.reductions.replicates` reads it)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Target", "target_of"]


@dataclass(frozen=True)
class Target:
    """How accurate a reduction's statistics must be for a scan to stop.

    Parameters
    ----------
    standard_error : float, optional, the output's unit (a fraction's: 1): the largest
        standard error taken.
    relative : float, optional, 1: the largest standard error as a share of the statistic's
        magnitude.

    Both given: both must hold.
    """

    standard_error: float | None = None
    relative: float | None = None

    def __post_init__(self):
        if self.standard_error is None and self.relative is None:
            raise ValueError("a target gives standard_error, relative or both")
        for name in ("standard_error", "relative"):
            value = getattr(self, name)
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating,
                                                                 np.integer)):
                raise TypeError(f"target {name} must be a number, got {value!r}")
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"target {name} must be a finite number > 0, got {value!r}")
            object.__setattr__(self, name, float(value))

    def holds(self, estimate: np.ndarray, error: np.ndarray) -> np.ndarray:
        """Where the standard error is within the target (never where it is NaN)."""
        ok = np.isfinite(error)
        if self.standard_error is not None:
            ok &= error <= self.standard_error
        if self.relative is not None:
            ok &= error <= self.relative * np.abs(estimate)
        return ok

    def __str__(self) -> str:
        parts = []
        if self.standard_error is not None:
            parts.append(f"standard error <= {self.standard_error:g}")
        if self.relative is not None:
            parts.append(f"relative standard error <= {self.relative:g}")
        return " and ".join(parts)


def target_of(value) -> Target | None:
    """A reduction's target from None, a :class:`Target` or a mapping of its fields."""
    if value is None or isinstance(value, Target):
        return value
    if isinstance(value, dict):
        unknown = sorted(set(value) - {"standard_error", "relative"})
        if unknown:
            raise ValueError(f"target: unknown key(s) {', '.join(unknown)}; a target gives "
                             "standard_error, relative or both")
        return Target(**value)
    raise TypeError(f"target must be a mapping such as {{'relative': 1e-3}}, got {value!r}")
