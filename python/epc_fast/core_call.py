"""evaluate's call into the compiled core, and the parameters and outputs of the loaded core.

The core names its parameters (``_core.parameter_names``, in params.h's order) and its shares.
A parameter of :data:`epc_fast.params.PARAMETERS` that the loaded core does not name (``lens``,
until the core computes lens tables) is not passed to it: a point where that parameter is
outside its domain is made INVALID by a NaN in the core's ``mtf_threshold`` column (the caller's
``invalid="raise"`` then names the real culprit), and the outputs the core lacks are filled
here: a share it lacks is 0 where its ``share_aberration`` (a term it has off) is 0 and NaN where
that is NaN, and an elasticity it lacks (a whole number's) is NaN. Once the core names every
parameter and share, all of this passes everything through unchanged.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from . import elasticity_outputs, params
from ._validation import column
from .outputs import OUTPUT_DTYPES, SHARE_OUTPUTS

__all__ = ["core_slots", "for_core", "run_core"]

#: The share whose values (0 or NaN) a share the core lacks takes: the wavefront error's,
#: which the core has off.
_OFF_SHARE = "share_aberration"


@functools.cache
def core_slots() -> tuple[int, ...]:
    """The positions in PARAMETERS of the parameters the loaded core takes, in its order."""
    from . import _core

    return tuple(params.PARAMETER_NAMES.index(name) for name in _core.parameter_names)


def for_core(columns: list, domains: np.ndarray) -> tuple[list, np.ndarray]:
    """``columns`` (one per parameter of PARAMETERS, each of size 1 or n) and the ``domains``
    table as the loaded core takes them: those it names. A point whose dropped parameter lies
    outside its domain gets a NaN threshold (INVALID in the core); a dropped column that is a
    scalar inside its domain costs nothing."""
    slots = core_slots()
    if len(slots) == len(columns):
        return columns, domains
    threshold = params.PARAMETER_NAMES.index("mtf_threshold")
    table = params.parameters()
    for j in sorted(set(range(len(columns))) - set(slots)):
        lo, hi = domains[j, 0], domains[j, 1]
        param = params.Param(table[j].name, table[j].default, lo, hi, bool(domains[j, 2]),
                             bool(domains[j, 3]), table[j].meaning, bool(domains[j, 4]))
        outside = ~params.in_domain(param, columns[j])
        if outside.any():
            n = max(columns[threshold].size, columns[j].size)
            columns = list(columns)
            columns[threshold] = np.where(outside, np.nan,
                                          np.broadcast_to(columns[threshold], (n,)))
    return [columns[j] for j in slots], np.ascontiguousarray(domains[list(slots)])


def _outputs_for_core(out: dict, allocate: list, n: int):
    """(out, allocate, filled) for the core: ``out`` and ``allocate`` without the outputs it
    lacks, every elasticity as one row each of a (rows, n) array when the core lacks some
    rows, and ``filled``, the arrays this module writes (name -> array)."""
    from . import _core

    known = set(_core.parameter_names)
    missing_rows = [row for row in elasticity_outputs.ROWS
                    if row[len("elasticity_"):] not in known]
    # share_lens comes with the core's lens term
    core_shares = SHARE_OUTPUTS if "lens" in known else tuple(
        s for s in SHARE_OUTPUTS if s != "share_lens")
    filled = {}
    if not missing_rows and len(core_shares) == len(SHARE_OUTPUTS):
        return out, allocate, filled
    out = dict(out)
    allocate = list(allocate)
    every = elasticity_outputs.ALL
    if missing_rows and (every in out or every in allocate):
        array = out.pop(every) if every in out else np.empty(len(elasticity_outputs.ROWS) * n)
        if every in allocate:
            allocate.remove(every)
        rows = array.reshape(len(elasticity_outputs.ROWS), n)
        for row, values in zip(elasticity_outputs.ROWS, rows):
            (filled if row in missing_rows else out)[row] = values
        filled[every] = array
    for name in missing_rows + [s for s in SHARE_OUTPUTS if s not in core_shares]:
        if name in allocate:
            allocate.remove(name)
            filled[name] = np.empty(n)
        elif name in out:
            filled[name] = out.pop(name)
    if any(name in SHARE_OUTPUTS for name in filled) and not (_OFF_SHARE in out
                                                               or _OFF_SHARE in allocate):
        allocate.append(_OFF_SHARE)
    return out, allocate, filled


def run_core(arrays, shape, size_is_pixel_count, spec, f50_solver, f50_rtol, t_mpe_solver,
             t_mpe_rtol, threads, out=None, precision="float64", allocate=None,
             binning_readout="digital", lens_tables=None, chunk_points=1 << 18):
    """The core's flat outputs for the model parameters ``arrays`` (PARAMETERS' order) over
    the broadcast ``shape``: ``out``'s arrays (name -> flat array) written and those named in
    ``allocate`` new. ``lens_tables`` (the checked ``lens_mtf``, a list of MtfTable) is for the
    core's lens term; evaluate refuses a call with them on the core until it has one. The core
    checks for Ctrl-C between chunks of ``chunk_points`` points (it releases the GIL inside)."""
    from . import _core

    n = math.prod(shape)
    out = {} if out is None else out
    columns = [column(a, shape) for a in arrays]
    if out:  # an input that is also an output would be overwritten while read
        columns = [c.copy() if any(np.may_share_memory(c, o) for o in out.values()) else c
                   for c in columns]
    columns, domains = for_core(columns, params.domain_table(len(lens_tables or ()) or 1))
    if allocate is None:  # the core's own default: every default output, unless out has them
        allocate = [] if out else list(OUTPUT_DTYPES)
    core_out, core_allocate, filled = _outputs_for_core(out, allocate, n)
    if spec is None:
        wavelengths = weights = np.empty(0)
    else:
        wavelengths, weights = spec.wavelengths_nm, spec.weights
    result = _core.evaluate(columns, size_is_pixel_count, domains,
                            np.ascontiguousarray(wavelengths, dtype=np.float64),
                            np.ascontiguousarray(weights, dtype=np.float64), n, f50_solver,
                            f50_rtol, t_mpe_solver, t_mpe_rtol, precision, threads,
                            chunk_points, core_out, core_allocate,
                            binning_readout=binning_readout)
    for name, array in filled.items():
        if name in SHARE_OUTPUTS:
            np.multiply(result[_OFF_SHARE], 0.0, out=array)  # 0, and NaN where it is NaN
        elif name != elasticity_outputs.ALL:
            array.fill(np.nan)
        result[name] = array
    if elasticity_outputs.ALL in filled:  # its rows, one output each, are inside it
        for row in elasticity_outputs.ROWS:
            result.pop(row, None)
    return result
