"""One chunk of a scan, start to end: draw its points, evaluate them, reduce them.

This is the unit of work of both backends: the local loop calls it in order, and on Dask it
is the task a worker runs. Its outcome holds only partial reductions (small), never points.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..api import evaluate
from .chunk import Chunk
from .groups import GroupKey
from .space import Space

__all__ = ["PlanItem", "ChunkOutcome", "chunk_outputs", "reduce_chunk"]


@dataclass(frozen=True)
class PlanItem:
    """A named reduction and its group key resolved against the scan's space."""

    name: str
    reduction: object
    key: GroupKey


@dataclass
class ChunkOutcome:
    """The partial reductions of points ``start .. stop - 1`` and what they cost.

    Attributes
    ----------
    start, stop : point indices.
    partials : {reduction name: partial}.
    sampling_s, core_s, output_s, reduction_s : s, time drawing the points, in
        :func:`epc_fast.evaluate`, writing Parquet, and reducing.
    """

    start: int
    stop: int
    partials: dict
    sampling_s: float
    core_s: float
    output_s: float
    reduction_s: float


def chunk_outputs(plan: tuple, parquet: bool) -> tuple | None:
    """The :class:`~epc_fast.Result` fields a chunk needs: the output of each reduction and the
    status (summaries count statuses), or every field (None) when the points go to Parquet.
    The core computes only these (``evaluate(outputs=...)``): without f50 or EPC among them it
    does not solve f50 at all."""
    if parquet:
        return None
    return ("status",) + tuple(sorted({item.reduction.of for item in plan}))


def reduce_chunk(space: Space, plan: tuple, seed: int, start: int, stop: int, points_total: int,
                 threads: int | None, parquet_dir: str | None = None) -> ChunkOutcome:
    """Draw, evaluate and reduce points ``start .. stop - 1`` of a scan of ``points_total``."""
    t0 = time.perf_counter()
    points = space.points(seed, start, stop)
    t1 = time.perf_counter()
    result = evaluate(**points.parameters, threads=threads,
                      outputs=chunk_outputs(plan, parquet_dir is not None),
                      **space.evaluate_options)
    t2 = time.perf_counter()
    if parquet_dir is not None:
        from .parquet import write_part

        write_part(parquet_dir, space, points, result)
    t3 = time.perf_counter()
    chunk = Chunk(points, result, points_total)
    partials = {item.name: item.reduction.reduce(chunk, item.key) for item in plan}
    t4 = time.perf_counter()
    return ChunkOutcome(start, stop, partials, t1 - t0, t2 - t1, t3 - t2, t4 - t3)
