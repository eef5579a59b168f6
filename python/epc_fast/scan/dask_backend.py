"""A scan's chunks as tasks on a ``dask.distributed`` cluster (the ``dask`` extra).

Each chunk is one task (:func:`epc_fast.scan.tasks.reduce_chunk`) whose result is its partial
reductions. Results are handed back in block order, the same partials merged in the same order
as a local run: the reductions are the same to the last bit (for workers with the same NumPy
and CPU features as the client, see docs/scan.md). At most twice as many chunks as the cluster
has worker threads are submitted or waiting to be merged at a time, so memory stays bounded.
"""

from __future__ import annotations

from .tasks import reduce_chunk

__all__ = ["dask_outcomes"]


def dask_outcomes(client, space, plan, seed, ranges, points, threads, parquet_dir):
    """Yield the :class:`~epc_fast.scan.tasks.ChunkOutcome` of each range, in order."""
    try:
        from distributed import as_completed
    except ImportError:
        raise ImportError("scans on Dask need dask.distributed: pip install 'epc-fast[dask]'"
                          ) from None
    space_future, plan_future = client.scatter([space, plan], broadcast=True)
    limit = 2 * max(1, sum(client.nthreads().values()))
    ranges = iter(ranges)
    number_of = {}
    waiting = as_completed()
    arrived = {}
    submitted = expected = 0

    def top_up():
        nonlocal submitted
        while submitted - expected < limit:
            span = next(ranges, None)
            if span is None:
                return
            future = client.submit(reduce_chunk, space_future, plan_future, seed, *span, points,
                                   threads, parquet_dir, pure=False)
            number_of[future] = submitted
            submitted += 1
            waiting.add(future)

    top_up()
    try:
        for future in waiting:
            arrived[number_of.pop(future)] = future.result()
            while expected in arrived:
                yield arrived.pop(expected)
                expected += 1
            top_up()
    finally:
        for future in number_of:
            future.cancel()
