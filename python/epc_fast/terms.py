"""The model terms a space turns on, for people: the values its points take where nobody set a
parameter, and one phrase per term that is on beside the axes (the printed space,
:meth:`epc_fast.scan.Space.describe`, and every figure's conditions,
:func:`epc_fast.plotting.common.space_conditions`).

A term is on where a parameter with a default differs from the default the points take
(``stabilization`` 4, ``read_noise_e`` 2), or where an evaluate option adds a factor: a colour
filter (``cfa``), lens MTF tables (``lens_mtf``), a spectrum, a frame cap
(``max_exposure_s``), a design's charge binning, readout modes or night mode. The SNR target
and where it is met have a line of their own.
"""

from __future__ import annotations

import math

import numpy as np

from .cfa import DEFAULT_CFA_TRANSMITTANCE, DEFAULT_COLOR_NOISE_GAIN
from .params import PARAMETERS

__all__ = ["default_values", "designs_terms", "readout_terms", "terms_on"]

#: Parameters that are no term: the SNR target's (said on its own line), the lens table's
#: index (said with the tables) and the binning readout (said with the readout modes).
NOT_TERMS = ("snr_db", "field_angle_deg", "lens", "binning_readout")
#: Each colour filter array's name in printouts.
CFA_NAMES = {"bayer": "Bayer", "quad_bayer": "quad Bayer (binning 1 remosaicked, 2 Bayer)"}
#: The demosaicker evaluate takes when a colour filter is given without one.
DEFAULT_DEMOSAIC = "malvar2004"


def default_values(cfa: str = "none") -> dict:
    """{name: value} of every parameter with a default, as a point takes it when nobody sets
    it: evaluate's default, and with a colour filter (``cfa="bayer"`` or ``"quad_bayer"``)
    its transmittance and colour noise gain (:mod:`epc_fast.cfa`)."""
    values = {p.name: p.default for p in PARAMETERS if p.default is not None}
    if cfa != "none":
        values.update(cfa_transmittance=DEFAULT_CFA_TRANSMITTANCE,
                      color_noise_gain=DEFAULT_COLOR_NOISE_GAIN)
    return values


def designs_terms(names, table: dict, cfa: str = "none", skip=()) -> list[str]:
    """One phrase per parameter of ``table`` ({name: one value per design of ``names``}) that
    is on in some design, in the model's order: ``"stabilization 4"`` when every design has
    it, ``"read_noise_e 2 (A), 0 (B)"`` when they differ; ``skip`` left out."""
    defaults = default_values(cfa)
    terms = []
    for name in defaults:
        if name in NOT_TERMS or name in skip or name not in table:
            continue
        values = np.asarray(table[name], dtype=float)
        if np.all(values == defaults[name]):
            continue
        if np.all(values == values[0]):
            terms.append(f"{name} {values[0]:g}")
        else:
            terms.append(f"{name} " + ", ".join(f"{value:g} ({design})"
                                                for value, design in zip(values, names)))
    return terms


def terms_on(space) -> list[str]:
    """One phrase per term ``space`` (:class:`epc_fast.scan.Space`) turns on that is not one of
    its axes: the colour filter and its demosaicker, the lens tables, a spectrum, EPC counted in
    both directions, the frame cap (``"frame cap 0.1 s"``), the designs' parameters that
    differ from their defaults, charge binning, readout modes and night mode."""
    options = space.evaluate_options
    cfa = options.get("cfa", "none")
    terms = []
    if cfa != "none":
        terms.append(f"colour filter {CFA_NAMES.get(cfa, cfa)}, "
                     f"{options.get('demosaic', DEFAULT_DEMOSAIC)} demosaicking")
    if options.get("lens_mtf") is not None:
        count = space.lens_count
        terms.append("lens MTF table (1)" if count == 1
                     else f"lens MTF tables ({count}), picked by lens")
    if options.get("spectrum") is not None:
        terms.append("diffraction over a spectrum")
    if options.get("epc_axes", "motion") != "motion":
        terms.append("EPC in both directions (4 S f50 f50_across)")
    if options.get("max_exposure_s", math.inf) != math.inf:
        terms.append(f"frame cap {options['max_exposure_s']:g} s")
    terms += designs_terms(space.design_names, space.design_table, cfa, skip=space.axes)
    return terms + readout_terms(space.design_names, space.design_readout, space.design_modes)


def readout_terms(names, readouts, modes) -> list[str]:
    """``"charge binning (A)"`` and ``"readout modes (A: 3)"`` for the designs of ``names``
    that read their binned pixels as charge or pick among modes (``readouts``: each design's
    ``binning_readout``; ``modes``: each design's modes or None), and ``"night mode up to 8
    frames (A)"`` for those with a night mode (``frames="auto"``); "every design" when all
    do."""
    terms = []
    charge = [name for name, readout in zip(names, readouts) if readout == "charge"]
    if charge:
        which = "every design" if len(charge) == len(names) else ", ".join(charge)
        terms.append(f"charge binning ({which})")
    picked = [f"{name}: {len(m)}" for name, m in zip(names, modes) if m]
    if picked:
        terms.append(f"readout modes ({'; '.join(picked)})")
    night: dict = {}  # the most frames of each design's night modes -> the designs
    for name, design_modes in zip(names, modes):
        most = max((m["max_frames"] for m in design_modes or () if m.get("frames") == "auto"),
                   default=None)
        if most is not None:
            night.setdefault(most, []).append(name)
    for most, designs in night.items():
        which = "every design" if len(designs) == len(names) else ", ".join(designs)
        terms.append(f"night mode up to {most:g} frames ({which})")
    return terms
