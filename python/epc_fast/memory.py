"""Memory: how much there is, and the output memory the core keeps between calls.

``evaluate`` writes its outputs into new arrays. A new array's pages are mapped on first write
and zeroed by the operating system first: for 10^7 points' default outputs, 500 MB zeroed
before a byte of them is written, a sizeable part of the call's time. So the core keeps the memory of output
arrays (of 1 MiB and more) once they are freed, up to a limit, and hands it to a later call of
about the same size: a scan's next chunk, a benchmark's next round. ``output_cache`` reads and
sets the limit; ``output_cache(0)`` frees what is kept and keeps nothing from then on.

The default limit is the smaller of 1 GiB and a sixteenth of the machine's (or container's)
memory; ``EPC_FAST_OUTPUT_CACHE_MB`` (MiB, >= 0) sets it instead, read when the core is first
loaded.
"""

from __future__ import annotations

import numbers
from typing import NamedTuple

from ._limits import (CACHE_ENV, MAX_CACHE_BYTES, MAX_DEFAULT_CACHE_BYTES, default_cache_bytes,
                      memory_limit_bytes)

__all__ = ["CACHE_ENV", "MAX_CACHE_BYTES", "MAX_DEFAULT_CACHE_BYTES", "OutputCacheState",
           "default_cache_bytes", "memory_limit_bytes", "output_cache"]


class OutputCacheState(NamedTuple):
    """The output cache's limit and the bytes it keeps now, waiting for a call."""

    limit_bytes: int
    retained_bytes: int


def output_cache(limit_bytes: int | None = None) -> OutputCacheState:
    """The output cache's state; with ``limit_bytes`` (an int >= 0), its new limit first.

    Lowering the limit frees the oldest kept memory beyond it; 0 frees all of it and keeps
    none from then on (every call's outputs are new memory, as NumPy's own arrays are).
    """
    from . import _core

    if limit_bytes is not None:
        if isinstance(limit_bytes, bool) or not isinstance(limit_bytes, numbers.Integral):
            raise TypeError(f"limit_bytes must be an int, got {limit_bytes!r}")
        if limit_bytes < 0:
            raise ValueError(f"limit_bytes must be >= 0, got {limit_bytes}")
        limit_bytes = min(int(limit_bytes), MAX_CACHE_BYTES)
    state = _core.output_cache(limit_bytes)
    return OutputCacheState(int(state["limit_bytes"]), int(state["retained_bytes"]))
