"""A ``[[design.custom]]`` table's readout ``modes`` (:mod:`epc_fast.modes`), night mode among
them: ``modes = [{binning = 1}, {binning = 2, frames = "auto", max_frames = 8}]``."""

from __future__ import annotations

from ...api import BINNING_READOUTS
from ...exposure_limits import NIGHT_MODE
from ...jobs.errors import ConfigError
from ...jobs.schema import MAX_LIST, choice, config_prefix, number, short
from ...modes import MODE_DEFAULTS, check_modes
from ..sampling.space import domain_problem

__all__ = ["design_modes"]


def design_modes(where: str, label: str, design: dict) -> list:
    """A design's ``modes``, checked with :func:`epc_fast.modes.check_modes` (a night mode's
    ``frames = "auto"`` and ``max_frames`` there) and every other value against its domain; a
    ConfigError naming the design (``label``), the mode and the key otherwise."""
    value = design["modes"]
    if not isinstance(value, list) or len(value) > MAX_LIST:
        raise ConfigError(f"{config_prefix()} {label}: modes = {short(value)}: expected a list of "
                          "readout modes, e.g. [{binning = 1}, {binning = 4}]")
    try:
        modes = check_modes(value)
    except (TypeError, ValueError) as error:
        raise ConfigError(f"{config_prefix()} {label}: {error}") from None
    for index, mode in enumerate(modes):
        for key, item in mode.items():
            if key == "binning_readout":
                choice(f"{where}.modes[{index}]", key, item, BINNING_READOUTS)
                continue
            if key in design and design[key] != MODE_DEFAULTS[key]:
                raise ConfigError(f"{config_prefix()} {label}: modes[{index}]: {key} is set by the "
                                  f"design too ({key} = {design[key]:g}): give it in each mode")
            if key == "max_frames" or item == NIGHT_MODE:
                continue  # night mode's, checked with the modes
            number(f"{where}.modes[{index}]", key, item)
            problem = domain_problem(key, item)
            if problem:
                raise ConfigError(f"{config_prefix()} {label}: modes[{index}]: {key} = {problem}")
    return list(modes)
