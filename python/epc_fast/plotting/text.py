"""Text on figures: units as a reader writes them, and axis labels derived from names.

Parameter and output names carry their unit as an ASCII suffix (``illuminance_lux``,
``pixel_pitch_um``); a figure shows "Illuminance (lux)" and "Pixel pitch (µm)". Design names
and the readings' descriptions write micrometres as ``um`` and powers as ``^4``; on a figure
they read ``µm`` and ``⁴``. No matplotlib here: these are plain strings.
"""

from __future__ import annotations

import re

__all__ = ["unit_text", "quantity_label", "quantity_unit", "output_scale"]

_MICROMETRE = re.compile(r"(?<![A-Za-z])um(?![A-Za-z])")
_POWER = re.compile(r"\^(-?\d+)")
_SUPERSCRIPTS = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")

#: Unit suffixes of names, longest first, and how a figure writes them.
UNIT_SUFFIXES = (
    ("_per_lux_s_m2", "e⁻/(lux s m²)"), ("_deg_per_s", "°/s"), ("_cyc_per_mm", "cycles/mm"),
    ("_e_per_s", "e⁻/s"), ("_mm2", "mm²"), ("_lux", "lux"), ("_um", "µm"), ("_mm", "mm"),
    ("_nm", "nm"), ("_deg", "°"), ("_db", "dB"), ("_e", "e⁻"), ("_s", "s"),
)
#: Names whose words are not their name's words.
_QUANTITIES = {
    "epc": "EPC", "f_number": "f-number", "f50_cyc_per_mm": "f50",
    "t_mpe": "Exposure time T_MPE", "stabilization": "Stabilisation factor", "prnu": "PRNU",
    "snr": "SNR", "pixel_count": "Pixel count", "shake": "Hand shake",
    "mtf_threshold": "MTF threshold",
    "electrons_per_lux_s_m2": "Photo-electron yield",
}
#: Outputs drawn in a larger unit than their own: name -> (divisor, unit shown).
_SCALED = {"epc": (1e6, "Mpixel"), "pixel_count": (1e6, "Mpixel")}


def unit_text(text) -> str:
    """``text`` with ``um`` written ``µm`` and ``^n`` as a superscript (``cos^4`` -> ``cos⁴``)."""
    text = _MICROMETRE.sub("µm", str(text))
    return _POWER.sub(lambda m: m.group(1).translate(_SUPERSCRIPTS), text)


def output_scale(name: str) -> float:
    """1: what values of ``name`` are divided by before they are drawn (EPC in Mpixel: 1e6)."""
    return _SCALED.get(name, (1.0, ""))[0]


def quantity_unit(name: str) -> str:
    """The unit a figure draws ``name`` in ("" for a pure number): ``"epc"`` -> ``"Mpixel"``."""
    if name in _SCALED:
        return _SCALED[name][1]
    return next((shown for suffix, shown in UNIT_SUFFIXES
                 if name.endswith(suffix) and len(name) > len(suffix)), "")


def quantity_label(name: str) -> str:
    """An axis label for a parameter or output name: its words, capitalised, and its unit in
    parentheses (``"illuminance_lux"`` -> ``"Illuminance (lux)"``, ``"epc"`` ->
    ``"EPC (Mpixel)"``). A name without a known suffix is a pure number: no unit."""
    if name in _SCALED:
        return f"{_QUANTITIES.get(name, name)} ({_SCALED[name][1]})"
    stem, unit = name, ""
    for suffix, shown in UNIT_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            stem, unit = name[:-len(suffix)], shown
            break
    words = _QUANTITIES.get(name) or _QUANTITIES.get(stem)
    if words is None:
        words = stem.replace("_", " ")
        words = words[:1].upper() + words[1:]
    return f"{words} ({unit})" if unit else words
