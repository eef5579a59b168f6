"""Capture simulation and its measurements: the slanted-edge e-SFR of ISO 12233:2017
(:mod:`~epc_fast.simulate.slanted_edge`) and the SNR of a flat patch
(:mod:`~epc_fast.simulate.flat_patch`). The modules are not named after the functions they
export, which would hide them (``epc_fast.simulate.esfr`` is the function)."""

from .flat_patch import FlatSNR, snr
from .slanted_edge import EdgeSFR, esfr, mtf50
