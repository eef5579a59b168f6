"""A space's designs as :func:`epc_fast.evaluate` takes them: each design's keywords
(:func:`design_dict`), and a parameter that some designs give and others leave out filled in
those at the value evaluate gives that design alone (:func:`fill_left_out`): evaluate's
default, and under a Bayer sensor the colour filter's ``cfa_transmittance`` and
``color_noise_gain`` (:func:`epc_fast.terms.default_values`), not the monochrome 1.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..presets import Design
from ..sensor import design_parameters
from .running.readout_modes import READOUT_KEYS
from ..terms import default_values

__all__ = ["design_dict", "fill_left_out"]


def design_dict(design, position: int) -> tuple[dict, str]:
    """A design's evaluate keywords (with its ``"name"``) and where it meets the SNR target,
    for people."""
    if isinstance(design, Design):
        return {"name": design.name, **design.evaluate_kwargs()}, design.snr_at_text
    if not isinstance(design, Mapping):
        raise TypeError(f"a design is an epc_fast.presets.Design or a mapping of parameters, "
                        f"got {design!r}")
    entry = dict(design)
    name = entry.pop("name", f"design {position}")
    readout = {k: entry.pop(k) for k in READOUT_KEYS if k in entry}
    try:
        kwargs, where = design_parameters(entry)
    except (TypeError, ValueError) as error:
        raise type(error)(f"design {name!r}: {error}") from None
    return {"name": name, **kwargs, **readout}, where


def fill_left_out(entries: list, cfa: str = "none") -> set:
    """The parameters any of ``entries`` (designs' evaluate keywords, each with its
    ``"name"``) gives; each entry that leaves one out gets, in place, the value evaluate gives
    that design alone under the space's colour filter ``cfa`` (``"bayer"``: the filter's
    defaults). A ValueError names a design that leaves out a parameter without a default."""
    names = set().union(*entries) - {"name"}
    defaults = default_values(cfa)
    for entry in entries:
        missing = sorted(names - set(entry))
        if any(name not in defaults for name in missing):
            raise ValueError(f"every design must give the same parameters, or leave out "
                             f"only parameters with a default: {entry['name']!r} gives "
                             f"{sorted(set(entry) - {'name'})}, others give {missing}")
        entry.update({name: defaults[name] for name in missing})
    return names
