"""The compiled core, built once per x86-64 micro-architecture level (CMakeLists.txt).

The baseline module (x86-64, SSE2) is imported first and asked which levels the CPU supports;
the widest built module the CPU runs is then imported and its functions are this module's.
No level uses fast-math. The x86-64-v3 and -v4 modules use fused multiply-add and give
bit-identical results (wider vectors only run more lanes per instruction); the baseline has no
fused multiply-add and agrees with them to a few ulp (docs/numerics.md). Set ``EPC_FAST_ISA``
to ``x86-64``, ``x86-64-v3`` or ``x86-64-v4`` to choose one (an error if the CPU or the build
lacks it).

``OMP_NUM_THREADS`` sets the default thread count of every call; it is checked as ``threads=``
is (:func:`checked_default_threads`): the OpenMP runtime itself takes any count and crashes
creating, e.g., 100000 threads, or more than an address-space limit (``ulimit -v``) leaves room
for, so the default is capped below :func:`epc_fast._limits.startable_threads`.
``EPC_FAST_OUTPUT_CACHE_MB`` (:mod:`epc_fast.memory`) is checked when the module loads; its
limits come from :mod:`epc_fast._limits`, which imports nothing of the package, so that the
loader and :mod:`epc_fast.memory` do not import each other.
"""

from __future__ import annotations

import importlib
import os

from ._limits import CACHE_ENV as _CACHE_ENV
from ._limits import MAX_CACHE_BYTES, MAX_THREADS
from ._limits import DEFAULT_THREADS_SHARE as _DEFAULT_THREADS_SHARE
from ._limits import startable_threads as _startable_threads
from ._limits import default_cache_bytes as _default_cache_bytes

#: Level name -> extension module, widest first.
MODULES = {
    "x86-64-v4": "_core_x86_64_v4",
    "x86-64-v3": "_core_x86_64_v3",
    "x86-64": "_core_x86_64",
    "generic": "_core_generic",
}


def _import(module_name):
    try:
        return importlib.import_module(f"{__package__}.{module_name}")
    except ImportError:
        return None


def _omp_counts(text: str) -> list[int] | None:
    """The counts of an ``OMP_NUM_THREADS`` value (``"4"`` or nested ``"4,2"``); None when a
    part is not a whole number."""
    parts = [p.strip() for p in text.split(",")]
    if not all(p.isdigit() for p in parts):
        return None
    return [int(p) for p in parts]


def checked_default_threads() -> int:
    """The thread count a call without ``threads=`` uses, at most :data:`MAX_THREADS`; a
    ValueError naming ``OMP_NUM_THREADS`` when it asks for more, or is not a count. The count
    is capped to the threads whose stacks take at most half the address space left
    (:func:`epc_fast._limits.startable_threads`: fewer under an address-space limit), where an
    explicit ``threads=`` above what can start is refused."""
    text = os.environ.get("OMP_NUM_THREADS", "").strip()
    if text:
        counts = _omp_counts(text)
        if counts is None or not all(1 <= c <= MAX_THREADS for c in counts):
            raise ValueError(f"OMP_NUM_THREADS={text!r}: expected a thread count between 1 and "
                             f"{MAX_THREADS} (as threads=), or comma-separated counts")
    count = default_threads()
    if not 1 <= count <= MAX_THREADS:
        raise ValueError(f"the OpenMP runtime's default of {count} threads is not between 1 and "
                         f"{MAX_THREADS}: set OMP_NUM_THREADS or pass threads=")
    if count <= started_threads():  # threads this Python thread's calls run on already
        return count
    return min(count, _startable_threads(_DEFAULT_THREADS_SHARE))


def _load():
    baseline = _import(MODULES["x86-64"]) or _import(MODULES["generic"])
    if baseline is None:
        raise ImportError("epc_fast's compiled core is missing: reinstall the package")
    supported = dict(baseline.cpu_levels(), **{"x86-64": True, "generic": True})
    forced = os.environ.get("EPC_FAST_ISA", "").strip()
    if forced:
        if forced not in MODULES:
            raise ImportError(f"EPC_FAST_ISA={forced!r}: expected one of {', '.join(MODULES)}")
        if not supported.get(forced, False):
            raise ImportError(f"EPC_FAST_ISA={forced!r}: this CPU does not support it")
        module = _import(MODULES[forced])
        if module is None:
            raise ImportError(f"EPC_FAST_ISA={forced!r}: this build has no such module")
        return forced, module
    for level, name in MODULES.items():
        if supported.get(level, False):
            module = _import(name)
            if module is not None:
                return level, module
    raise ImportError("no epc_fast core module runs on this CPU")  # pragma: no cover


#: The level of the loaded module, e.g. "x86-64-v4".
isa, _module = _load()
globals().update({name: getattr(_module, name) for name in dir(_module)
                  if not name.startswith("__")})

_cache_bytes = _default_cache_bytes()
if _cache_bytes > MAX_CACHE_BYTES:
    raise ValueError(f"{_CACHE_ENV}={os.environ.get(_CACHE_ENV)!r}: expected a size in MiB "
                     f"between 0 and {MAX_CACHE_BYTES >> 20}")
_module.output_cache(_cache_bytes)  # the module's output cache starts at the default limit
