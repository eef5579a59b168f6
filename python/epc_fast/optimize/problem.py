"""A design optimisation under common random numbers: the scene drawn once, every candidate
design evaluated on the same draws.

:class:`Problem` draws the space's points once (:meth:`epc_fast.scan.Space.points`: a point's
draws depend only on the seed, the parameter and the point's index), holds them, and evaluates
the EPC of a candidate (the optimised parameters set to its values, every other parameter as
the space gives it) at every draw. Candidates differ only in the optimised parameters, so the
objective is a deterministic, continuous function of them (the mean and the quantile; the
probability is a step function with steps of 1/n), and the difference between two candidates
carries far less Monte Carlo noise than either value.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..api import evaluate
from ..memory import memory_limit_bytes
from .checks import (checked_bounds, checked_objective, checked_points, checked_search,
                     checked_threads, size_name, unit_of)
from .result import Curve, Estimate, Optimum
from .search import maximize_on_cube
from ..scan.running.core_plan import checked_seed
from ..scan.sampling.qmc import Sampling
from ..scan.sampling.space import Space
from ..status import Status

__all__ = ["Problem", "MIN_BATCH_POINTS", "DEFAULT_BATCHES", "DEFAULT_XTOL"]

#: Draws of one batch at the least: the batches' optima estimate the optimum's spread.
MIN_BATCH_POINTS = 100
#: Batches of the draws whose optima give the optimum's standard error, by default.
DEFAULT_BATCHES = 10
#: 1: the tolerance on the optimum's location by default, a fraction of each bound's range.
DEFAULT_XTOL = 1e-4
#: Bytes per draw besides the varying parameters' columns (8 each): EPC (8), status (1), and the
#: point index and one parameter's uniforms that drawing makes on the way (16).
BYTES_PER_DRAW = 25


class Problem:
    """Maximise an objective of EPC over design parameters, every candidate on the same draws.

    Parameters
    ----------
    space : epc_fast.scan.Space
        The scene's distribution and the fixed design, given as for a scan: its random
        parameters are the scene, drawn once; its value of an optimised parameter is replaced
        by each candidate's.
    bounds : {name: (low, high)}
        The optimised parameters (per-point parameters of :func:`epc_fast.evaluate`, fixed in
        the space), each with its bounds in its unit, e.g. ``{"pixel_pitch_um": (0.8, 4.0)}``.
        The sensor stays as the space gives it: a sensor given by its area (a preset, a
        ``Design``, width and height) keeps its area while the pitch changes, and its pixel
        count follows (N = S / p^2); a sensor given as ``pixel_count`` keeps its pixel count,
        and its area follows (S = N p^2).
    objective : Mean, Quantile or ProbabilityAtLeast, optional
        What is maximised (default: the mean EPC). Every draw counts: where the design's
        status is not OK it is worth 0 pixels (an unreachable SNR target: no picture of that
        scene; unbounded blur: EPC 0 already). A point outside its domain raises.
    points : int, optional
        Draws of the scene (default: one pass over the grid, for spaces without random
        parameters).
    seed : int, optional
        The seed of the draws, in [0, 2**64); None draws one (kept in :attr:`seed`).
    threads : int, optional
        Core threads (see :func:`epc_fast.evaluate`); results do not depend on it.
    sampling : {"monte_carlo", "sobol"}
        How the scene is drawn (:mod:`epc_fast.scan.sampling.qmc`): independent draws, or scrambled
        Sobol' points in :data:`DEFAULT_BATCHES` replicates, which are then the batches of
        :meth:`maximize` (``points`` a multiple of the replicates times the grid's cells) and
        give the estimates' standard errors; for a smooth objective their error falls faster
        with the draws (docs/optimize.md measures it).
    """

    def __init__(self, space: Space, bounds: dict, objective=None, *, points=None, seed=None,
                 threads=None, sampling: str = "monte_carlo"):
        self.bounds = checked_bounds(space, bounds)
        self.space = space
        self.names = tuple(self.bounds)
        self.objective = checked_objective(objective)
        self.points = checked_points(space, points)
        self.seed = checked_seed(seed)
        self.threads = checked_threads(threads)
        #: How the scene is drawn; Sobol' sampling's replicates are the batches.
        self.sampling = Sampling(sampling, DEFAULT_BATCHES if sampling == "sobol" else 1)
        if self.sampling.sobol and not space.is_random:
            self.sampling = Sampling("sobol", 1)
        unit = space.grid_size * self.sampling.replicates
        if self.sampling.replicates > 1 and self.points % unit:
            raise ValueError(f"sampling='sobol' draws {self.sampling.replicates} replicates of "
                             f"every grid cell: points must be a multiple of {unit}, got "
                             f"{self.points}")
        self._check_memory()
        started = time.perf_counter()
        drawn = _drawn(space.sampled(self.sampling), self.seed, self.points)
        #: s, the time the scene's draws took.
        self.draw_s = time.perf_counter() - started
        self._readout, set_by_modes = design_readout(space, self.names)
        self._parameters = {k: v for k, v in {**drawn, **space.evaluate_options}.items()
                            if k not in self.names and k not in set_by_modes}
        self._epc = np.empty(self.points)
        self._status = np.empty(self.points, dtype=np.uint8)

    def _check_memory(self) -> None:
        needed = self.points * (8 * len(self.space.varying_parameters) + BYTES_PER_DRAW)
        limit = memory_limit_bytes()
        if limit is not None and needed > limit:
            raise MemoryError(f"points={self.points:,} draws of this space need about "
                              f"{needed / 2**30:,.1f} GiB, more than the {limit / 2**30:,.1f} GiB "
                              "of memory here; use fewer points")

    @property
    def sensor_held(self) -> str:
        """What stays fixed of the sensor while the parameters change, for people."""
        size = size_name(self.space)
        if "pixel_pitch_um" not in self.names or size in self.names:
            return f"the sensor as the space gives it ({size})"
        if size == "sensor_area_mm2":
            return "the sensor's area (sensor_area_mm2); its pixel count follows the pitch"
        return "the pixel count (pixel_count); the sensor's area follows the pitch"

    def _slice(self, batch, batches) -> slice:
        if batch is None:
            return slice(0, self.points)
        size = self.points // batches
        return slice(batch * size, (batch + 1) * size)

    def _values(self, values) -> tuple:
        """The candidate as a tuple in :attr:`names`' order from a mapping of them."""
        unknown = sorted(set(values) - set(self.names))
        missing = [name for name in self.names if name not in values]
        if unknown or missing:
            raise TypeError(f"give a value of each optimised parameter ({', '.join(self.names)})"
                            f"; missing: {missing}, unknown: {unknown}")
        return tuple(float(values[name]) for name in self.names)

    def _epc_at(self, x: tuple, batch=None, batches=1) -> tuple[np.ndarray, int]:
        """(EPC at every draw of the batch, 0 where not OK; the count not OK), in the problem's
        own buffers (overwritten by the next call)."""
        part = self._slice(batch, batches)
        kwargs = {k: (v[part] if isinstance(v, np.ndarray) else v)
                  for k, v in self._parameters.items()}
        kwargs.update(zip(self.names, x))
        out = {"epc": self._epc[part], "status": self._status[part]}
        size = out["epc"].size
        if not any(isinstance(v, np.ndarray) and v.size == size for v in kwargs.values()):
            # Every parameter fixed: the illuminance repeated gives the outputs one per draw.
            kwargs["illuminance_lux"] = np.full(size, kwargs["illuminance_lux"])
        if "modes" in self._readout or "max_exposure_s" in kwargs:
            # the best mode per draw, or a frame cap's passes: evaluate takes no out= then
            result = evaluate(**kwargs, **self._readout, threads=self.threads,
                              outputs=("epc", "status"), invalid="raise")
            out["epc"][...], out["status"][...] = result.epc, result.status
        else:
            evaluate(**kwargs, **self._readout, threads=self.threads, outputs=("epc", "status"),
                     invalid="raise", out=out)
        epc, status = out["epc"], out["status"]
        not_ok = int(np.count_nonzero(status))  # Status.OK is 0
        if not_ok:
            epc[status != Status.OK] = 0.0
        return epc, not_ok

    def value_at(self, x: tuple, batch=None, batches=1) -> float:
        """The objective at candidate ``x`` (a tuple in :attr:`names`' order) over all draws,
        or over batch ``batch`` of ``batches`` (draws ``batch * m .. (batch + 1) * m - 1``,
        m = points // batches)."""
        return self.objective.value(self._epc_at(x, batch, batches)[0])

    def epc(self, **values) -> np.ndarray:
        """pixels: the EPC of the candidate ``values`` (each optimised parameter's value, in
        its unit) at every draw, 0 where its status is not OK (a new array)."""
        return self._epc_at(self._values(values))[0].copy()

    def estimate(self, **values) -> Estimate:
        """The objective at the candidate ``values`` (each optimised parameter's value, in its
        unit), with its Monte Carlo standard error."""
        return self._estimate(self._values(values))

    def _estimate(self, x: tuple) -> Estimate:
        epc, not_ok = self._epc_at(x)
        value = self.objective.value(epc)
        replicates = self.sampling.replicates
        if not self.space.is_random:
            error = 0.0
        elif replicates > 1:  # the replicates' spread: Sobol' points have no variance formula
            size = self.points // replicates
            each = [self.objective.value(epc[r * size:(r + 1) * size])
                    for r in range(replicates)]
            error = float(np.std(each, ddof=1) / math.sqrt(replicates))
        else:
            error = self.objective.standard_error(epc)
        return Estimate(value, error, not_ok / epc.size)

    def curve(self, name: str, values, at: dict | None = None) -> Curve:
        """The objective along parameter ``name`` at ``values`` (its unit), the other
        optimised parameters at ``at`` ({name: value}; needed when there are others)."""
        if name not in self.names:
            raise ValueError(f"curve: {name!r} is not an optimised parameter "
                             f"({', '.join(self.names)})")
        values = np.asarray(values, dtype=np.float64).reshape(-1)
        others = {k: v for k, v in (at or {}).items() if k != name}
        estimates = [self._estimate(self._values({**others, name: v})) for v in values]
        return Curve(name, values, np.array([e.value for e in estimates]),
                     np.array([e.standard_error for e in estimates]), others)

    def _candidate(self, u: np.ndarray) -> tuple:
        """The candidate at coordinates ``u`` in the unit cube: each bound's range mapped
        linearly onto [0, 1]."""
        return tuple(low + float(c) * (high - low)
                     for c, (low, high) in zip(u, self.bounds.values()))

    def maximize(self, *, batches: int = DEFAULT_BATCHES, start_grid: int | None = None,
                 xtol: float = DEFAULT_XTOL) -> Optimum:
        """The candidate that maximises the objective over every draw, with its uncertainty.

        The search (:mod:`epc_fast.optimize.search`) evaluates a start grid of
        ``start_grid`` values per parameter, then refines the best grid point with SciPy:
        :func:`scipy.optimize.minimize_scalar` (bounded Brent) for one parameter, bounded
        Powell for several. The optimum's standard error comes from batch means: the same
        search on each of ``batches`` disjoint batches of the draws (m = points // batches
        each) gives ``batches`` optima; their standard deviation over sqrt(batches) is the
        standard error of the optimum over all the draws, as the spread of an optimum shrinks
        as 1 / sqrt(draws). The objective's standard error is its own (:meth:`estimate`).

        Parameters
        ----------
        batches : int
            Batches for the optimum's standard error, >= 2, each of at least
            :data:`MIN_BATCH_POINTS` draws; 0 for none (NaN standard error). A space without
            random parameters has no Monte Carlo error: no batch is run, the error is 0.
        start_grid : int, optional
            Start grid values per parameter (the bounds included), >= 2; default 9 for one
            parameter, 5 for two, 3 for more (``start_grid ** len(bounds)`` candidates).
        xtol : float
            1, the tolerance on the optimum's location, a fraction of each bound's range, in
            (0, 0.1].

        Returns
        -------
        epc_fast.optimize.Optimum
        """
        replicates = self.sampling.replicates
        if replicates > 1 and batches not in (0, replicates):
            raise ValueError(f"batches={batches!r}: under sampling='sobol' the batches are its "
                             f"{replicates} replicates: give batches={replicates} or 0 (or "
                             "sampling='monte_carlo')")
        batches, grid, xtol = checked_search(batches, start_grid, xtol, len(self.names),
                                             self.points, self.space.is_random,
                                             MIN_BATCH_POINTS)
        started = time.perf_counter()
        found = maximize_on_cube(lambda u: self.value_at(self._candidate(u)), len(self.names),
                                 grid, xtol)
        batch_found = [maximize_on_cube(
            lambda u, b=b: self.value_at(self._candidate(u), b, batches), len(self.names),
            grid, xtol) for b in range(batches)]
        x = self._candidate(found.u)
        estimate = self._estimate(x)
        batch_x = np.array([self._candidate(f.u) for f in batch_found]).reshape(
            batches, len(self.names))
        if not self.space.is_random:
            spread = np.zeros(len(self.names))
        elif batches:
            spread = batch_x.std(axis=0, ddof=1) / math.sqrt(batches)
        else:
            spread = np.full(len(self.names), math.nan)
        ranges = [high - low for low, high in self.bounds.values()]
        return Optimum(
            x=dict(zip(self.names, x)), x_standard_error=dict(zip(self.names, spread.tolist())),
            batch_x={name: tuple(batch_x[:, i].tolist()) for i, name in enumerate(self.names)},
            value=estimate.value, value_standard_error=estimate.standard_error,
            not_ok_fraction=estimate.not_ok_fraction,
            at_bound={name: bool(min(abs(v - low), abs(high - v)) <= xtol * r)
                      for name, v, (low, high), r in zip(self.names, x, self.bounds.values(),
                                                         ranges)},
            objective=self.objective, unit=self.objective.unit, bounds=dict(self.bounds),
            held=self.sensor_held, points=self.points, seed=self.seed, batches=batches,
            evaluations=found.evaluations,
            batch_evaluations=sum(f.evaluations for f in batch_found),
            wall_s=time.perf_counter() - started)

    def describe(self) -> str:
        """The scene (the space without the optimised parameters), the optimised parameters
        with their bounds, what the sensor keeps, and the objective."""
        lines = [line for line in self.space.describe().splitlines()
                 if line.split(":", 1)[0].strip() not in self.names]
        lines += [f"optimised: {name} in [{low:g}, {high:g}] {unit_of(name)}"
                  for name, (low, high) in self.bounds.items()]
        lines.append(f"held: {self.sensor_held}")
        drawn = ("" if not self.sampling.sobol else
                 f", Sobol' points in {self.sampling.replicates} replicates")
        lines.append(f"objective: {self.objective.label} over {self.points:,} draws{drawn}, "
                     f"seed {self.seed} (a draw not OK counts as 0 pixels)")
        return "\n".join(lines)


def design_readout(space, names) -> tuple[dict, frozenset]:
    """(evaluate's keywords for how the space's designs are read, the parameters their modes
    set): one readout for every design (their binning_readout and modes), which the optimised
    parameters do not set."""
    from ..scan.running.readout_modes import readout_groups, readout_kwargs

    if not space.has_modes:
        return {}, frozenset()
    groups = readout_groups(space)
    if len(groups) > 1:
        raise ValueError("the optimiser reads every design one way: give the designs the same "
                         "binning_readout and modes, or optimise each design on its own")
    _, readout, modes = groups[0]
    kwargs, set_by_modes = readout_kwargs(readout, None if modes == ({},) else modes)
    both = sorted(set(names) & set_by_modes)
    if both:
        raise ValueError(f"{both[0]} is optimised and set by the designs' readout modes: "
                         "one or the other")
    return kwargs, set_by_modes


def _drawn(space: Space, seed: int, points: int) -> dict:
    """The scene's parameters at points 0 .. points - 1; in replicates (Sobol' sampling), each
    replicate's points together and in order, so that batch b of :meth:`Problem.maximize` is
    replicate b."""
    drawn = space.points(seed, 0, points)
    replicate = drawn.indices.get("replicate")
    if replicate is None:
        return drawn.parameters
    order = np.argsort(replicate, kind="stable")
    return {k: v[order] if isinstance(v, np.ndarray) and v.shape == (points,) else v
            for k, v in drawn.parameters.items()}
