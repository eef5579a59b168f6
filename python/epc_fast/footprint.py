"""Whether a call of :func:`epc_fast.evaluate` fits in memory, checked before anything is
allocated: a MemoryError that says so, rather than NumPy's midway or the kernel's
out-of-memory killer."""

from __future__ import annotations

import functools
import math

from . import _limits, elasticity_outputs
from .outputs import OUTPUT_DTYPES, SHARE_OUTPUTS, output_bytes

__all__ = ["BYTES_PER_POINT", "SENSITIVITY_BYTES_FACTOR", "UNCHECKED_BYTES", "check_memory"]


#: Bytes a backend allocates per point besides the inputs: the core its eight output columns
#: (6 float64 + 2 uint8); the reference peaks near 320 (tracemalloc, 2e5 random designs), twice
#: that leaves room.
BYTES_PER_POINT = {"core": 6 * 8 + 2, "reference": 640}
#: The reference's peak per byte of a sensitivity output it returns: its temporaries hold a few
#: copies of each (tracemalloc on 2e5 random designs stays below 4).
SENSITIVITY_BYTES_FACTOR = 4
#: A call that needs at most this much is not checked: reading the limits (the cgroup's files,
#: /proc) costs more than such a call's points, and an allocation this small that fails is
#: NumPy's MemoryError, not the kernel's out-of-memory killer.
UNCHECKED_BYTES = 4 * 2**20


@functools.lru_cache(maxsize=64)
def _bytes_per_point(outputs: tuple) -> int:
    """Bytes a point of ``outputs`` takes."""
    return sum(output_bytes(k) for k in outputs)


def check_memory(shape, arrays, backend, out_given, computed=tuple(OUTPUT_DTYPES), threads=1):
    """A MemoryError, before any allocation, for a call that cannot fit in memory: physical
    memory (or the container's), or under an address-space limit (``RLIMIT_AS``) the address
    space left, less the stacks of the ``threads`` not started yet.

    A call that needs at most :data:`UNCHECKED_BYTES` is not checked. The estimate counts the
    contiguous copy of every input that is not a scalar and the backend's own arrays; a call that fits the estimate may still fail with NumPy's own
    MemoryError, but none is left to the kernel's out-of-memory killer by a silly shape.
    """
    n = math.prod(shape)
    if backend == "core":  # the outputs it computes, unless the caller gave them
        own = 0 if out_given else _bytes_per_point(tuple(computed))
    else:  # the reference forms every elasticity for any of them
        formed = [k for k in SHARE_OUTPUTS if k in computed]
        formed += ["elasticities"] if elasticity_outputs.rows_in(computed) else []
        own = BYTES_PER_POINT[backend] + sum(output_bytes(k) * SENSITIVITY_BYTES_FACTOR
                                             for k in formed)
    if n * (8 * len(arrays) + own) <= UNCHECKED_BYTES:  # even were every input an array
        return
    needed = n * (8 * sum(1 for a in arrays if a.size > 1) + own)
    if needed <= UNCHECKED_BYTES:
        return
    limit = _limits.memory_limit_bytes()
    where = "of memory here"
    free = _limits.address_space_free_bytes()
    if free is not None:
        free = max(0, free - _limits.new_thread_bytes(threads))
        if limit is None or free <= limit:
            limit, where = free, "of address space left under RLIMIT_AS (ulimit -v)"
    if limit is not None and needed > limit:
        raise MemoryError(f"evaluate over the broadcast shape {shape} ({n:,} points) needs "
                          f"about {needed / 2**30:,.1f} GiB, more than the "
                          f"{limit / 2**30:,.1f} GiB {where}; evaluate it in pieces")
