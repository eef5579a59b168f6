"""One chunk of a scan, start to end: draw its points, evaluate them, reduce them.

This is the unit of work of both the local loop (which calls it in order) and Dask (where it
is the task a worker runs). Its outcome holds only partial reductions (small), never points.

Three backends do the same work: ``"core"``, the fused pass of the C++ core (it forms the
points, evaluates them and folds them into the reductions; core_plan.py), ``"numpy"``, NumPy
draws and reductions around :func:`epc_fast.evaluate`, and ``"reference"``, the same with the
NumPy reference of the model: the scan's readable specification, for tests on small scans.
Exact quantiles (scans of at most ``exact_up_to`` points) keep every value, and Parquet
writes every point: for those the core forms and evaluates the chunk's points as arrays.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..._validation import threads_of
from ...api import OUTPUT_DTYPES, evaluate
from .chunk import Chunk
from .core_plan import CorePlan
from .camera_terms import camera_terms
from ..reductions.groups import GroupKey
from ..reductions.histograms import Quantiles
from .readout_modes import evaluate_space_points
from ..sampling.space import Space

__all__ = ["PlanItem", "ChunkOutcome", "chunk_outputs", "reduce_chunk", "BACKENDS"]

#: The scan backends (see the module docstring).
BACKENDS = ("core", "numpy", "reference")


@dataclass(frozen=True)
class PlanItem:
    """A named reduction and its group key resolved against the scan's space: ``key`` the one
    it folds by (the replicate first, :func:`~epc_fast.scan.reductions.groups.replicated`),
    ``base_key`` the one its result is given by (None: ``key``)."""

    name: str
    reduction: object
    key: GroupKey
    base_key: GroupKey | None = None


@dataclass
class ChunkOutcome:
    """The partial reductions of points ``start .. stop - 1`` and what they cost.

    Attributes
    ----------
    start, stop : point indices.
    partials : {reduction name: partial}.
    sampling_s, core_s, output_s, reduction_s : s, time drawing the points as arrays, in
        the core (:func:`epc_fast.evaluate`, or the fused pass, which draws, evaluates and
        reduces), writing Parquet, and reducing in NumPy.
    """

    start: int
    stop: int
    partials: dict
    sampling_s: float
    core_s: float
    output_s: float
    reduction_s: float


def chunk_outputs(plan: tuple, parquet: bool) -> tuple:
    """The :class:`~epc_fast.Result` fields a chunk needs: the output of each reduction and the
    status (summaries count statuses), and every default field when the points go to Parquet.
    The core computes only these (``evaluate(outputs=...)``): without f50, EPC or a share among
    them it does not solve f50 at all."""
    reduced = tuple(sorted({item.reduction.of for item in plan}))
    if parquet:
        return tuple(OUTPUT_DTYPES) + tuple(name for name in reduced if name not in OUTPUT_DTYPES)
    return ("status",) + reduced


def _per_point(item: PlanItem, points_total: int) -> bool:
    """Whether a reduction needs the chunk's values as arrays: exact quantiles keep them, and
    the fused pass has no f50 across the motion."""
    return ((isinstance(item.reduction, Quantiles)
             and points_total <= item.reduction.exact_up_to)
            or item.reduction.of == "f50_across_cyc_per_mm")


def reduce_chunk(space: Space, plan: tuple, seed: int, start: int, stop: int, points_total: int,
                 threads: int | None, parquet_dir: str | None = None,
                 backend: str = "core") -> ChunkOutcome:
    """Draw, evaluate and reduce points ``start .. stop - 1`` of a scan of ``points_total``."""
    if backend == "core":
        return _core_chunk(space, plan, seed, start, stop, points_total, threads, parquet_dir)
    t0 = time.perf_counter()
    points = space.points(seed, start, stop)
    t1 = time.perf_counter()
    result = _evaluate(space, points, threads=threads,
                       outputs=chunk_outputs(plan, parquet_dir is not None),
                       backend="reference" if backend == "reference" else "core",
                       **_options(space, backend))
    t2 = time.perf_counter()
    if parquet_dir is not None:
        from .parquet import write_part

        write_part(parquet_dir, space, points, result)
    t3 = time.perf_counter()
    chunk = Chunk(points, result, points_total)
    partials = {item.name: item.reduction.reduce(chunk, item.key) for item in plan}
    t4 = time.perf_counter()
    return ChunkOutcome(start, stop, partials, t1 - t0, t2 - t1, t3 - t2, t4 - t3)


def _evaluate(space: Space, points, **options):
    """:func:`epc_fast.evaluate` at ``points``; per design's readout and modes when the space's
    designs have them (:mod:`epc_fast.scan.running.readout_modes`)."""
    if space.has_modes:
        return evaluate_space_points(space, points, **options)
    return evaluate(**points.parameters, **options)


def _options(space: Space, backend: str) -> dict:
    """The space's evaluate options; the reference backend takes the spectrum, the lens tables,
    the colour sensor, how EPC counts the resolution and the frame cap only."""
    if backend == "reference":
        return {k: v for k, v in space.evaluate_options.items()
                if k in ("spectrum", "lens_mtf", "cfa", "demosaic", "epc_axes",
                         "max_exposure_s")}
    return space.evaluate_options


#: The last scan's CorePlan, reused by its next chunk (a run's chunks, or a Dask worker's
#: tasks, share one space and plan object): one (key, value) entry, read and replaced whole.
_last_plan: list = [None]


def _core_plan(space, plan, seed, points_total) -> tuple:
    """The CorePlan of the reductions the fused pass folds, and the plan items it does not."""
    last = _last_plan[0]
    if (last is not None and last[0][0] is space and last[0][1] is plan
            and last[0][2:] == (seed, points_total)):
        return last[1]
    # the fused pass reads the space's lens tables, colour sensor and the readout modes its
    # designs share (camera_terms.py; None where it cannot: those points are evaluated as
    # arrays). It counts EPC in both directions (kernel.h across_f50) but folds no share then:
    # those take the two passes of epc_fast.axes.
    terms = camera_terms(space)
    both = space.evaluate_options.get("epc_axes", "motion") == "both"
    fused = tuple(item for item in plan if not _per_point(item, points_total)
                  and terms is not None
                  and not (both and item.reduction.of.startswith("share_")))
    arrays = tuple(item for item in plan if item not in fused)
    entry = ((space, plan, seed, points_total), (CorePlan(space, seed, fused, terms), arrays))
    _last_plan[0] = entry
    return entry[1]


def _core_chunk(space, plan, seed, start, stop, points_total, threads, parquet_dir):
    """The fused pass for every reduction it folds; the chunk's points as arrays, formed by
    the core, for exact quantiles and Parquet."""
    t0 = time.perf_counter()
    threads = threads_of(threads)
    core, arrays = _core_plan(space, plan, seed, points_total)
    fused = core.plan
    partials = core.reduce(start, stop, threads) if fused else {}
    core_s = time.perf_counter() - t0
    sampling_s = output_s = reduction_s = 0.0
    if arrays or parquet_dir is not None:
        t1 = time.perf_counter()
        points = core.points(start, stop)
        t2 = time.perf_counter()
        result = _evaluate(space, points, threads=threads,
                           outputs=chunk_outputs(arrays, parquet_dir is not None),
                           **space.evaluate_options)
        t3 = time.perf_counter()
        if parquet_dir is not None:
            from .parquet import write_part

            write_part(parquet_dir, space, points, result)
        t4 = time.perf_counter()
        chunk = Chunk(points, result, points_total)
        partials.update({item.name: item.reduction.reduce(chunk, item.key) for item in arrays})
        sampling_s, output_s, reduction_s = t2 - t1, t4 - t3, time.perf_counter() - t4
        core_s += t3 - t2
    partials = {item.name: partials[item.name] for item in plan}
    return ChunkOutcome(start, stop, partials, sampling_s, core_s, output_s, reduction_s)
