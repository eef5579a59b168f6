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

import importlib
from importlib import metadata as _metadata

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

#: The subsystems loaded on first use (``epc_fast.scan``, ``epc_fast.optimize``): importing
#: epc_fast for evaluate loads neither.
_SUBPACKAGES = ("scan", "optimize")

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
    "__version__",
]


def __getattr__(name: str):
    if name in _SUBPACKAGES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBPACKAGES))
