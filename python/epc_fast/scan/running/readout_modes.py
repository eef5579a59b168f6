"""A chunk's points evaluated per design's readout ``modes`` (:mod:`epc_fast.modes`).

A mode is evaluated on every point it could be picked at, so a space whose designs have modes
is evaluated here, design group by design group: every mode of a design on the same points (the
same draws for every mode), and per point the mode with the highest EPC, as
``evaluate(modes=...)`` picks it. The chunk's :class:`~epc_fast.Result` then holds the picked
mode's outputs and its index (``mode``; a design without modes has one, its own readout, index
0; -1 where no mode has an EPC). A space without modes never comes here: its chunks are the
core's fused pass, a design's ``binning_readout`` one of its columns.
"""

from __future__ import annotations

import numpy as np

from ..._validation import short
from ...api import BINNING_READOUTS, evaluate
from ...exposure_limits import NIGHT_MODE
from ...modes import MODE_DEFAULTS, check_modes
from ...outputs import Result
from ...params import READOUT_CODES
from ..sampling.domains import domain_problem

# Space and Points (scan/sampling/space.py, which imports this module) are named in annotations
# only.

__all__ = ["evaluate_space_points", "readout_groups", "readout_kwargs", "design_readout",
           "READOUT_KEYS"]

#: How a design's sensor is read: ``binning_readout`` (a name, ``"digital"`` or ``"charge"``,
#: which the design's column holds as its code) and its readout ``modes``
#: (:mod:`epc_fast.modes`).
READOUT_KEYS = ("binning_readout", "modes")


def design_readout(entry: dict, overridden: set) -> tuple[str, tuple | None]:
    """A design's ``binning_readout`` and its checked ``modes`` (None: none), popped from its
    ``entry``, where a charge readout's code (:data:`epc_fast.params.READOUT_CODES`) is put
    back as the design's ``binning_readout`` column unless ``overridden`` (a digital one is the
    column's default); a ValueError or TypeError naming the design and the mode otherwise."""
    name = entry["name"]
    readout = entry.pop("binning_readout", MODE_DEFAULTS["binning_readout"])
    if not isinstance(readout, str) or readout not in BINNING_READOUTS:
        raise ValueError(f"design {name!r}: binning_readout = {short(readout)}: expected one of "
                         f"{', '.join(map(repr, BINNING_READOUTS))}")
    if readout != MODE_DEFAULTS["binning_readout"] and "binning_readout" not in overridden:
        entry["binning_readout"] = READOUT_CODES[readout]
    modes = entry.pop("modes", None)
    if modes is None:
        return readout, None
    try:
        modes = check_modes(modes)
    except (TypeError, ValueError) as error:
        raise type(error)(f"design {name!r}: {error}") from None
    for index, mode in enumerate(modes):
        for key, value in mode.items():
            where = f"design {name!r}: modes[{index}]: {key}"
            if key == "binning_readout":
                if not isinstance(value, str) or value not in BINNING_READOUTS:
                    raise ValueError(f"{where} = {short(value)}: expected one of "
                                     f"{', '.join(map(repr, BINNING_READOUTS))}")
                continue
            if key in overridden:
                raise ValueError(f"{where}: the space's parameters set {key} too: a mode "
                                 "sets it, or the parameters do, not both")
            if key in entry and float(entry[key]) != MODE_DEFAULTS[key]:
                raise ValueError(f"{where}: the design sets {key} = {entry[key]:g} too: "
                                 "give it in each mode")
            if key == "max_frames" or value == NIGHT_MODE:
                continue  # night mode's, checked with the modes
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise TypeError(f"{where} = {value!r}: expected a number") from None
            problem = domain_problem(key, number)
            if problem:
                raise ValueError(f"{where} = {problem}")
    return readout, modes


def readout_groups(space: Space) -> list[tuple[tuple, str, tuple]]:
    """(design indices, binning_readout, modes) for each distinct readout of the space's
    designs, in the order of their first design; a design without modes has one mode, ``{}``
    (its own readout)."""
    groups: dict = {}
    for index, (readout, modes) in enumerate(zip(space.design_readout, space.design_modes)):
        key = (readout, tuple(tuple(sorted(m.items())) for m in modes) if modes else None)
        groups.setdefault(key, (readout, modes or ({},), []))[2].append(index)
    return [(tuple(designs), readout, modes) for readout, modes, designs in groups.values()]


def readout_kwargs(readout: str, modes) -> tuple[dict, frozenset]:
    """(evaluate's keywords for a design read by ``readout`` with ``modes``, the per-point
    parameters those modes set, which the call must not give). Without modes the design's
    ``binning_readout`` column reads it; when a mode sets ``binning_readout``, the modes that
    do not read as the design does."""
    if modes is None or modes == ({},):
        return {}, frozenset()
    if any("binning_readout" in m for m in modes):
        modes = [m if "binning_readout" in m else {**m, "binning_readout": readout}
                 for m in modes]
    return {"modes": list(modes)}, frozenset(k for m in modes for k in m)


def _subset(value, positions):
    if positions is None or np.ndim(value) == 0:
        return value
    return np.asarray(value)[positions]


def evaluate_space_points(space: Space, points: Points, **options) -> Result:
    """The :class:`~epc_fast.Result` of ``points`` (of ``space``), each point read by its
    design's readout: per point the mode with the highest EPC, its outputs, and its index in
    ``mode`` (int16). ``options`` are evaluate's (``outputs``, ``threads``, ``backend``, the
    space's evaluate options)."""
    n = len(points)
    design = points.indices.get("design")
    fields: dict = {}
    mode = np.full(n, -1, np.int16)
    for designs, readout, modes in readout_groups(space):
        if design is None or len(designs) == len(space.design_names):
            positions = None
        else:
            positions = np.flatnonzero(np.isin(design, designs))
            if positions.size == 0:
                continue
        extra, set_by_modes = readout_kwargs(readout, modes)
        if "modes" not in extra:  # one mode, the design's own readout: index 0
            extra = {"modes": [{}]}
        call = {name: _subset(value, positions) for name, value in points.parameters.items()
                if name not in set_by_modes}
        result = evaluate(**call, **extra, **options)
        size = n if positions is None else positions.size
        for name in Result.__dataclass_fields__:
            value = getattr(result, name)
            if value is None:
                fields.setdefault(name, None)
                continue
            if name == "elasticities":
                target = fields.get(name) or {}
                for key, values in value.items():
                    _scatter(target, key, values, positions, n, size)
                fields[name] = target
            elif name == "mode":
                mode[slice(None) if positions is None else positions] = np.broadcast_to(
                    np.asarray(value), (size,))
            else:
                if fields.get(name) is None:
                    fields.pop(name, None)
                _scatter(fields, name, value, positions, n, size)
    fields.pop("mode", None)
    return Result(**fields, mode=mode)


def _scatter(target: dict, name: str, value, positions, n: int, size: int) -> None:
    dtype = np.uint8 if name in ("status", "cause") else None
    value = np.broadcast_to(np.asarray(value, dtype=dtype), (size,))
    if name not in target:
        target[name] = np.empty(n, value.dtype)
    target[name][slice(None) if positions is None else positions] = value
