"""The bounds a call is checked against: the most threads, how much memory there is, and the
output cache's limits.

An address-space limit (``RLIMIT_AS``, ``ulimit -v``) bounds both: the OpenMP runtime maps a
stack for every thread it starts and ends the process ("Thread creation failed") when one
cannot be mapped, so :func:`startable_threads` counts the stacks the address space still free
holds; :func:`memory_limit_bytes` is at most that free address space.

A leaf module (no import of the package, nor of the compiled core): the core's loader
(:mod:`epc_fast._core`) checks ``OMP_NUM_THREADS`` and reads the cache's default limit from it
when the compiled module loads; :mod:`epc_fast._validation` checks ``threads=`` and
:mod:`epc_fast.memory` the cache's limit against it, without loading the core first.
"""

from __future__ import annotations

import functools
import math
import os
import re

try:
    import resource
except ImportError:  # pragma: no cover - not on POSIX
    resource = None

#: Upper bound on ``threads=`` and ``OMP_NUM_THREADS``: more is a mistake, not a faster run.
MAX_THREADS = 1024

#: The environment variable that sets the output cache's limit, in MiB.
CACHE_ENV = "EPC_FAST_OUTPUT_CACHE_MB"

#: Bytes the output cache's limit may be: the core holds it in a signed 64-bit integer.
MAX_CACHE_BYTES = 2**62

#: The default limit's ceiling (bytes): one 10^7-point default call's outputs (500 MB) fit.
MAX_DEFAULT_CACHE_BYTES = 2**30


#: A thread's stack when ``RLIMIT_STACK`` is unlimited: glibc's default on x86-64.
UNLIMITED_STACK_BYTES = 2 * 2**20

#: Address space a thread maps besides its stack: the guard page, its TLS and the OpenMP
#: runtime's own state (about 50 KiB measured; twice that leaves room).
THREAD_OVERHEAD_BYTES = 128 * 2**10

#: Address space kept free for the call itself when counting the threads that fit.
THREAD_RESERVE_BYTES = 32 * 2**20

#: The share of the free address space the default thread count's stacks may take: the rest
#: stays for the call's data, so that the default stays below the most that can start as the
#: process maps more (a scan passes it on to every chunk as an explicit count).
DEFAULT_THREADS_SHARE = 0.5


def memory_limit_bytes() -> int | None:
    """The memory a call may use: physical memory, or the container's (cgroup) limit where
    lower, or the address space still free under ``RLIMIT_AS`` where lower; None when
    unknown."""
    limits = [m for m in (_physical_memory_bytes(), address_space_free_bytes()) if m is not None]
    return min(limits) if limits else None


def address_space_limit_bytes() -> int | None:
    """The soft ``RLIMIT_AS`` (``ulimit -v``) in bytes; None when unlimited or unknown."""
    if resource is None:  # pragma: no cover
        return None
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    except (AttributeError, ValueError, OSError):  # pragma: no cover
        return None
    return None if soft == resource.RLIM_INFINITY or soft < 0 else int(soft)


def address_space_free_bytes() -> int | None:
    """The address space this process may still map: the soft ``RLIMIT_AS`` less what it has
    mapped now (``/proc/self/statm``); None when there is no such limit."""
    limit = address_space_limit_bytes()
    if limit is None:
        return None
    try:
        with open("/proc/self/statm") as f:
            mapped = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):  # pragma: no cover - no /proc: the limit alone
        mapped = 0
    return max(0, limit - mapped)


def _stack_text_bytes(text: str) -> int | None:
    """An ``OMP_STACKSIZE`` value in bytes, as the OpenMP runtime reads it (a size with an
    optional B, K, M or G; K when none); None when it is not one."""
    match = re.fullmatch(r"\s*(\d+)\s*([bkmgBKMG]?)\s*", text)
    if not match:
        return None
    scale = {"b": 1, "k": 2**10, "": 2**10, "m": 2**20, "g": 2**30}[match.group(2).lower()]
    return int(match.group(1)) * scale


def thread_stack_bytes() -> int:
    """The stack of each thread the OpenMP runtime starts: ``OMP_STACKSIZE`` (or
    ``GOMP_STACKSIZE``) when set, else the soft ``RLIMIT_STACK`` (``ulimit -s``), glibc's
    default for a new thread, or 2 MiB when that is unlimited."""
    for name in ("OMP_STACKSIZE", "GOMP_STACKSIZE"):
        size = _stack_text_bytes(os.environ.get(name, ""))
        if size is not None:
            return size
    if resource is not None:
        try:
            soft, _ = resource.getrlimit(resource.RLIMIT_STACK)
        except (AttributeError, ValueError, OSError):  # pragma: no cover
            soft = resource.RLIM_INFINITY
        if soft != resource.RLIM_INFINITY and soft > 0:
            return int(soft)
    return UNLIMITED_STACK_BYTES


def _running_threads() -> int:
    """The threads of this process now (the OpenMP runtime's kept ones among them)."""
    try:
        return max(1, len(os.listdir("/proc/self/task")))
    except OSError:  # pragma: no cover
        return 1


def new_thread_bytes(threads: int) -> int:
    """The address space a call on ``threads`` threads maps for the stacks of the threads not
    running yet."""
    return max(0, threads - _running_threads()) * (thread_stack_bytes() + THREAD_OVERHEAD_BYTES)


def startable_threads(share: float = 1.0) -> int:
    """The most threads a call can run on: :data:`MAX_THREADS`, or fewer where the address
    space left under ``RLIMIT_AS`` holds fewer thread stacks (:func:`thread_stack_bytes` and
    :data:`THREAD_OVERHEAD_BYTES` each, :data:`THREAD_RESERVE_BYTES` kept for the call), or
    where ``RLIMIT_NPROC`` allows fewer. The threads running now count as started: the OpenMP
    runtime keeps a call's threads for the next. ``share`` < 1 counts only that share of the
    free address space, leaving the rest for the call's data (the default thread count)."""
    count = MAX_THREADS
    free = address_space_free_bytes()
    if free is not None:
        per_thread = thread_stack_bytes() + THREAD_OVERHEAD_BYTES
        usable = int(max(0, free - THREAD_RESERVE_BYTES) * share)
        count = min(count, _running_threads() + usable // per_thread)
    if resource is not None and hasattr(resource, "RLIMIT_NPROC"):
        soft, _ = resource.getrlimit(resource.RLIMIT_NPROC)
        if soft != resource.RLIM_INFINITY and soft > 0:
            count = min(count, int(soft))
    return max(1, count)


def threads_limit_reason() -> str:
    """Why :func:`startable_threads` is below :data:`MAX_THREADS`, for an error message."""
    limit = address_space_limit_bytes()
    if limit is None:
        return "RLIMIT_NPROC (ulimit -u) limits this user's processes and threads"
    return (f"the address space is limited to {limit / 2**30:,.2f} GiB by RLIMIT_AS "
            f"(ulimit -v), {(address_space_free_bytes() or 0) / 2**30:,.2f} GiB of it free, and "
            f"each thread maps a stack of {thread_stack_bytes() / 2**20:,.4g} MiB "
            "(OMP_STACKSIZE or ulimit -s)")


@functools.lru_cache(maxsize=None)
def _physical_memory_bytes() -> int | None:
    """Physical memory, or the container's (cgroup) limit where lower; None when unknown."""
    limits = []
    try:
        limits.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        pass
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path) as f:
                text = f.read().strip()
        except OSError:
            continue
        if text.isdigit():
            limits.append(int(text))
    return min(limits) if limits else None


def default_cache_bytes() -> int:
    """The output cache's limit when the core is loaded: ``EPC_FAST_OUTPUT_CACHE_MB`` MiB if
    set, else min(1 GiB, memory / 16)."""
    text = os.environ.get(CACHE_ENV, "").strip()
    if text:
        try:
            mib = float(text)
        except ValueError:
            mib = math.nan
        if not (math.isfinite(mib) and mib >= 0):
            raise ValueError(f"{CACHE_ENV}={text!r}: expected a size in MiB, >= 0")
        return int(mib * 2**20)
    memory = memory_limit_bytes()
    return MAX_DEFAULT_CACHE_BYTES if memory is None else min(MAX_DEFAULT_CACHE_BYTES,
                                                              memory // 16)
