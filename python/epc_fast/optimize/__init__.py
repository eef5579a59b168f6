"""The best design: maximise an objective of EPC over a few design parameters, under a scene
distribution, with common random numbers and SciPy's bounded optimisers.

>>> from epc_fast import optimize, scan
>>> from epc_fast.presets import HIGH_TIER
>>> space = scan.Space(design=[HIGH_TIER[2]], illuminance_lux=scan.LogUniform(10, 1e5))
>>> best = optimize.maximize(space, {"pixel_pitch_um": (0.8, 4.0)}, optimize.Quantile(0.5),
...                          points=100_000, seed=1)
>>> 1.0 < best.x["pixel_pitch_um"] < 4.0
True

The scene is an :class:`epc_fast.scan.Space`, as for a scan: its random parameters are drawn
once (the scan's counter-based draws, so a seed gives the same scenes anywhere) and every
candidate design is evaluated on exactly these draws (common random numbers). The objective
is then a deterministic, continuous function of the design parameters, which a bounded
optimiser can maximise; the difference between two candidates carries far less noise than
either value. Objectives (:mod:`epc_fast.optimize.objectives`): :class:`Mean`,
:class:`Quantile` (exact) and :class:`ProbabilityAtLeast`. A draw where the design's status is
not OK (an unreachable SNR target) is worth 0 pixels: every scene counts, and a design that
cannot take a picture of a scene gets nothing for it.

Uncertainty. The objective's Monte Carlo standard error at the optimum is the objective's own
(mean: s / sqrt(n); quantile: from the order statistics one binomial standard deviation either
side; probability: sqrt(p (1 - p) / n)). The optimum's location has its own: the same search on
disjoint batches of the draws gives one optimum per batch, and their standard deviation over
sqrt(batches) is the standard error of the optimum over all the draws (batch means).

SciPy is needed (``pip install 'epc-fast[optimize]'``) and imported only when a search runs.
"""

from __future__ import annotations

from .objectives import Mean, ProbabilityAtLeast, Quantile
from .problem import DEFAULT_BATCHES, DEFAULT_XTOL, Problem
from .result import Curve, Estimate, Optimum

__all__ = ["maximize", "Problem", "Mean", "Quantile", "ProbabilityAtLeast", "Optimum",
           "Estimate", "Curve"]


def maximize(space, bounds: dict, objective=None, *, points: int | None = None,
             seed: int | None = None, threads: int | None = None,
             batches: int = DEFAULT_BATCHES, start_grid: int | None = None,
             xtol: float = DEFAULT_XTOL, sampling: str = "monte_carlo") -> Optimum:
    """The design parameters that maximise ``objective`` over the scenes of ``space``.

    ``Problem(space, bounds, objective, points=, seed=, threads=).maximize(batches=,
    start_grid=, xtol=)``: see :class:`Problem` and :meth:`Problem.maximize` for each argument.
    Keep the :class:`Problem` instead to evaluate the objective elsewhere on the same draws
    (:meth:`Problem.estimate`, :meth:`Problem.curve`).

    Parameters
    ----------
    space : epc_fast.scan.Space, the scene's distribution and the fixed design.
    bounds : {name: (low, high)}, the optimised parameters, each in its unit.
    objective : Mean (default), Quantile or ProbabilityAtLeast.
    points : int, draws of the scene.
    seed : int, the draws' seed.
    threads : int, core threads.
    batches : int, batches for the optimum's standard error (0: none).
    start_grid : int, start grid values per parameter.
    xtol : 1, the tolerance on the optimum, a fraction of each bound's range.
    sampling : "monte_carlo" or "sobol", how the scene is drawn (:class:`Problem`).

    Returns
    -------
    Optimum
    """
    problem = Problem(space, bounds, objective, points=points, seed=seed, threads=threads,
                      sampling=sampling)
    return problem.maximize(batches=batches, start_grid=start_grid, xtol=xtol)
