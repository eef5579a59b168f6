"""The bounds a call is checked against: the most threads, how much memory there is, and the
output cache's limits.

A leaf module (no import of the package, nor of the compiled core): the core's loader
(:mod:`epc_fast._core`) checks ``OMP_NUM_THREADS`` and reads the cache's default limit from it
when the compiled module loads; :mod:`epc_fast._validation` checks ``threads=`` and
:mod:`epc_fast.memory` the cache's limit against it, without loading the core first.
"""

from __future__ import annotations

import functools
import math
import os

#: Upper bound on ``threads=`` and ``OMP_NUM_THREADS``: more is a mistake, not a faster run.
MAX_THREADS = 1024

#: The environment variable that sets the output cache's limit, in MiB.
CACHE_ENV = "EPC_FAST_OUTPUT_CACHE_MB"

#: Bytes the output cache's limit may be: the core holds it in a signed 64-bit integer.
MAX_CACHE_BYTES = 2**62

#: The default limit's ceiling (bytes): one 10^7-point default call's outputs (500 MB) fit.
MAX_DEFAULT_CACHE_BYTES = 2**30


@functools.lru_cache(maxsize=None)
def memory_limit_bytes() -> int | None:
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
