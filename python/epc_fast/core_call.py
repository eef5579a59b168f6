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


@functools.cache
def _missing() -> tuple[tuple[int, ...], tuple[str, ...]]:
    """The positions in PARAMETERS of the parameters the loaded core lacks, and the outputs
    it lacks: their elasticities, and share_lens, which comes with the core's lens term."""
    slots = core_slots()
    dropped = tuple(j for j in range(len(params.PARAMETERS)) if j not in slots)
    outputs = tuple(f"elasticity_{params.PARAMETER_NAMES[j]}" for j in dropped)
    if "lens" in (params.PARAMETER_NAMES[j] for j in dropped):
        outputs += ("share_lens",)
    return dropped, outputs


def for_core(columns: list, domains: np.ndarray) -> tuple[list, np.ndarray]:
    """``columns`` (one per parameter of PARAMETERS, each of size 1 or n) and the ``domains``
    table as the loaded core takes them: those it names. A point whose dropped parameter lies
    outside its domain gets a NaN threshold (INVALID in the core); a dropped column that is a
    scalar inside its domain costs a comparison."""
    dropped, _ = _missing()
    if not dropped:
        return columns, domains
    threshold = params.PARAMETER_NAMES.index("mtf_threshold")
    for j in dropped:
        lo, hi, lo_closed, hi_closed, integer = domains[j].tolist()
        if columns[j].size == 1:
            v = columns[j].item()
            if ((v >= lo if lo_closed else v > lo) and (v <= hi if hi_closed else v < hi)
                    and (not integer or v.is_integer())):
                continue
        table = params.PARAMETERS[j]
        param = params.Param(table.name, table.default, lo, hi, bool(lo_closed),
                             bool(hi_closed), table.meaning, bool(integer))
        outside = ~params.in_domain(param, columns[j])
        n = max(columns[threshold].size, columns[j].size)
        columns = list(columns)
        columns[threshold] = np.where(outside, np.nan, np.broadcast_to(columns[threshold], (n,)))
    slots = core_slots()
    if slots == tuple(range(len(slots))):  # the core lacks the last ones: a view of its rows
        return columns[:len(slots)], domains[:len(slots)]
    return [columns[j] for j in slots], np.ascontiguousarray(domains[list(slots)])


def _outputs_for_core(out: dict, allocate: list, n: int):
    """(out, allocate, filled) for the core: ``out`` and ``allocate`` without the outputs it
    lacks, every elasticity as one row each of a (rows, n) array when the core lacks some
    rows, and ``filled``, the arrays this module writes (name -> array)."""
    _, lacking = _missing()
    every = elasticity_outputs.ALL
    asked = set(out).union(allocate)
    filled = {}
    if not lacking or asked.isdisjoint(lacking + (every,)):  # most calls
        return out, allocate, filled
    out = dict(out)
    allocate = list(allocate)
    if every in asked:
        array = out.pop(every) if every in out else np.empty(len(elasticity_outputs.ROWS) * n)
        if every in allocate:
            allocate.remove(every)
        rows = array.reshape(len(elasticity_outputs.ROWS), n)
        for row, values in zip(elasticity_outputs.ROWS, rows):
            (filled if row in lacking else out)[row] = values
        filled[every] = array
    for name in lacking:
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
