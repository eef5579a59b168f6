"""The compiled core, built once per x86-64 micro-architecture level (CMakeLists.txt).

The baseline module (x86-64, SSE2) is imported first and asked which levels the CPU supports;
the widest built module the CPU runs is then imported and its functions are this module's.
No level uses fast-math. The x86-64-v3 and -v4 modules use fused multiply-add and give
bit-identical results (wider vectors only run more lanes per instruction); the baseline has no
fused multiply-add and agrees with them to a few ulp (docs/numerics.md). Set ``EPC_FAST_ISA``
to ``x86-64``, ``x86-64-v3`` or ``x86-64-v4`` to choose one (an error if the CPU or the build
lacks it).
"""

from __future__ import annotations

import importlib
import os

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


def _load():
    baseline = _import(MODULES["x86-64"]) or _import(MODULES["generic"])
    if baseline is None:
        raise ImportError("epc_fast's compiled core is missing: reinstall the package")
    supported = dict(baseline.cpu_levels(), **{"x86-64": True, "generic": True})
    forced = os.environ.get("EPC_FAST_ISA")
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

from .memory import default_cache_bytes as _default_cache_bytes  # noqa: E402

_module.output_cache(_default_cache_bytes())  # the module's output cache starts at the default limit
