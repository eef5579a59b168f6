"""The NumPy reference of the colour filter array's MTF term (docs/model.md, "The colour filter
array"; issue #40): the demosaicker's luminance MTF, a table in cycles per output pixel
(:func:`epc_fast.cfa.demosaic_mtf_table`), at f p_out. The CFA's transmittance multiplies the
electron rate and its noise gains every noise variance (:mod:`epc_fast.reference.model`).
"""

from __future__ import annotations

import numpy as np

from ..mtf_table import mtf_tabulated

__all__ = ["mtf_demosaic", "demosaic_log_factor"]


def mtf_demosaic(f_cyc_per_mm, output_pitch_um, table):
    """1: M_dem(f p_out), the demosaicker's luminance MTF ``table`` (an MtfTable in cycles per
    output pixel, held at its last value past its end) at f p_out, p_out = k p in mm."""
    x = np.asarray(f_cyc_per_mm, dtype=np.float64) * (np.asarray(output_pitch_um) * 1e-3)
    return mtf_tabulated(x, table)[0]


def demosaic_log_factor(f_cyc_per_mm, output_pitch_um, table):
    """1: (ln M_dem, f d ln M_dem / df) at f: the share's numerator and the log-slope (also
    the output pitch's, p d ln M_dem / dp, as M_dem is a function of f p)."""
    x = np.asarray(f_cyc_per_mm, dtype=np.float64) * (np.asarray(output_pitch_um) * 1e-3)
    value, slope, _ = mtf_tabulated(x, table)
    return np.log(value), x * slope / value
