"""epc_fast: the effective pixel count of camera designs, fast.

EPC(L) = 4 S f50(L)^2: how many pixels a camera design is worth at illuminance L, once photon
noise, hand shake during the exposure it needs, diffraction and the pixel aperture are counted
(Xiao, Farrell, Catrysse, Wandell, Proc. SPIE 7250, 2009; the model is ``MODEL.md``).

>>> import epc_fast
>>> r = epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, sensor_area_mm2=15.6751)
>>> r.status is epc_fast.Status.OK
True
"""

from __future__ import annotations

from . import optimize
from .api import Result, evaluate
from .inverse import InverseStatus, crossover_lux, lux_for_epc
from .memory import output_cache
from .params import PARAMETERS
from .presets import Design
from .spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2, Spectrum
from .status import Cause, Status

#: The package's version, the same as pyproject.toml's (a test holds them equal), so that a
#: source tree and an installed wheel report the same.
__version__ = "0.2.0"

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
    "optimize",
    "__version__",
]
