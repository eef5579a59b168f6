"""Resolution counted in both directions (docs/model.md, "Resolution in both directions").

The paper's motion blur is one-directional. Along the motion the system MTF is the product of
every factor; across it the motion's factor is 1 and the image keeps the pixel's and the
lens's resolution. ``epc_axes="motion"`` (the default) is the paper's metric,
EPC = 4 S f50^2 with f50 along the motion; ``epc_axes="both"`` counts each direction once,
EPC = 4 S f50 f50_across.

f50_across is the f50 of the same design without the motion blur, which leaves the exposure
and every other factor (jitter and a burst's alignment included) as they are. The core solves
it in the same pass as the f50 along the motion (:func:`core_outputs`); shares or elasticities
across or in both directions, ``out=`` and the reference backend take two calls, the second
with the shake rate 0 (:func:`evaluate_axes`), bit for bit the same values.
"""

from __future__ import annotations

import numpy as np

from ._validation import choice
from .outputs import (ACROSS_OUTPUTS, OUTPUT_DTYPES, SHARE_NAMES, Result, names_any,
                      new_result, out_arrays, selected_outputs)
from .params import BIG
from .status import Status

__all__ = ["EPC_AXES", "check_epc_axes", "asks_across", "default_outputs", "epc_both",
           "core_outputs", "evaluate_axes"]

#: How EPC counts the resolution: along the motion twice (the paper's), or each direction once.
EPC_AXES = ("motion", "both")

_ACROSS = frozenset(ACROSS_OUTPUTS)
#: Each share across the motion by the name of the same share in a pass without motion.
_SHARES_ACROSS = {f"share_{name}": f"share_{name}_across" for name in SHARE_NAMES}


def check_epc_axes(epc_axes) -> str:
    """``epc_axes`` itself when it is one of :data:`EPC_AXES`, else a ValueError naming it."""
    return choice("epc_axes", epc_axes, EPC_AXES)


def asks_across(outputs) -> bool:
    """Whether ``outputs=`` names an output across the motion (:data:`ACROSS_OUTPUTS`)."""
    return names_any(outputs, _ACROSS)


def default_outputs(epc_axes: str) -> tuple:
    """evaluate's outputs when ``outputs=`` is None: f50_across_cyc_per_mm among them with
    ``epc_axes="both"``."""
    extra = ("f50_across_cyc_per_mm",) if epc_axes == "both" else ()
    return tuple(OUTPUT_DTYPES) + extra


def core_outputs(outputs, epc_axes: str):
    """The outputs of a call whose f50 across the motion the core solves in the same pass
    (kernel.h across_f50; EPC and the status counted in both directions with
    ``epc_axes="both"``), or None where the call takes two passes (:func:`evaluate_axes`): a
    share or an elasticity asked for, which the two passes form."""
    epc_axes = check_epc_axes(epc_axes)
    names = _names(outputs, epc_axes)
    if any(not isinstance(name, str) or name.startswith(("share_", "elasticit"))
           for name in names):
        return None
    return tuple(names)


def epc_both(epc, f50_cyc_per_mm, f50_across_cyc_per_mm):
    """pixels, 4 S f50 f50_across, from the paper's EPC 4 S f50^2 and the two f50s (cycles/mm):
    EPC f50_across / f50, and 0 where the blur is unbounded (f50 = 0, EPC = 0)."""
    f50 = np.asarray(f50_cyc_per_mm, dtype=np.float64)
    across = np.asarray(f50_across_cyc_per_mm, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        value = np.asarray(epc, dtype=np.float64) * (across / f50)
    return np.where(f50 == 0.0, 0.0 * across, value)


def _still_shake(shake):
    """The shake rate of the pass without motion: 0 where ``shake`` is in its domain, itself
    (so the point stays INVALID) where not; the same shape, so both passes broadcast alike."""
    try:
        value = np.asarray(shake, dtype=np.float64)
    except (TypeError, ValueError):
        return shake  # evaluate names it
    still = np.where((value >= 0.0) & (value <= BIG), 0.0, value)
    return still if still.ndim else float(still)


def _names(outputs, epc_axes: str) -> list:
    if outputs is None:
        return list(default_outputs(epc_axes))
    return [outputs] if isinstance(outputs, str) else list(outputs)


def evaluate_axes(evaluate, call: dict) -> Result:
    """``evaluate``'s Result over ``call``'s keywords (evaluate's own) with the outputs across
    the motion: a first pass as asked, a second with the shake rate 0 for f50_across and its
    shares; with ``epc_axes="both"``, EPC, status and elasticities counted in both directions."""
    both = check_epc_axes(call.pop("epc_axes")) == "both"
    out = call.pop("out", None)
    names = _names(call.pop("outputs"), "both" if both else "motion")
    pixel = call.get("pixel_count") is not None
    selected = selected_outputs(names, pixel)  # errors name a bad output
    if out is not None and any(name.startswith("elasticit") for name in selected):
        raise TypeError("out= cannot take the elasticities with epc_axes='both' or an output "
                        "across the motion: take them from the Result")
    across = [name for name in names if name in _ACROSS]
    along = [name for name in names if name not in _ACROSS]
    elastic = [name for name in along
               if name == "elasticities" or name.startswith("elasticity_")]
    fields: dict = {}
    if along or both:
        extra = ["status", "f50_cyc_per_mm", "epc"] if both else []
        first = evaluate(**call, outputs=tuple(dict.fromkeys(along + extra)))
        fields = {name: getattr(first, name) for name in Result.__dataclass_fields__
                  if getattr(first, name) is not None}
    second_names = ["status", "f50_cyc_per_mm"]
    second_names += [plain for plain, name in _SHARES_ACROSS.items() if name in across]
    if both and elastic:
        second_names += ["epc", *elastic]
    still = {**call, "shake_deg_per_s": _still_shake(call["shake_deg_per_s"])}
    second = evaluate(**still, outputs=tuple(dict.fromkeys(second_names)))
    scalar = not isinstance(second.status, np.ndarray)
    shape = np.shape(first.status) if fields else np.shape(second.status)

    def shaped(value):
        return np.broadcast_to(np.asarray(value), shape) if shape else value

    f50_across = shaped(second.f50_cyc_per_mm)
    if "f50_across_cyc_per_mm" in across or both:
        fields["f50_across_cyc_per_mm"] = (f50_across if scalar
                                           else np.array(f50_across, dtype=np.float64))
    for plain, name in _SHARES_ACROSS.items():
        if name in across:
            fields[name] = shaped(getattr(second, plain))
            fields[name] = fields[name] if scalar else np.array(fields[name])
    if both:
        _count_both(fields, first, second, shaped, scalar, set(along))
    if out is None:
        return new_result(fields)
    given = out_arrays(out, shape, selected, pixel)  # checked as evaluate checks them
    for name, array in given.items():
        np.copyto(array, np.reshape(fields[name], array.shape), casting="unsafe")
    return new_result(given)


def _count_both(fields: dict, first: Result, second: Result, shaped, scalar: bool,
                asked: set) -> None:
    """``fields`` counted in both directions: status (BEYOND_TABLE where only the f50 across
    passes a table's end), EPC 4 S f50 f50_across and each elasticity the mean of the two
    passes' (ln EPC is the mean of ln 4 S f50^2 and ln 4 S f50_across^2)."""
    status = np.asarray(first.status, dtype=np.uint8)
    across_status = np.asarray(shaped(second.status), dtype=np.uint8)
    status = np.where((status == Status.OK) & (across_status == Status.BEYOND_TABLE),
                      np.uint8(Status.BEYOND_TABLE), status).astype(np.uint8)
    f50_across = np.asarray(fields["f50_across_cyc_per_mm"], dtype=np.float64)
    epc = epc_both(first.epc, first.f50_cyc_per_mm, f50_across)
    epc = np.where(status == Status.BEYOND_TABLE, np.nan, epc)
    ok = status == Status.OK
    if "epc" in asked:
        fields["epc"] = float(epc) if scalar else epc
    else:
        fields.pop("epc", None)
    if "status" in asked:
        fields["status"] = Status(int(status)) if scalar else status
    else:
        fields.pop("status", None)
    if "f50_cyc_per_mm" not in asked:
        fields.pop("f50_cyc_per_mm", None)
    if fields.get("elasticities") is not None:
        mean = {}
        for key, along in fields["elasticities"].items():
            value = 0.5 * (np.asarray(along) + np.asarray(shaped(second.elasticities[key])))
            value = np.where(ok, value, np.nan)
            mean[key] = float(value) if scalar else value
        fields["elasticities"] = mean
