"""A scan's chunks as tasks on a ``dask.distributed`` cluster (the ``dask`` extra).

Each chunk is one task (:func:`epc_fast.scan.running.tasks.reduce_chunk`) whose result is its
partial reductions. Results are handed back in block order, the same partials merged in the same
order as a local run: the reductions are the same to the last bit (for workers with the same NumPy
and CPU features as the client, see docs/scan.md). At most twice as many chunks as the cluster
has worker threads are submitted or waiting to be merged at a time, so memory stays bounded.

Every worker must run the client's epc_fast build (version and core level): the workers
present are asked before the first task, and each task checks the worker it lands on (one
that joins later), so another build's numbers are never merged in.

Workers may die and join while the scan runs. The space and the plan reach the workers as the
results of two small tasks, not as scattered data: when every worker holding them is gone, the
cluster computes them again for the workers left or new, where scattered data would be lost and
take every chunk with it. A chunk whose worker dies is run again by the cluster (up to its
``distributed.scheduler.allowed-failures``); a chunk whose task is lost all the same (cancelled)
is submitted again by the scan, up to :data:`RESUBMITS` times. The scan ends with
:class:`~epc_fast.jobs.errors.ScanAborted`, which keeps the prefix merged before, only when the
cluster is lost: no worker for :data:`WORKERLESS_S` seconds, a chunk that killed its workers
more often than the cluster allows (``KilledWorker``) or was lost more than :data:`RESUBMITS`
times, or a task that fails; or when it stalls: no chunk merged for the stall timeout (the Dask
config key ``epc-fast.stall-timeout``, :data:`STALL_TIMEOUT_S` by default), whatever the cause
(a hung worker, a task the scheduler never runs again). Its tasks are then cancelled.
"""

from __future__ import annotations

import time

from .aborted import ScanAborted
from .tasks import reduce_chunk

__all__ = ["dask_outcomes", "WorkerMismatch", "build", "WORKERLESS_S", "RESUBMITS",
           "STALL_TIMEOUT_S", "STALL_CONFIG_KEY", "stall_timeout_s"]

#: s, how long a scan waits with no worker in the cluster before it gives up.
WORKERLESS_S = 60.0
#: s, how often a waiting scan checks that the cluster still has workers.
POLL_S = 1.0
#: Times a chunk whose task the cluster lost (cancelled) is submitted again.
RESUBMITS = 3
#: s, how long a scan waits for its next chunk to merge before it ends as stalled, by default:
#: ten times the longest a healthy chunk takes (2**24 points, the largest chunk, on the
#: reference backend at ~10**5 points/s: about 3 minutes).
STALL_TIMEOUT_S = 1800.0
#: The Dask config key that sets the stall timeout (a number of seconds or a duration such as
#: "2 hours"; in the environment ``DASK_EPC_FAST__STALL_TIMEOUT``).
STALL_CONFIG_KEY = "epc-fast.stall-timeout"


class WorkerMismatch(RuntimeError):
    """A Dask worker runs another epc_fast version or core build than the client."""


def build() -> tuple:
    """(epc_fast version, core level) of this process."""
    from ... import __version__, _core

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


def stall_timeout_s() -> float:
    """s, the stall timeout: the Dask config's ``epc-fast.stall-timeout``, else
    :data:`STALL_TIMEOUT_S`; a ValueError for a value that is not a positive duration."""
    import dask.config
    from dask.utils import parse_timedelta

    value = dask.config.get(STALL_CONFIG_KEY, default=None)
    if value is None:
        return STALL_TIMEOUT_S
    try:
        seconds = parse_timedelta(value, default="seconds")
    except (TypeError, ValueError, KeyError):
        seconds = None
    if not isinstance(seconds, (int, float)) or not seconds > 0:
        raise ValueError(f"Dask config {STALL_CONFIG_KEY} = {value!r}: expected a positive "
                         "number of seconds or a duration such as '30 minutes'")
    return float(seconds)


def _stalled(stall_s: float, span: tuple, future, workers: int, merged_points: int
             ) -> ScanAborted:
    state = "not submitted" if future is None else f"its task {future.status}"
    return ScanAborted(
        f"the Dask cluster merged no chunk for {stall_s:g} s ({STALL_CONFIG_KEY}), waiting for "
        f"points {span[0]:,} to {span[1] - 1:,} ({state}, {workers} worker(s)), after "
        f"{merged_points:,} points were merged")


def _value(value):
    """``value``, as a task's result: data the cluster can compute again when it is lost."""
    return value


def _lost(future) -> bool:
    """Whether the cluster lost the future's task or result (cancelled, forgotten)."""
    return future.status in ("cancelled", "lost")


def dask_outcomes(client, space, plan, seed, ranges, points, threads, parquet_dir,
                  backend="core"):
    """Yield the :class:`~epc_fast.scan.running.tasks.ChunkOutcome` of each range, in order."""
    try:
        from distributed import wait
    except ImportError:
        raise ImportError("scans on Dask need dask.distributed: pip install 'epc-fast[dask]'"
                          ) from None
    expected = build()
    stall_s = stall_timeout_s()
    _check_workers(client, expected)
    sources = []

    def sources_now():
        if not sources or any(_lost(source) for source in sources):
            sources[:] = [client.submit(_value, space, pure=False),
                          client.submit(_value, plan, pure=False)]
        return sources

    limit = 2 * max(1, sum(client.nthreads().values()))
    ranges = iter(ranges)
    number_of = {}
    span_of = {}
    resubmitted = {}
    arrived = {}
    submitted = expected_number = 0
    merged_points = 0
    workerless_since = None
    merged_at = time.monotonic()

    def submit(number, span):
        future = client.submit(checked_reduce_chunk, expected, *sources_now(), seed, *span,
                               points, threads, parquet_dir, backend, pure=False)
        number_of[future] = number
        span_of[number] = span

    def top_up():
        nonlocal submitted
        while submitted - expected_number < limit:
            span = next(ranges, None)
            if span is None:
                return
            submit(submitted, span)
            submitted += 1

    def take(future) -> bool:
        """Keep a finished chunk's outcome or submit a lost one again (True); False when its
        result was lost after it finished and the cluster is computing it again."""
        number = number_of.pop(future)
        if _lost(future):
            resubmitted[number] = resubmitted.get(number, 0) + 1
            if resubmitted[number] > RESUBMITS:
                raise ScanAborted(
                    f"the Dask cluster lost the task of points {span_of[number][0]:,} to "
                    f"{span_of[number][1] - 1:,} {resubmitted[number]} times, after "
                    f"{merged_points:,} points were merged")
            try:
                submit(number, span_of[number])
            except Exception as error:  # e.g. the client lost its scheduler
                raise _aborted(error, merged_points) from error
            return True
        try:
            arrived[number] = future.result(timeout=POLL_S)
        except TimeoutError:  # its worker left with the result: waited for again
            number_of[future] = number
            return False
        except Exception as error:
            raise _aborted(error, merged_points) from error
        del span_of[number]
        return True

    top_up()
    try:
        while number_of:
            if time.monotonic() - merged_at > stall_s:
                waited = next((f for f, n in number_of.items() if n == expected_number), None)
                raise _stalled(stall_s, span_of[expected_number], waited,
                               len(client.nthreads()), merged_points)
            failure = None
            try:
                wait(list(number_of), timeout=POLL_S, return_when="FIRST_COMPLETED")
            except TimeoutError:
                pass
            except Exception as error:  # futures cancelled (their task lost): submitted again
                failure = error
            finished = [future for future in number_of if future.status != "pending"]
            if failure is not None and not finished:
                raise _aborted(failure, merged_points) from failure
            if not [future for future in finished if take(future)]:
                if client.nthreads():
                    workerless_since = None
                elif workerless_since is None:
                    workerless_since = time.monotonic()
                elif time.monotonic() - workerless_since > WORKERLESS_S:
                    raise ScanAborted(f"the Dask cluster has had no worker for {WORKERLESS_S:g} "
                                      f"s, after {merged_points:,} points were merged")
                continue
            while expected_number in arrived:
                outcome = arrived.pop(expected_number)
                yield outcome
                merged_points = outcome.stop
                merged_at = time.monotonic()
                expected_number += 1
            top_up()
    finally:
        for future in [*number_of, *sources]:
            future.cancel()
