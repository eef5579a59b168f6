"""Exposure limits and night mode (docs/model.md, "Exposure limits and night mode").

A camera caps one frame's exposure: a phone held in the hand takes frames of at most about
1/15 to 1/4 s, a tripod longer ones. ``evaluate(..., max_exposure_s=c)`` gives a point whose
frame T_MPE / frames is longer than c the status :attr:`~epc_fast.Status.EXPOSURE_LIMIT`:
its T_MPE and electron counts are what the target would need, its blur, f50 and EPC NaN.

A burst fills the gap: ``frames="auto"`` with ``max_frames=N`` takes at each point the least n
in 1 .. N with T_MPE(n) / n <= c (T_MPE depends on n through each frame's read noise), as a
phone's night mode picks it; where no n does, N, and the point's status is EXPOSURE_LIMIT. The
n taken is the output ``frames_used``. It is found by bisection on n, a pass of T_MPE alone per
halving (T_MPE(n) / n falls as n grows), then the picked counts are evaluated as any ``frames``
array.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ._validation import short
from .axes import check_epc_axes, default_outputs
from .outputs import (ACROSS_OUTPUTS, LIMIT_OUTPUTS, SHARE_OUTPUTS, Result, names_any,
                      new_result, scalar_fields)
from .params import PARAMETER_NAMES, SIZE_KEYWORDS
from .status import Cause, Status

__all__ = ["NIGHT_MODE", "MAX_FRAMES", "asks_frames_used", "asks_limits", "sets_limits",
           "check_max_exposure", "check_max_frames", "check_scan_cap", "least_frames",
           "evaluate_limits"]

#: ``frames`` for night mode: the least frames up to ``max_frames`` that keep each frame within
#: ``max_exposure_s``.
NIGHT_MODE = "auto"
#: The largest ``max_frames``: its candidate counts are evaluated at once, one pass of the
#: points each.
MAX_FRAMES = 1024

#: evaluate's keywords that are per-point arrays (they set the broadcast shape).
_POINT_KEYS = tuple(name for name in PARAMETER_NAMES if name != "size") + tuple(
    name for name in SIZE_KEYWORDS if name != "aspect")
#: The outputs of the exposure limits, as a set.
_LIMITS = frozenset(LIMIT_OUTPUTS)
#: The statuses whose T_MPE is finite: the cap applies to them.
_TIMED = np.array([Status.OK, Status.BLUR_UNBOUNDED, Status.BEYOND_TABLE], np.uint8)
#: Whether each status code (uint8) is one of _TIMED, by lookup.
_TIMED_CODES = np.isin(np.arange(256), _TIMED)
#: The outputs a point over the cap keeps: what the target would need.
_KEPT = frozenset(("electron_rate_e_per_s", "electrons", "t_mpe_s", "status", "cause",
                   "frames_used"))
_FLOATS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc",
           *ACROSS_OUTPUTS, *SHARE_OUTPUTS, *LIMIT_OUTPUTS)


def asks_frames_used(outputs) -> bool:
    """Whether ``outputs=`` names ``frames_used``."""
    return names_any(outputs, _LIMITS)


def asks_limits(call: dict) -> bool:
    """Whether evaluate's keywords ``call`` set an exposure limit, night mode or ask for
    ``frames_used``."""
    return (call["max_exposure_s"] is not math.inf or call["max_frames"] is not None
            or isinstance(call["frames"], str) or asks_frames_used(call["outputs"]))


def sets_limits(keywords: dict) -> bool:
    """Whether evaluate's keywords (a design's) set a frame cap or night mode, themselves or in
    one of their ``modes``."""
    return bool({"max_exposure_s", "max_frames"} & set(keywords)
                or isinstance(keywords.get("frames"), str)
                or any(isinstance(m.get("frames"), str) for m in keywords.get("modes") or ()))


def check_max_exposure(max_exposure_s) -> np.ndarray:
    """``max_exposure_s`` (s) as a float64 array, or a TypeError naming it; its values are
    checked per point (NaN or <= 0: status INVALID)."""
    if isinstance(max_exposure_s, (str, bytes, bool)):
        raise TypeError(f"max_exposure_s: s, the longest single frame the camera takes, a "
                        f"number or an array of them; got {short(max_exposure_s)}")
    try:
        return np.asarray(max_exposure_s, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"max_exposure_s: s, the longest single frame the camera takes, a "
                        f"number or an array of them; got {short(max_exposure_s)}") from None


def check_max_frames(frames, max_frames) -> int | None:
    """The most frames night mode takes (None without it), or a ValueError naming ``frames``
    and ``max_frames``: ``max_frames`` goes with ``frames="auto"`` and only with it."""
    auto = isinstance(frames, str)
    if auto and frames != NIGHT_MODE:
        raise ValueError(f"frames={frames!r}: a whole number >= 1, or {NIGHT_MODE!r} with "
                         "max_frames (night mode)")
    if max_frames is None:
        if auto:
            raise ValueError(f"frames={NIGHT_MODE!r} (night mode) needs max_frames, the most "
                             "frames a burst takes, e.g. max_frames=8")
        return None
    if not auto:
        raise ValueError(f"max_frames={short(max_frames)} is given with frames="
                         f"{short(frames)}: max_frames only with frames={NIGHT_MODE!r}")
    if (isinstance(max_frames, bool) or not isinstance(max_frames, numbers.Real)
            or not 1 <= max_frames <= MAX_FRAMES or max_frames != int(max_frames)):
        raise ValueError(f"max_frames={short(max_frames)}: a whole number in 1 .. "
                         f"{MAX_FRAMES}, the most frames night mode takes")
    return int(max_frames)


def check_scan_cap(max_exposure_s) -> float:
    """A scan's ``max_exposure_s`` (one value for every point, s in (0, inf]) as a float, or a
    ValueError naming it."""
    if (isinstance(max_exposure_s, bool) or not isinstance(max_exposure_s, numbers.Real)
            or not max_exposure_s > 0):
        raise ValueError(f"max_exposure_s = {short(max_exposure_s)}: one value a scan, s in "
                         "(0, inf], the longest single frame the camera takes")
    return float(max_exposure_s)


def least_frames(t_mpe_s, frames, max_exposure_s) -> np.ndarray:
    """Per point, the least of the candidate ``frames`` (a leading axis, ascending) whose frame
    ``t_mpe_s`` / n (s, T_MPE at that n, the same leading axis) is within ``max_exposure_s``
    (s), the last candidate where none is (float64, the points' shape)."""
    fits = np.asarray(t_mpe_s, dtype=np.float64) / frames <= max_exposure_s  # NaN: False
    fits = np.broadcast_to(fits, np.broadcast_shapes(fits.shape, np.shape(frames)))
    first = np.argmax(fits, axis=0)
    candidates = np.asarray(frames, dtype=np.float64).reshape(-1)
    return np.where(fits.any(axis=0), candidates[first], candidates[-1])


def _search_frames(evaluate, base: dict, cap: np.ndarray, shape: tuple, max_frames: int):
    """Night mode's n* at every point (float64 of ``shape``): the least n in 1 .. max_frames
    whose frame T_MPE(n) / n is within ``cap``, max_frames where none is, by bisection on n.

    T_MPE(n) / n falls strictly as n grows (the quadratic's root over n: its read-noise term
    grows as n, the rest not at all; docs/model.md "Night mode"), and a full well is
    overfilled less by shorter frames, so "fits" holds from n* on. The search keeps the
    largest count known not to fit, ``below`` (0: none yet), and tries it plus each power of
    two from the largest below max_frames down: ceil(log2(max_frames)) passes of T_MPE alone
    (the points' frames an array), where a pass for every candidate count would take
    max_frames."""
    below = np.zeros(shape)
    cap = np.broadcast_to(cap, shape)
    trial = {**base, "epc_axes": "motion", "invalid": "status", "outputs": ("t_mpe_s",)}
    step = 1 << max(max_frames - 1, 1).bit_length() - 1 if max_frames > 1 else 0
    count, ratio = np.empty(shape), np.empty(shape)  # buffers: no new pages a pass
    over = np.empty(shape, dtype=bool)
    while step >= 1:
        np.minimum(np.add(below, float(step), out=count), float(max_frames - 1), out=count)
        t_mpe = np.asarray(evaluate(**{**trial, "frames": count}).t_mpe_s, dtype=np.float64)
        np.divide(t_mpe, count, out=ratio)
        np.logical_not(np.less_equal(ratio, cap, out=over), out=over)  # NaN: does not fit
        np.copyto(below, count, where=over)
        step >>= 1
    return np.add(below, 1.0, out=below)


def _points_shape(call: dict, cap: np.ndarray):
    """The broadcast shape of the points and the cap, or None where they do not broadcast
    (evaluate then names the argument)."""
    try:
        return np.broadcast_shapes(cap.shape, *(np.shape(call[key]) for key in _POINT_KEYS
                                                if call.get(key) is not None))
    except ValueError:
        return None


def _outputs(call: dict, auto: bool) -> list:
    outputs = call["outputs"]
    if outputs is None:
        extra = list(LIMIT_OUTPUTS) if auto else []
        return list(default_outputs(check_epc_axes(call.get("epc_axes", "motion")))) + extra
    return [outputs] if isinstance(outputs, str) else list(outputs)


def evaluate_limits(evaluate, call: dict) -> Result:
    """``evaluate``'s Result over ``call``'s keywords (evaluate's own) with the frame cap
    ``max_exposure_s`` and night mode (``frames="auto"``, ``max_frames``) applied, and
    ``frames_used`` where asked (by default with night mode)."""
    max_frames = check_max_frames(call["frames"], call.pop("max_frames"))
    cap = check_max_exposure(call.pop("max_exposure_s"))
    if call.get("out") is not None:
        raise TypeError("out= cannot be given with max_exposure_s, frames='auto' or the output "
                        "frames_used: the frames are picked, then evaluated")
    names = _outputs(call, max_frames is not None)
    inner = [name for name in names if name not in LIMIT_OUTPUTS]
    limited = bool(np.any(cap != np.inf))
    base = {**call, "max_exposure_s": math.inf, "max_frames": None}
    shape = _points_shape(call, cap)
    if max_frames is not None:
        if shape is None:  # evaluate names what does not broadcast
            evaluate(**{**base, "frames": 1.0, "outputs": ("status",)})
            raise ValueError(f"max_exposure_s of shape {cap.shape} does not broadcast with "
                             "the points")
        base["frames"] = _search_frames(evaluate, base, cap, shape, max_frames)
    elif cap.ndim and shape is not None:  # the cap's axes are the points' too
        try:
            base["frames"] = np.broadcast_to(np.asarray(call["frames"], dtype=np.float64),
                                             shape)
        except (TypeError, ValueError):
            pass  # evaluate names frames
    needed = ["status"] + (["t_mpe_s"] if limited else [])
    result = evaluate(**{**base, "outputs": tuple(dict.fromkeys(inner + needed))})
    fields = {name: getattr(result, name) for name in Result.__dataclass_fields__
              if getattr(result, name) is not None}
    scalar = not isinstance(result.status, np.ndarray)
    status = np.asarray(result.status, dtype=np.uint8)
    frames = np.broadcast_to(np.asarray(base["frames"], dtype=np.float64), status.shape)
    if limited or max_frames is not None:
        bad = np.broadcast_to(~(cap > 0.0), status.shape)
        if call["invalid"] == "raise" and bad.any():
            _raise_bad_cap(cap, bad)
        if limited:
            t_mpe = np.asarray(result.t_mpe_s, dtype=np.float64)
            # one frame's T_MPE (T_MPE itself for one frame: x / 1 is x)
            frame = t_mpe if _one_frame(base["frames"]) else t_mpe / frames
            over = _TIMED_CODES[status] & (frame > cap)
            if np.ndim(cap) or not cap > 0.0:
                over &= ~bad
            _limit(fields, over, bad, status)
            status = np.asarray(fields["status"], dtype=np.uint8)
    if LIMIT_OUTPUTS[0] in names:
        used = (np.where(status == Status.INVALID, np.nan, frames) if max_frames is not None
                else np.array(frames))
        fields["frames_used"] = used
    for name in needed:
        if name not in inner:
            fields.pop(name, None)
    return new_result(scalar_fields(fields) if scalar else fields)


def _raise_bad_cap(cap: np.ndarray, bad: np.ndarray):
    """The ValueError ``invalid="raise"`` asks for at the first point whose cap is NaN or not
    positive."""
    index = np.unravel_index(int(np.argmax(bad)), bad.shape) if bad.ndim else ()
    value = float(np.broadcast_to(cap, bad.shape)[index])
    where = f" at index {tuple(int(i) for i in index)}" if bad.ndim else ""
    raise ValueError(f"max_exposure_s={value!r}{where} is outside its domain (0, inf] (s, the "
                     "longest single frame the camera takes)")


def _one_frame(frames) -> bool:
    """Whether ``frames`` is the one value 1 (no division needed for a frame's T_MPE)."""
    return np.ndim(frames) == 0 and not isinstance(frames, str) and frames == 1.0


def _nan_where(value, mask: np.ndarray):
    """``value`` as float64 with NaN where ``mask``: in place in a writeable float64 array of
    its shape (evaluate's own result), else a new array."""
    if (isinstance(value, np.ndarray) and value.dtype == np.float64 and value.flags.writeable
            and value.shape == mask.shape):
        np.putmask(value, mask, np.nan)
        return value
    return np.where(mask, np.nan, np.asarray(value, dtype=np.float64))


def _limit(fields: dict, over: np.ndarray, bad: np.ndarray, status: np.ndarray) -> None:
    """``fields`` with the points ``over`` the cap EXPOSURE_LIMIT (NaN but for what the target
    would need) and those whose cap is ``bad`` INVALID (NaN, cause NONE)."""
    any_bad = bool(bad.any())
    if not (any_bad or over.any()):
        return
    both = over | bad if any_bad else over
    for name, value in list(fields.items()):
        if name in _FLOATS and name != "frames_used":
            if name in _KEPT and not any_bad:
                continue
            fields[name] = _nan_where(value, bad if name in _KEPT else both)
    if fields.get("elasticities") is not None:
        fields["elasticities"] = {key: _nan_where(value, both)
                                  for key, value in fields["elasticities"].items()}
    status = np.where(over, np.uint8(Status.EXPOSURE_LIMIT), status)
    fields["status"] = (np.where(bad, np.uint8(Status.INVALID), status).astype(np.uint8)
                        if any_bad else status.astype(np.uint8, copy=False))
    if any_bad and fields.get("cause") is not None:
        cause = np.asarray(fields["cause"], dtype=np.uint8)
        fields["cause"] = np.where(bad, np.uint8(Cause.NONE), cause).astype(np.uint8)
