"""evaluate's call into the NumPy reference: the model's columns broadcast to points, their
domains checked, the model's outputs and the sensitivities asked for (as
:mod:`epc_fast.core_call` is its call into the compiled core)."""

from __future__ import annotations

import math

import numpy as np

from .. import elasticity_outputs, params
from ..outputs import SHARE_OUTPUTS

__all__ = ["run_reference"]


def run_reference(arrays, shape, size_is_pixel_count, spec, computed=(), lens_tables=None,
                  demosaic_table=None) -> dict:
    """The reference's flat outputs for the model parameters ``arrays`` (PARAMETERS' order)
    over the broadcast ``shape``: every model output, and the shares and elasticity rows named
    in ``computed``. ``spec``: the Spectrum, or None for monochromatic; ``lens_tables``: the
    checked ``lens_mtf`` (a list of MtfTable), or None; ``demosaic_table``: a colour sensor's
    demosaicker's MtfTable, or None."""
    from . import model, sensitivity

    n = math.prod(shape)
    p = {name: np.broadcast_to(a, shape).reshape(n)
         for name, a in zip(params.PARAMETER_NAMES, arrays)}
    valid = np.ones(n, dtype=bool)
    for param in params.parameters(1 if lens_tables is None else len(lens_tables)):
        valid &= params.in_domain(param, p[param.name])
    wavelengths = weights = None
    if spec is not None:
        wavelengths, weights = spec.wavelengths_nm, spec.weights
    result = model.evaluate_points(p, size_is_pixel_count, wavelengths, weights, valid,
                                   lens_tables=lens_tables, demosaic_table=demosaic_table)
    shares = any(name in computed for name in SHARE_OUTPUTS)
    rows = elasticity_outputs.rows_in(computed)
    if shares or rows:
        result.update(sensitivity.sensitivity_points(
            p, size_is_pixel_count, wavelengths, weights, result, shares=shares,
            elasticities=bool(rows), lens_tables=lens_tables, demosaic_table=demosaic_table))
    if rows and elasticity_outputs.ALL not in computed:  # the rows asked for, one output each
        every = dict(zip(elasticity_outputs.ROWS, result.pop(elasticity_outputs.ALL)))
        result.update({row: every[row] for row in rows})
    return result
