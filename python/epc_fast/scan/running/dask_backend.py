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


class _InFlight:
    """A scan's chunk tasks on a Dask cluster: at most twice as many as the cluster has threads
    ahead of the next chunk to merge, the space and the plan sent once (again when lost), a lost
    task submitted again (at most :data:`RESUBMITS` times), and the outcomes kept until they are
    given in order."""

    def __init__(self, client, expected: tuple, space, plan, seed, ranges, rest: tuple):
        self.client, self.expected, self.space, self.plan = client, expected, space, plan
        self.seed, self.rest = seed, rest  # rest: points, threads, parquet_dir, backend
        self.sources = []
        self.limit = 2 * max(1, sum(client.nthreads().values()))
        self.ranges = iter(ranges)
        self.number_of = {}  # future -> chunk number
        self.span_of = {}  # chunk number -> (start, stop)
        self.resubmitted = {}
        self.arrived = {}  # chunk number -> outcome
        self.submitted = self.next_number = 0
        self.merged_points = 0
        self.workerless_since = None
        self.merged_at = time.monotonic()

    def _sources_now(self) -> list:
        if not self.sources or any(_lost(source) for source in self.sources):
            self.sources[:] = [self.client.submit(_value, self.space, pure=False),
                               self.client.submit(_value, self.plan, pure=False)]
        return self.sources

    def _submit(self, number: int, span: tuple) -> None:
        future = self.client.submit(checked_reduce_chunk, self.expected, *self._sources_now(),
                                    self.seed, *span, *self.rest, pure=False)
        self.number_of[future] = number
        self.span_of[number] = span

    def top_up(self) -> None:
        """Submit the next chunks, up to the limit ahead of the next one to merge."""
        while self.submitted - self.next_number < self.limit:
            span = next(self.ranges, None)
            if span is None:
                return
            self._submit(self.submitted, span)
            self.submitted += 1

    def _take(self, future) -> bool:
        """Keep a finished chunk's outcome or submit a lost one again (True); False when its
        result was lost after it finished and the cluster is computing it again."""
        number = self.number_of.pop(future)
        if _lost(future):
            self.resubmitted[number] = self.resubmitted.get(number, 0) + 1
            if self.resubmitted[number] > RESUBMITS:
                span = self.span_of[number]
                raise ScanAborted(
                    f"the Dask cluster lost the task of points {span[0]:,} to "
                    f"{span[1] - 1:,} {self.resubmitted[number]} times, after "
                    f"{self.merged_points:,} points were merged")
            try:
                self._submit(number, self.span_of[number])
            except Exception as error:  # e.g. the client lost its scheduler
                raise _aborted(error, self.merged_points) from error
            return True
        try:
            self.arrived[number] = future.result(timeout=POLL_S)
        except TimeoutError:  # its worker left with the result: waited for again
            self.number_of[future] = number
            return False
        except Exception as error:
            raise _aborted(error, self.merged_points) from error
        del self.span_of[number]
        return True

    def check_stall(self, stall_s: float) -> None:
        """A :class:`ScanAborted` when no chunk was merged for ``stall_s`` seconds."""
        if time.monotonic() - self.merged_at > stall_s:
            waited = next((f for f, n in self.number_of.items() if n == self.next_number), None)
            raise _stalled(stall_s, self.span_of[self.next_number], waited,
                           len(self.client.nthreads()), self.merged_points)

    def took_some(self, wait) -> bool:
        """Wait up to :data:`POLL_S` for tasks to finish; whether one gave its outcome or was
        submitted again."""
        failure = None
        try:
            wait(list(self.number_of), timeout=POLL_S, return_when="FIRST_COMPLETED")
        except TimeoutError:
            pass
        except Exception as error:  # futures cancelled (their task lost): submitted again
            failure = error
        finished = [future for future in self.number_of if future.status != "pending"]
        if failure is not None and not finished:
            raise _aborted(failure, self.merged_points) from failure
        return bool([future for future in finished if self._take(future)])

    def check_workers(self) -> None:
        """A :class:`ScanAborted` when the cluster has had no worker for
        :data:`WORKERLESS_S` seconds."""
        if self.client.nthreads():
            self.workerless_since = None
        elif self.workerless_since is None:
            self.workerless_since = time.monotonic()
        elif time.monotonic() - self.workerless_since > WORKERLESS_S:
            raise ScanAborted(f"the Dask cluster has had no worker for {WORKERLESS_S:g} "
                              f"s, after {self.merged_points:,} points were merged")

    def merged(self, outcome) -> None:
        """Note that ``outcome``, the next chunk's, was merged."""
        self.merged_points = outcome.stop
        self.merged_at = time.monotonic()
        self.next_number += 1

    def cancel(self) -> None:
        for future in [*self.number_of, *self.sources]:
            future.cancel()


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
    chunks = _InFlight(client, expected, space, plan, seed, ranges,
                       (points, threads, parquet_dir, backend))
    chunks.top_up()
    try:
        while chunks.number_of:
            chunks.check_stall(stall_s)
            if not chunks.took_some(wait):
                chunks.check_workers()
                continue
            while chunks.next_number in chunks.arrived:
                outcome = chunks.arrived.pop(chunks.next_number)
                yield outcome
                chunks.merged(outcome)
            chunks.top_up()
    finally:
        chunks.cancel()
