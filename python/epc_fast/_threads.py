"""The bound on thread counts.

A leaf module (no import of the package, nor of the compiled core): the core's loader
(:mod:`epc_fast._core`) checks ``OMP_NUM_THREADS`` against it, and :mod:`epc_fast.api`, which
checks ``threads=``, re-exports it without loading the core.
"""

#: Upper bound on ``threads=`` and ``OMP_NUM_THREADS``: more is a mistake, not a faster run.
MAX_THREADS = 1024
