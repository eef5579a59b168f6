"""The search for a function's maximum in the unit cube [0, 1]^d: a start grid, then SciPy.

The function is evaluated on a grid of ``grid`` values per coordinate (the cube's corners
included), so that the search starts in the basin of the grid's best point rather than in
whichever basin a bracket happens to hold; then

- one coordinate: :func:`scipy.optimize.minimize_scalar` (``method="bounded"``, Brent's method
  on the interval between the best grid point's two neighbours, to ``xtol``);
- several: :func:`scipy.optimize.minimize` (``method="Powell"``, bounded to the cube, from
  the best grid point).

The best of the grid's best point, SciPy's answer and SciPy's answer with each coordinate
within ``xtol`` of a bound put on it is the maximum: a maximum on the cube's boundary is found
exactly, though SciPy's bounded line searches never evaluate an interval's ends.
Every value is computed once (a cache by point). SciPy is imported here only (the
``optimize`` extra).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

__all__ = ["Found", "maximize_on_cube", "default_grid"]

#: Powell's relative tolerance on the objective between two iterations: far below any Monte
#: Carlo error, so that ``xtol`` decides when it stops.
POWELL_FTOL = 1e-12
#: Evaluations Powell may take per coordinate.
POWELL_EVALUATIONS_PER_COORDINATE = 200


@dataclass(frozen=True)
class Found:
    """A maximum found in the unit cube.

    Attributes
    ----------
    u : float64 array (d,), its coordinates in [0, 1].
    value : the function's value there.
    evaluations : int, the function's evaluations (each distinct point once).
    """

    u: np.ndarray
    value: float
    evaluations: int


def default_grid(dimensions: int) -> int:
    """Grid values per coordinate by default: 9 for one parameter, 5 for two, 3 for more."""
    return 9 if dimensions == 1 else 5 if dimensions == 2 else 3


def _scipy_optimize():
    try:
        import scipy.optimize
    except ImportError:
        raise ImportError("the optimiser needs SciPy: pip install 'epc-fast[optimize]'") from None
    return scipy.optimize


def maximize_on_cube(function, dimensions: int, grid: int, xtol: float) -> Found:
    """The maximum of ``function(u)`` (u a float64 array in [0, 1]^dimensions) found from a
    start grid of ``grid`` values per coordinate, to ``xtol`` in each coordinate."""
    optimize = _scipy_optimize()
    cache: dict = {}

    def value(u) -> float:
        key = tuple(float(min(max(c, 0.0), 1.0)) for c in np.ravel(u))
        if key not in cache:
            cache[key] = float(function(np.array(key)))
        return cache[key]

    axis = np.linspace(0.0, 1.0, grid)
    best = max(itertools.product(axis, repeat=dimensions), key=value)
    if dimensions == 1:
        k = int(np.flatnonzero(axis == best[0])[0])
        bracket = (axis[max(k - 1, 0)], axis[min(k + 1, grid - 1)])
        found = optimize.minimize_scalar(lambda u: -value(u), bounds=bracket, method="bounded",
                                         options={"xatol": xtol})
    else:
        found = optimize.minimize(lambda u: -value(u), np.array(best), method="Powell",
                                  bounds=[(0.0, 1.0)] * dimensions,
                                  options={"xtol": xtol, "ftol": POWELL_FTOL,
                                           "maxfev": POWELL_EVALUATIONS_PER_COORDINATE
                                           * dimensions})
    refined = np.clip(np.ravel(found.x), 0.0, 1.0)
    # SciPy's bounded line searches never evaluate a bound itself: a coordinate within xtol of
    # one is tried on it too (a maximum on the boundary, where the slope is not zero).
    snapped = np.where(refined <= xtol, 0.0, np.where(refined >= 1.0 - xtol, 1.0, refined))
    point = max((tuple(best), tuple(refined), tuple(snapped)), key=value)
    return Found(np.array(point), value(point), len(cache))
