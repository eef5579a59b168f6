"""Readout modes: a camera that reads its sensor several ways (full resolution, binned, a burst)
picks, shot by shot, the way that gives the most effective pixels.

``evaluate(..., modes=[{"binning": 1}, {"binning": 4}, {"binning": 4, "frames": 8}])``
evaluates every mode at every point and returns, per point, the outputs of the mode with the
highest EPC and that mode's index (:attr:`Result.mode`). A mode may be a night mode,
``{"frames": "auto", "max_frames": 8}``: with ``max_exposure_s`` its burst takes the least
frames that keep each frame within the cap (:mod:`epc_fast.exposure_limits`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ._validation import compiled_core, short, threads_of
from .axes import check_epc_axes, core_outputs, default_outputs
from .exposure_limits import asks_limits, check_max_frames
from .outputs import (ACROSS_OUTPUTS, LIMIT_OUTPUTS, Result, names_any, scalar_fields,
                      selected_outputs)
from .params import READOUT_CODES, readout_codes

__all__ = ["MODE_KEYS", "MODE_DEFAULTS", "NO_MODE", "check_modes", "evaluate_modes", "core_codes"]

#: The keywords a readout mode sets, and their defaults (evaluate's).
MODE_DEFAULTS = {"binning": 1.0, "binning_readout": "digital", "frames": 1.0,
                 "alignment_error_um": 0.0, "max_frames": None}
MODE_KEYS = tuple(MODE_DEFAULTS)
#: The mode index of a point where no mode has an EPC (every mode INVALID or UNREACHABLE): its
#: outputs are the first mode's, whose status says why.
NO_MODE = -1


def check_modes(modes) -> tuple:
    """The modes as a tuple of dicts, each key one of :data:`MODE_KEYS` with one value; a
    TypeError or ValueError naming the mode and the key otherwise, for no mode at all, and for
    a mode that repeats another."""
    if isinstance(modes, (str, bytes, Mapping)) or not hasattr(modes, "__iter__"):
        raise TypeError(f"modes: a list of readout modes, each a dict of "
                        f"{', '.join(MODE_KEYS)}; got {short(modes)}")
    modes = list(modes)
    if not modes:
        raise ValueError("modes: at least one readout mode, e.g. [{'binning': 1}, "
                         "{'binning': 4}]; got an empty list")
    out, seen = [], {}
    for i, mode in enumerate(modes):
        if not isinstance(mode, Mapping):
            raise TypeError(f"modes[{i}]: a dict of {', '.join(MODE_KEYS)}, got {short(mode)}")
        unknown = [k for k in mode if k not in MODE_DEFAULTS]
        if unknown:
            raise ValueError(f"modes[{i}]: {unknown[0]!r} is not a readout mode's key; a mode "
                             f"sets {', '.join(MODE_KEYS)}")
        for key, value in mode.items():
            if key != "binning_readout" and np.ndim(value) != 0:
                raise ValueError(f"modes[{i}]: {key} = {short(value)}: one value a mode")
        full = {**MODE_DEFAULTS, **mode}
        try:  # night mode: frames="auto" with max_frames, and max_frames only with it
            check_max_frames(full["frames"], full["max_frames"])
        except ValueError as error:
            raise ValueError(f"modes[{i}]: {error}") from None
        signature = tuple(str(full[k]) if k == "binning_readout"
                          else full[k] if full[k] is None or isinstance(full[k], str)
                          else float(full[k]) for k in MODE_KEYS)
        if signature in seen:
            raise ValueError(f"modes[{i}] repeats modes[{seen[signature]}] "
                             f"({short(dict(mode))}): each mode once")
        seen[signature] = i
        out.append(dict(mode))
    return tuple(out)


def evaluate_modes(evaluate, call: dict, in_core=None) -> Result:
    """``evaluate``'s Result over ``call``'s keywords (evaluate's own) for each of its
    ``modes``, per point the mode with the highest EPC (as ``epc_axes`` counts it), with
    :attr:`Result.mode` its index (the first of equal ones; :data:`NO_MODE` where no mode has
    an EPC). ``in_core(call, codes, outputs)``, where given, evaluates every mode in the core's
    one pass (api._modes_in_core) for the calls it can take: the core backend, no night mode,
    frame cap or frames_used, no ``invalid="raise"``, and no share or elasticity with the
    count in both directions; the others are one call per mode and the core's pick."""
    modes = check_modes(call.pop("modes"))
    if call.get("out") is not None:
        raise TypeError("out= cannot be given with modes: each mode's outputs are computed, "
                        "then the best mode's taken")
    for i, mode in enumerate(modes):
        for key in mode:
            if not _is_default(key, call.get(key)):
                raise ValueError(f"{key} = {short(call[key])} is given to evaluate and in "
                                 f"modes[{i}]: give it in each mode")
    epc_axes = check_epc_axes(call.get("epc_axes", "motion"))
    wanted = (default_outputs(epc_axes) if call.get("outputs") is None
              else selected_outputs(call.get("outputs")))
    night = [LIMIT_OUTPUTS[0]] if call.get("outputs") is None and any(
        isinstance(mode.get("frames"), str) for mode in modes) else []
    codes = core_codes(call, modes, wanted, epc_axes) if in_core is not None else None
    if codes is not None:
        return in_core(call, codes, wanted)
    asked = tuple(dict.fromkeys((*wanted, *night, "epc")))
    results = [evaluate(**{**call, **mode, "outputs": asked}) for mode in modes]
    if np.ndim(results[0].epc) == 0 and not isinstance(results[0].epc, np.ndarray):
        return _best_of_scalars(results, wanted)
    shape = np.shape(results[0].epc)
    if call.get("backend") == "reference":
        mode, best = _pick_reference(results)
    else:  # the core's pick: one parallel pass over the modes' EPC, one per output taken
        core, threads = compiled_core(), threads_of(call.get("threads"))
        mode = core.best_mode([_column(r.epc) for r in results], threads).reshape(shape)

        def best(values):
            flat = [_column(v) for v in values]
            return core.take_mode(mode.reshape(-1), flat, threads).reshape(shape)

    fields = _fields(results, wanted, best)
    return Result(**fields, mode=mode)


def _pick_reference(results):
    """The reference backend's pick in NumPy: each point's first mode of the largest finite
    EPC (NO_MODE where none is finite, and the first mode's outputs), and the function that
    takes an output's values by it."""
    epc = np.stack([np.asarray(r.epc, dtype=np.float64) for r in results])
    finite = np.isfinite(epc)
    pick = np.argmax(np.where(finite, epc, -np.inf), axis=0)
    mode = np.where(finite.any(axis=0), pick, NO_MODE).astype(np.int16)

    def best(values):
        return np.take_along_axis(np.stack([np.asarray(v) for v in values]), pick[None, ...], axis=0)[0]

    return mode, best


def core_codes(call: dict, modes: tuple, wanted: tuple, epc_axes: str):
    """The modes as the core's one pass takes them, (binning, binning_readout code, frames,
    alignment_error_um) each (None for a key the mode leaves to the call), or None where the
    call takes one call per mode: another backend, ``invalid="raise"`` (each mode's call raises
    for its own points), a quad Bayer sensor (each binning reads its own layout:
    cfa.sensor_color), a frame cap, night mode or frames_used (exposure_limits), a share or
    elasticity counted across the motion, or a mode value that is not one number (evaluate
    names it)."""
    if (call.get("backend") != "core" or call.get("invalid") == "raise"
            or call.get("cfa") == "quad_bayer"  # its layout, table and gain follow the binning
            or asks_limits(call) or any(mode.get("max_frames") is not None for mode in modes)):
        return None
    if (epc_axes != "motion" or names_any(wanted, ACROSS_OUTPUTS)) and core_outputs(
            wanted, epc_axes) is None:
        return None
    codes = []
    for mode in modes:
        try:  # a key the mode does not set keeps the call's column (None)
            codes.append(tuple(
                None if key not in mode else float(readout_codes(mode[key]))
                if key == "binning_readout" else _number(mode[key])
                for key in ("binning", "binning_readout", "frames", "alignment_error_um")))
        except (TypeError, ValueError):
            return None
    return codes


def _number(value) -> float:
    """A mode's value as a float, or a TypeError for a string or bool (evaluate names those)."""
    if isinstance(value, (str, bytes, bool)):
        raise TypeError(value)
    return float(value)


def _column(values) -> np.ndarray:
    """An output array as the 1-d contiguous column the core's pick reads."""
    return np.ascontiguousarray(values).reshape(-1)


def _fields(results, wanted, best) -> dict:
    """Result's fields (but the mode) from the modes' results, each output by ``best``."""
    fields = {}
    for name in Result.__dataclass_fields__:
        if name == "mode":
            continue
        values = [getattr(r, name) for r in results]
        if values[0] is None or (name == "epc" and name not in wanted):
            fields[name] = None
        elif name == "elasticities":
            fields[name] = {k: best([v[k] for v in values]) for k in values[0]}
        else:
            fields[name] = best(values)
    return fields


def _best_of_scalars(results, wanted) -> Result:
    """evaluate_modes' Result for one point (every input a scalar), by the NumPy pick."""
    mode, best = _pick_reference(results)
    return Result(**scalar_fields(_fields(results, wanted, best)), mode=int(mode))


def _is_default(key, value) -> bool:
    if value is None:
        return True
    if isinstance(value, str) and key != "binning_readout":
        return False  # frames="auto"
    if key == "binning_readout":
        return bool(np.all(np.asarray(readout_codes(value)) == READOUT_CODES["digital"]))
    return bool(np.all(np.asarray(value, dtype=float) == MODE_DEFAULTS[key]))
