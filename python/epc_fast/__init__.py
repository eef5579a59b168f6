"""epc_fast: the effective pixel count of camera designs, fast.

EPC(L) = 4 S f50(L)^2: how many pixels a camera design is worth at illuminance L, once photon
noise, hand shake during the exposure it needs, diffraction and the pixel aperture are counted
(Xiao, Farrell, Catrysse, Wandell, Proc. SPIE 7250, 2009; the model is docs/model.md).

>>> import epc_fast
>>> r = epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, sensor_area_mm2=15.6751)
>>> r.status is epc_fast.Status.OK
True
"""

from __future__ import annotations

import dataclasses as _dataclasses
import importlib
from importlib import metadata as _metadata
from importlib import util as _util

from .api import Result, evaluate
from .inverse import InverseStatus, crossover_lux, lux_for_epc
from .memory import output_cache
from .params import PARAMETERS
from .presets import Design
from .spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2, Spectrum
from .status import Cause, Status

#: The installed distribution's version (pyproject.toml's); "0+unknown" for a source tree that
#: was never installed.
try:
    __version__ = _metadata.version("epc-fast")
except _metadata.PackageNotFoundError:  # pragma: no cover - a bare source checkout
    __version__ = "0+unknown"

#: The subsystems loaded on first use (``epc_fast.scan``, ``epc_fast.optimize``,
#: ``epc_fast.simulate``): importing epc_fast for evaluate loads none of them.
_SUBPACKAGES = ("scan", "optimize", "simulate")

__all__ = [
    "evaluate",
    "Result",
    "Design",
    "lux_for_epc",
    "crossover_lux",
    "output_cache",
    "InverseStatus",
    "Status",
    "Cause",
    "Spectrum",
    "PARAMETERS",
    "DEFAULT_ELECTRONS_PER_LUX_S_M2",
    "scan",
    "optimize",
    "simulate",
    "__version__",
    "BuildInfo",
    "build_info",
]


@_dataclasses.dataclass(frozen=True)
class BuildInfo:
    """The compiled core loaded, and the machine it runs on (:func:`build_info`); ``str()``
    gives it in one line, as ``epc-fast --version`` and the main job print it."""

    #: The package's version.
    version: str
    #: The instruction-set level of the module loaded, e.g. "x86-64-v4" (``EPC_FAST_ISA``
    #: chooses another).
    isa: str
    #: The levels this installation has a module for, baseline first.
    built_levels: tuple[str, ...]
    #: The levels this CPU runs, baseline first.
    cpu_levels: tuple[str, ...]
    #: Whether the core was built with OpenMP (without it every call runs on one thread).
    openmp: bool
    #: The threads a call without ``threads=`` runs on (``OMP_NUM_THREADS`` or the cores,
    #: capped to what the process can start).
    default_threads: int

    def core_text(self) -> str:
        """The build without the version, in one line: the core's level, the levels built and
        those the CPU runs, OpenMP and the default threads."""
        return (f"core {self.isa} (built: {', '.join(self.built_levels)}; CPU: "
                f"{', '.join(self.cpu_levels)}), OpenMP {'on' if self.openmp else 'off'}, "
                f"{self.default_threads} threads by default")

    def __str__(self) -> str:
        return f"epc_fast {self.version}, {self.core_text()}"


def build_info() -> BuildInfo:
    """The compiled core loaded (its instruction-set level), the levels built and those the CPU
    runs, OpenMP, the default thread count and the version; loads the core."""
    from . import _core

    levels = ("x86-64", "x86-64-v2", "x86-64-v3", "x86-64-v4")
    supported = dict(_core.cpu_levels(), **{"x86-64": True})
    built = tuple(level for level, name in reversed(_core.MODULES.items())
                  if _util.find_spec(f"{__name__}.{name}") is not None)
    try:
        threads = _core.checked_default_threads()
    except ValueError:  # a bad OMP_NUM_THREADS: each call says so; here the runtime's count
        threads = _core.default_threads()
    return BuildInfo(version=__version__, isa=_core.isa, built_levels=built,
                     cpu_levels=tuple(level for level in levels if supported.get(level)),
                     openmp=bool(_core.openmp_enabled()), default_threads=threads)


def __getattr__(name: str):
    if name in _SUBPACKAGES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBPACKAGES))
