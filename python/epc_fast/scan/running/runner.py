"""Run a scan: chunks of whole blocks, evaluated locally or on Dask, their partial reductions
merged in block order as they arrive, so memory stays bounded whatever the point count.

Ctrl-C (KeyboardInterrupt) or SIGTERM stops the scan between chunks: the result holds the
chunks merged so far, a prefix of the points, and is marked ``partial``. While the scan stops
(its tasks cancelled, its Parquet staging directory removed) both signals are held, so a second
Ctrl-C cannot leave a staging directory for a task still running to write into. An error between
merges (a chunk's task failing, a full disk under its Parquet part or ``on_chunk``) is raised
with that prefix as its ``scan_result``, so a caller can still write what was merged.
"""

from __future__ import annotations

import operator
import time
from dataclasses import dataclass, field

from .aborted import ScanAborted
from ..reductions.groups import group_key, replicated
from ..reductions.histograms import Quantiles
from ..progress import progress_reporter
from ..sampling.qmc import DEFAULT_REPLICATES, Sampling, check_points
from ..reductions.replicates import (REPLICATED, exact_companions, finish_plan, stage_plan,
                                     unmet_targets)
from ...jobs.signals import signals_deferred as _interrupts_deferred
from ...jobs.signals import terminate_as_interrupt
from ..sampling.space import BLOCK_POINTS, Space
from ..reductions.summaries import FractionBelow, Summary
from .core_plan import checked_seed
from .tasks import BACKENDS, PlanItem, reduce_chunk

__all__ = ["run", "ScanResult", "Timing", "default_reductions", "sampled_scan",
           "DEFAULT_CHUNK_POINTS"]

#: Points per chunk by default: 16 blocks, tens of milliseconds of the core's fused pass (and
#: ~200 MB of arrays on the NumPy path).
DEFAULT_CHUNK_POINTS = 16 * BLOCK_POINTS
#: pixels: the threshold of the default fraction-below reduction.
DEFAULT_EPC_THRESHOLD = 2e6


@dataclass
class Timing:
    """Where a scan's time went, in seconds (summed over chunks; on Dask, over workers).

    Attributes
    ----------
    wall_s : s, the whole scan.
    sampling_s : s, drawing the points' parameters as arrays (0 where the core's fused pass
        draws them: its time is ``core_s``).
    core_s : s, in the core: the fused pass (drawing, evaluating and reducing each block of
        points) and :func:`epc_fast.evaluate`.
    output_s : s, writing Parquet.
    reduction_s : s, reducing chunks and merging their partial results.
    """

    wall_s: float = 0.0
    sampling_s: float = 0.0
    core_s: float = 0.0
    output_s: float = 0.0
    reduction_s: float = 0.0


@dataclass
class ScanResult:
    """What a scan reduced.

    Attributes
    ----------
    space : Space, the scanned space.
    seed : int, the seed (the same seed gives the same numbers).
    points : int, points reduced: ``0 .. points - 1`` (fewer than asked when ``partial``).
    points_requested : int.
    partial : bool, whether the scan was interrupted.
    results : {name: result}, one per reduction (also ``scan_result[name]``).
    timing : Timing.
    unmet_targets : tuple of str, one line per reduction whose target did not hold when the
        scan stopped (at its points, or interrupted); empty when every target held or none
        was given.
    """

    space: Space
    seed: int
    points: int
    points_requested: int
    partial: bool
    results: dict
    timing: Timing
    unmet_targets: tuple = ()

    @property
    def sampling(self) -> Sampling:
        """How the scan sampled its random parameters (method and replicates)."""
        return self.space.sampling

    def __getitem__(self, name: str):
        return self.results[name]

    @property
    def points_per_s(self) -> float:
        """points/s over the wall time."""
        return self.points / self.timing.wall_s if self.timing.wall_s > 0 else float("nan")


def default_reductions(space: Space) -> dict:
    """Summary, 5/50/95% quantiles and P(EPC < 2 Mpixel), per design when there are designs."""
    by = "design" if space.design_names else None
    return {"summary": Summary(by=by), "quantiles": Quantiles((0.05, 0.5, 0.95), by=by),
            "below": FractionBelow(DEFAULT_EPC_THRESHOLD, by=by)}


def _checked_points(space: Space, points) -> int:
    if points is None:
        if space.is_random:
            raise TypeError("a space with random parameters needs points=")
        return space.grid_size
    count = operator.index(points)
    if count < 1:
        raise ValueError(f"points must be >= 1, got {points!r}")
    return count


def _checked_chunk_points(chunk_points) -> int:
    count = operator.index(chunk_points)
    if count < 1 or count % BLOCK_POINTS:
        raise ValueError(f"chunk_points must be a positive multiple of {BLOCK_POINTS} "
                         f"(the block), got {chunk_points!r}")
    return count


def sampled_scan(space: Space, points: int, reductions: dict | None, sampling: str,
                 replicates: int | None) -> tuple[Space, dict, bool]:
    """(the space sampled as asked, the reductions, whether any has a target), or a ValueError
    or TypeError naming what a scan of ``points`` cannot take: a sampling, replicates, a
    point count Sobol' sampling cannot balance, a target it cannot check."""
    if replicates is None:
        replicates = DEFAULT_REPLICATES if sampling == "sobol" else 1
    chosen = Sampling(sampling, replicates)
    if not space.is_random:  # nothing random: nothing to replicate
        chosen = Sampling(sampling, 1)
    space = space.sampled(chosen)
    reductions = default_reductions(space) if reductions is None else dict(reductions)
    targets = _checked_targets(space, reductions)
    check_points(points, space.grid_size, space.sampling, cap=targets)
    return space, reductions, targets


def _plan(space: Space, reductions: dict) -> tuple:
    """The plan items: summaries, fractions and quantiles folded per replicate."""
    plan = []
    for name, reduction in reductions.items():
        base = group_key(space, reduction.by)
        key = base
        if isinstance(reduction, REPLICATED):
            key = replicated(base, space.sampling.replicates)
        plan.append(PlanItem(name, reduction, key, base))
    return tuple(plan)


def _stages(space: Space, points: int, targets: bool) -> list[int]:
    """Where the scan may stop: at ``points``, or with targets at each power of two of points
    per replicate and grid cell that is a whole number of blocks, then ``points``."""
    if not targets:
        return [points]
    unit = space.grid_size * space.sampling.replicates
    end = unit
    while end % BLOCK_POINTS:
        end *= 2
    stages = []
    while end < points:
        stages.append(end)
        end *= 2
    return stages + [points]


def _checked_targets(space: Space, reductions: dict) -> bool:
    """Whether any reduction has a target; a ValueError for one the scan cannot check."""
    targets = [(n, r) for n, r in reductions.items() if getattr(r, "target", None) is not None]
    for name, reduction in targets:
        if not isinstance(reduction, REPLICATED):
            raise ValueError(f"reduction {name!r}: a {type(reduction).__name__} takes no target")
        if space.sampling.replicates < 2:
            raise ValueError(f"reduction {name!r}: a target needs replicates >= 2 and random "
                             f"parameters (the standard errors come from the replicates)")
    return bool(targets)


def _local_outcomes(space, plan, seed, ranges, points, threads, parquet_dir, backend):
    for start, stop in ranges:
        yield reduce_chunk(space, plan, seed, start, stop, points, threads, parquet_dir, backend)


def _outcomes(client, space, plan, seed, ranges, points, threads, parquet_dir, backend):
    """The chunk outcomes of ``ranges``, in order: computed here, or on ``client``'s cluster."""
    if client is None:
        return _local_outcomes(space, plan, seed, ranges, points, threads, parquet_dir, backend)
    from .dask_backend import dask_outcomes

    return dask_outcomes(client, space, plan, seed, ranges, points, threads, parquet_dir,
                         backend)


@dataclass
class _Progress:
    """A running scan's state: its reductions' states, the points merged (a prefix), whether a
    merge is under way, its timing, progress reporter, Parquet staging directory and the
    current stage's outcomes."""

    states: dict
    reporter: object
    timing: Timing = field(default_factory=Timing)
    done: int = 0
    merging: bool = False
    parquet_dir: object = None
    outcomes: object = None


def _merge(state: _Progress, items, outcome, on_chunk) -> None:
    """Merge one chunk's partial reductions, with SIGINT and SIGTERM held: then its Parquet part
    is committed and ``on_chunk`` told the points done."""
    merge_started = time.perf_counter()
    with _interrupts_deferred():
        state.merging = True
        for item in items:
            state.states[item.name] = item.reduction.merge(state.states[item.name],
                                                           outcome.partials[item.name])
        state.done = outcome.stop
        state.merging = False
        if state.parquet_dir is not None:
            from .parquet import commit_parts

            commit_parts(state.parquet_dir, state.done)
        if on_chunk is not None:
            on_chunk(state.done)
    timing = state.timing
    for name in ("sampling_s", "core_s", "output_s", "reduction_s"):
        setattr(timing, name, getattr(timing, name) + getattr(outcome, name))
    timing.reduction_s += time.perf_counter() - merge_started
    state.reporter.update(state.done)


def _targets_met(state: _Progress, plan, companions, space) -> bool:
    """Whether every reduction's target holds on the points merged so far."""
    checked = time.perf_counter()
    unmet = unmet_targets(plan, finish_plan(plan, companions, state.states, space,
                                            targeted=True))
    state.timing.reduction_s += time.perf_counter() - checked
    return not unmet


def _stop(state: _Progress) -> None:
    """Stop whole, with SIGINT and SIGTERM held (a second Ctrl-C waits until the tasks are
    cancelled and the staging directory is gone, then stops the scan as the first): the
    outcomes closed, the reporter closed, the uncommitted Parquet parts removed."""
    with _interrupts_deferred():
        if state.outcomes is not None:
            state.outcomes.close()
        state.reporter.close()
        if state.parquet_dir is not None:
            from .parquet import discard_uncommitted

            discard_uncommitted(state.parquet_dir, state.done)


def _result(state: _Progress, space, seed, points, partial, plan, companions, targets,
            error) -> ScanResult:
    """The scan's result; an error that stopped it is raised with the result (the prefix
    merged before it) as its ``result`` (:class:`ScanAborted`) or ``scan_result``."""
    results = finish_plan(plan, companions, state.states, space)
    unmet = unmet_targets(plan, results) if targets else []
    result = ScanResult(space, seed, state.done, points, partial, results, state.timing,
                        tuple(unmet))
    if isinstance(error, ScanAborted):
        error.result = result
        raise error
    if error is not None:
        try:
            error.scan_result = result
        except AttributeError:  # an exception type without attributes of its own
            pass
        raise error
    return result


def run(space: Space, points: int | None = None, *, seed: int | None = None,
        reductions: dict | None = None, chunk_points: int = DEFAULT_CHUNK_POINTS,
        threads: int | None = None, progress=None, parquet=None, client=None,
        on_chunk=None, backend: str = "core", sampling: str = "monte_carlo",
        replicates: int | None = None) -> ScanResult:
    """Evaluate ``points`` points of ``space`` in chunks and reduce them on the fly.

    Parameters
    ----------
    space : Space
    points : int, optional
        Points to evaluate; default: one pass over the grid (spaces without random
        parameters only). Point i takes grid cell i mod ``space.grid_size``.
    seed : int, optional
        The seed of every random draw, in [0, 2**64); None draws a fresh one (recorded in the
        result). docs/scan.md gives the draw contract: a point's draws depend only on the
        seed, the parameter and the point's index.
    reductions : {name: reduction}, optional
        :class:`Summary`, :class:`Histogram`, :class:`Quantiles`, :class:`FractionBelow`,
        :class:`TopK`; default :func:`default_reductions`.
    chunk_points : int
        Points per chunk, a multiple of :data:`BLOCK_POINTS`: the unit of progress, Ctrl-C,
        Parquet files and Dask tasks; results do not change. The core's fused pass keeps no
        per-point array; exact quantiles, Parquet and the other backends hold the chunk's
        points (~200 bytes a point).
    threads : int, optional
        Core threads per chunk (see :func:`epc_fast.evaluate`); results do not change.
    progress : None, bool or callable
        See :func:`epc_fast.scan.progress.progress_reporter`.
    parquet : path, optional
        A directory for per-point output, one file per chunk (the ``parquet`` extra).
    client : dask.distributed.Client, optional
        Run the chunks as tasks on this client's cluster (the ``dask`` extra); the results are
        the same as a local run's.
    on_chunk : callable, optional
        Called as ``on_chunk(points_done)`` after each chunk is merged (and its Parquet part
        renamed into place), with SIGINT and SIGTERM held: e.g. to record progress on disk.
    backend : {"core", "numpy", "reference"}
        ``"core"``: the C++ core draws, evaluates and reduces each block of points in one
        pass. ``"numpy"``: NumPy draws and reductions around :func:`epc_fast.evaluate`;
        ``"reference"``: the same with the NumPy reference of the model (slow: the readable
        specification of a scan, for checking the core on small scans). The same draws in
        all three; the statistics agree to rounding (docs/scan.md).
    sampling : {"monte_carlo", "sobol"}
        How the random parameters are drawn (:mod:`epc_fast.scan.sampling.qmc`): independent
        Philox draws, or scrambled Sobol' points, whose errors fall faster with the points
        for smooth outputs. Sobol' sampling takes ``points = 2^m x replicates x grid cells``.
    replicates : int, optional
        Independent randomisations, 1 to 1024 (default: 16 for Sobol' sampling, 1 for Monte
        Carlo, whose mean, fraction and quantiles have errors of their own): point i is in replicate
        (i div grid cells) mod replicates, and the spread of the replicates' statistics gives
        each summary's, fraction's and quantile's standard error
        (:mod:`epc_fast.scan.reductions.replicates`). One replicate for a space without random
        parameters.

    With a reduction's ``target`` (e.g. ``Summary(target={"relative": 1e-3})``), ``points``
    is a cap: the scan stops at the first power of two of points per replicate and grid cell
    (a whole number of blocks) where every target holds, else at ``points``, and
    :attr:`ScanResult.unmet_targets` says which did not hold.

    Returns
    -------
    ScanResult

    Raises
    ------
    ScanAborted
        When the scan cannot go on (e.g. its cluster lost every worker); its ``result`` holds
        the prefix merged before, marked ``partial``.
    Exception
        An error between merges (a chunk's task, Parquet, ``on_chunk``: a full disk, say) is
        raised as it was, with the prefix merged before it as its ``scan_result``.
    """
    points = _checked_points(space, points)
    chunk_points = _checked_chunk_points(chunk_points)
    seed = checked_seed(seed)
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}; "
                         f"got {backend!r}")
    space, reductions, targets = sampled_scan(space, points, reductions, sampling, replicates)
    plan = _plan(space, reductions)
    stages = _stages(space, points, targets)
    companions = exact_companions(plan, stages, points)  # exact quantiles where it may stop
    state = _Progress({item.name: item.reduction.start(item.key, points)
                       for item in plan + companions}, progress_reporter(progress, points))
    partial = False
    aborted = failure = None
    started = time.perf_counter()
    with terminate_as_interrupt():
        try:
            if parquet is not None:
                from .parquet import prepare_directory

                with _interrupts_deferred():  # its staging directory is made and known, or not
                    state.parquet_dir = prepare_directory(parquet)
            for stage in stages:
                items = stage_plan(plan, companions, stage, state.states)
                ranges = ((start, min(start + chunk_points, stage))
                          for start in range(state.done, stage, chunk_points))
                state.outcomes = _outcomes(client, space, items, seed, ranges, points, threads,
                                           state.parquet_dir, backend)
                for outcome in state.outcomes:
                    _merge(state, items, outcome, on_chunk)
                if targets and _targets_met(state, plan, companions, space):
                    break
        except KeyboardInterrupt:
            partial = state.done < points
        except ScanAborted as error:
            aborted, partial = error, True
        except Exception as error:
            if state.merging:  # the states may hold part of a chunk: no prefix to give
                raise
            if parquet is not None and state.parquet_dir is None:  # refused before the first point
                raise
            failure, partial = error, True
        finally:
            try:
                _stop(state)
            except KeyboardInterrupt:
                partial = state.done < points
    state.timing.wall_s = time.perf_counter() - started
    return _result(state, space, seed, points, partial, plan, companions, targets,
                   aborted if aborted is not None else failure)

