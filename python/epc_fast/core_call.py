"""evaluate's call into the compiled core: the model's columns, the domains (``lens`` in the
call's table count), the lens tables as the core reads them, and the outputs it writes."""

from __future__ import annotations

import math

import numpy as np

from . import params
from ._validation import column, compiled_core
from .outputs import OUTPUT_DTYPES

__all__ = ["core_tables", "run_core"]

#: The wavelengths and weights of a monochromatic call (no spectrum), as the core takes them.
_NO_SPECTRUM = np.empty(0)
_NO_SPECTRUM.flags.writeable = False


def core_tables(lens_tables) -> list | None:
    """The checked lens tables (a sequence of :class:`epc_fast.mtf_table.MtfTable`, or None)
    as the core takes them: (knots, values, coefficients flattened) triples."""
    if lens_tables is None:
        return None
    return [(np.ascontiguousarray(t.frequencies), np.ascontiguousarray(t.values),
             np.ascontiguousarray(t.coefficients).reshape(-1)) for t in lens_tables]


def run_core(arrays, shape, size_is_pixel_count, spec, f50_solver, f50_rtol, t_mpe_solver,
             t_mpe_rtol, threads, out=None, precision="float64", allocate=None,
             lens_tables=None, demosaic_table=None,
             chunk_points=1 << 18, columns_ready=False, epc_axes="motion", modes=None):
    """The core's flat outputs for the model parameters ``arrays`` (PARAMETERS' order) over
    the broadcast ``shape``: ``out``'s arrays (name -> flat array) written and those named in
    ``allocate`` new. ``lens_tables``: the checked ``lens_mtf`` (a list of MtfTable), or None;
    ``demosaic_table``: a colour sensor's demosaicker's MtfTable, or None.
    The core checks for Ctrl-C between chunks of ``chunk_points`` points (it releases the GIL
    inside). ``columns_ready``: every array is 0-d or C-contiguous of ``shape`` (no
    :func:`epc_fast._validation.column` pass). ``epc_axes="both"``: EPC and the status counted
    in both directions (no share or elasticity then; ``f50_across_cyc_per_mm`` may be asked
    for with either). ``modes``: (binning, binning_readout code, frames, alignment_error_um)
    per readout mode, None for a parameter it leaves to its column; each point then has the
    outputs of its best mode, and ``"mode"`` its index."""
    n = math.prod(shape)
    out = {} if out is None else out
    # the core copies an input that shares memory with an output before it runs
    columns = (arrays if columns_ready else  # 0-d: one value
               [a if a.ndim == 0 else column(a, shape) for a in arrays])
    if allocate is None:  # the core's own default: every default output, unless out has them
        allocate = [] if out else list(OUTPUT_DTYPES)
    if spec is None:
        wavelengths = weights = _NO_SPECTRUM
    else:
        wavelengths = np.ascontiguousarray(spec.wavelengths_nm, dtype=np.float64)
        weights = np.ascontiguousarray(spec.weights, dtype=np.float64)
    domains = params.domain_table(len(lens_tables) if lens_tables else 1)
    demosaic = None if demosaic_table is None else core_tables((demosaic_table,))[0]
    return compiled_core().evaluate(columns, size_is_pixel_count, domains, wavelengths, weights,
                                    n, f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision,
                                    threads, chunk_points, out, allocate,
                                    core_tables(lens_tables), demosaic, epc_axes == "both",
                                    modes)
