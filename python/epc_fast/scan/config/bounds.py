"""The bounds on every size a scan config controls, checked before anything is allocated."""

from __future__ import annotations

__all__ = ["MAX_POINTS", "MAX_CHUNK_POINTS", "MAX_TOP_K", "MAX_GROUPS", "MAX_CELLS",
           "MAX_SAMPLE_FILE_BYTES", "MAX_EXACT_QUANTILE_POINTS"]

#: Points of one scan: 10^12 is a week of one machine, minutes of a large cluster.
MAX_POINTS = 10**12
#: Points per chunk: memory is ~200 bytes a point, so 2^24 points is ~3.4 GB per chunk.
MAX_CHUNK_POINTS = 1 << 24
#: k of a top-k reduction: each kept point holds every varying parameter (8 bytes each).
MAX_TOP_K = 1_000_000
#: Groups of one reduction (the product of its ``by`` parts' sizes).
MAX_GROUPS = 1_000_000
#: Groups times bins of one histogram or streamed quantiles (8 bytes a cell, held twice).
MAX_CELLS = 20_000_000
#: Bytes of an empirical sample file (one value a line).
MAX_SAMPLE_FILE_BYTES = 64 * 2**20
#: ``exact_up_to`` of quantiles: 16 bytes a kept value, so 2^26 is ~1 GB.
MAX_EXACT_QUANTILE_POINTS = 1 << 26
