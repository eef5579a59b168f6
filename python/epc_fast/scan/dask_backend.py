"""A scan's chunks as tasks on a ``dask.distributed`` cluster (the ``dask`` extra).

Each chunk is one task (:func:`epc_fast.scan.tasks.reduce_chunk`) whose result is its partial
reductions. Results are handed back in block order, the same partials merged in the same order
as a local run: the reductions are the same to the last bit (for workers with the same NumPy
and CPU features as the client, see docs/scan.md). At most twice as many chunks as the cluster
has worker threads are submitted or waiting to be merged at a time, so memory stays bounded.

Every worker must run the client's epc_fast build (version and core level): the workers
present are asked before the first task, and each task checks the worker it lands on (one
that joins later), so another build's numbers are never merged in. A cluster that fails (no
worker left for :data:`WORKERLESS_S` seconds, tasks cancelled or killing their workers) ends
the scan with :class:`~epc_fast.scan.errors.ScanAborted`, which keeps the prefix merged before.
"""

from __future__ import annotations

import time

from .errors import ScanAborted
from .tasks import reduce_chunk

__all__ = ["dask_outcomes", "WorkerMismatch", "build", "WORKERLESS_S"]

#: s, how long a scan waits with no worker in the cluster before it gives up.
WORKERLESS_S = 60.0
#: s, how often a waiting scan checks that the cluster still has workers.
POLL_S = 1.0


class WorkerMismatch(RuntimeError):
    """A Dask worker runs another epc_fast version or core build than the client."""


def build() -> tuple:
    """(epc_fast version, core level) of this process."""
    from .. import __version__, _core

    return __version__, _core.isa


def _describe(found: tuple) -> str:
    return f"epc_fast {found[0]} (core {found[1]})"


def _mismatch(workers: dict, expected: tuple) -> str:
    return (f"Dask worker(s) {', '.join(sorted(workers))} run "
            f"{'; '.join(sorted({_describe(b) for b in workers.values()}))}, not this client's "
            f"{_describe(expected)}: install the same epc_fast on every worker")


def checked_reduce_chunk(expected: tuple, *args):
    """:func:`reduce_chunk` on a worker, after checking that its build is ``expected``."""
    found = build()
    if found != expected:
        raise WorkerMismatch(f"a Dask worker runs {_describe(found)}, not the client's "
                             f"{_describe(expected)}: install the same epc_fast on every worker")
    return reduce_chunk(*args)


def _check_workers(client, expected: tuple) -> None:
    builds = {address: tuple(found) for address, found in client.run(build).items()}
    other = {address: found for address, found in builds.items() if found != expected}
    if other:
        raise WorkerMismatch(_mismatch(other, expected))


def _aborted(error: Exception, merged_points: int) -> ScanAborted:
    """A task or cluster failure as ScanAborted, its message on one line of at most ~300
    characters."""
    if isinstance(error, WorkerMismatch):
        return ScanAborted(str(error))
    text = " ".join(str(error).split()) or "no message"
    text = text if len(text) <= 200 else text[:197] + "..."
    return ScanAborted(f"the Dask cluster failed the scan's tasks ({type(error).__name__}: "
                       f"{text}), after {merged_points:,} points were merged")


def _outcome(future, merged_points: int):
    """The future's outcome; a task or cluster failure as ScanAborted."""
    try:
        return future.result()
    except Exception as error:
        raise _aborted(error, merged_points) from error


def dask_outcomes(client, space, plan, seed, ranges, points, threads, parquet_dir,
                  backend="core"):
    """Yield the :class:`~epc_fast.scan.tasks.ChunkOutcome` of each range, in order."""
    try:
        from distributed import wait
    except ImportError:
        raise ImportError("scans on Dask need dask.distributed: pip install 'epc-fast[dask]'"
                          ) from None
    expected = build()
    _check_workers(client, expected)
    space_future, plan_future = client.scatter([space, plan], broadcast=True)
    limit = 2 * max(1, sum(client.nthreads().values()))
    ranges = iter(ranges)
    number_of = {}
    arrived = {}
    submitted = expected_number = 0
    merged_points = 0
    workerless_since = None

    def top_up():
        nonlocal submitted
        while submitted - expected_number < limit:
            span = next(ranges, None)
            if span is None:
                return
            future = client.submit(checked_reduce_chunk, expected, space_future, plan_future,
                                   seed, *span, points, threads, parquet_dir, backend,
                                   pure=False)
            number_of[future] = submitted
            submitted += 1

    top_up()
    try:
        while number_of:
            try:
                finished, _ = wait(list(number_of), timeout=POLL_S,
                                   return_when="FIRST_COMPLETED")
            except TimeoutError:
                finished = ()
            except Exception as error:  # e.g. the futures cancelled: their workers are gone
                raise _aborted(error, merged_points) from error
            if not finished:
                if client.nthreads():
                    workerless_since = None
                elif workerless_since is None:
                    workerless_since = time.monotonic()
                elif time.monotonic() - workerless_since > WORKERLESS_S:
                    raise ScanAborted(f"the Dask cluster has had no worker for {WORKERLESS_S:g} "
                                      f"s, after {merged_points:,} points were merged")
                continue
            for future in finished:
                arrived[number_of.pop(future)] = _outcome(future, merged_points)
            while expected_number in arrived:
                outcome = arrived.pop(expected_number)
                yield outcome
                merged_points = outcome.stop
                expected_number += 1
            top_up()
    finally:
        for future in number_of:
            future.cancel()
