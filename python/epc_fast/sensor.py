"""A sensor as its data sheet gives it, and where a design meets its SNR target.

Size. A data sheet gives the active area's width and height in mm, or its diagonal and aspect
ratio, and the pixel pitch in um. The model needs the sensor area S (docs/model.md, "EPC":
EPC = 4 S f50^2, S = N p^2), so the area is taken exactly, S = width x height, and the pixel
count follows as N = S / p^2 = (width / p) x (height / p) with no rounding: rounding the columns
and rows would move S away from the sensor's area. That N is the package's one physical pixel
count, :func:`physical_pixel_count`: a :class:`epc_fast.presets.Design`'s ``pixel_count``, the
dotted lines of the paper's figures and of a scan's bands, the paper's kept fractions.
:class:`~epc_fast.presets.Design` reports whole columns and rows (each rounded to the nearest
integer) for display only.

Where the SNR target is met (``snr_at``). The light falls off as cos^4 of the field angle
(docs/model.md, "Exposure: T_MPE"), so the same target met at the image corner asks for a
longer exposure than on the optical axis, and moves EPC several-fold:

- ``"axis"``: the optical axis, field angle 0 (``evaluate``'s default, docs/model.md's θ = 0);
- ``"corner"``: the image corner, field angle atan(half-diagonal / focal length) (the presets'
  reading of the paper, docs/model.md, "The paper's systems"; 27.03 degrees for its 1/3.2"
  designs);
- or an explicit ``field_angle_deg``.

:func:`epc_fast.evaluate` is the model and meets the target on the axis unless told. A
design (a preset, a :class:`~epc_fast.presets.Design`, a ``[[design.custom]]`` table) meets it
at the corner when it gives its sensor's shape and focal length, on the axis otherwise; the
space a scan prints names which, marked "default" where the design did not choose.
"""

from __future__ import annotations

import math
import numbers
from typing import NamedTuple

import numpy as np

from . import params
from ._validation import as_float_array, short
from .params import BIG
from .portable_math import arctan_deg

__all__ = ["SNR_AT", "SHAPE_KEYWORDS", "SIZE_WAYS", "SIZE_AND_SNR_AT", "aspect_ratio", "sensor_shape",
           "corner_field_angle_deg", "physical_pixel_count", "check_snr_at", "snr_at_text",
           "design_parameters", "SizeSlot", "size_and_field_angle"]

#: The named places where the SNR target can be met.
SNR_AT = ("axis", "corner")
#: The keywords that give a sensor's shape (width and height, or diagonal and aspect).
SHAPE_KEYWORDS = ("sensor_width_mm", "sensor_height_mm", "sensor_diagonal_mm", "aspect")
#: How a sensor's size can be given, for error messages.
SIZE_WAYS = ("pixel_count, or sensor_area_mm2, or sensor_width_mm and sensor_height_mm, "
             "or sensor_diagonal_mm and aspect")
#: What the ways of giving the size mean for where the SNR target is met, for error messages.
SIZE_AND_SNR_AT = ('snr_at = "corner" (the default of a design that gives its shape and focal '
                   "length) needs sensor_width_mm and sensor_height_mm, or sensor_diagonal_mm "
                   "and aspect; with sensor_area_mm2 or pixel_count the SNR target is met on "
                   "the axis unless the design gives field_angle_deg")


def aspect_ratio(aspect) -> float:
    """1: width / height of an aspect ratio written ``"4:3"``, ``"16/9"``, ``(4, 3)`` or ``4/3``.

    Raises ValueError naming ``aspect`` and its value for anything else.
    """
    ratio = math.nan
    if isinstance(aspect, str):
        for sep in (":", "/", "x"):
            if sep in aspect:
                parts = aspect.split(sep)
                if len(parts) == 2:
                    try:
                        ratio = float(parts[0]) / float(parts[1])
                    except (ValueError, ZeroDivisionError):
                        ratio = math.nan
                break
        else:
            try:
                ratio = float(aspect)
            except ValueError:
                ratio = math.nan
    elif isinstance(aspect, (tuple, list)) and len(aspect) == 2 and all(
            isinstance(a, numbers.Real) and not isinstance(a, bool) for a in aspect):
        ratio = float(aspect[0]) / float(aspect[1]) if aspect[1] != 0 else math.nan
    elif isinstance(aspect, numbers.Real) and not isinstance(aspect, bool):
        ratio = float(aspect)
    if not (math.isfinite(ratio) and ratio > 0):
        raise ValueError(f"aspect={short(aspect)}: expected width:height as \"4:3\", (4, 3) "
                         "or a positive number (width / height)")
    return ratio


def sensor_shape(sensor_width_mm=None, sensor_height_mm=None, sensor_diagonal_mm=None,
                 aspect=None, **others):
    """(width_mm, height_mm) of a sensor given by width and height or by diagonal and aspect;
    None when none of the four is given.

    ``others`` are the other ways of giving the size (``sensor_area_mm2``, ``pixel_count``),
    None when not given: any combination but exactly one way is a TypeError naming every
    argument given and its value. Widths, heights and diagonals may be arrays (float64 out).
    """
    given = {"sensor_width_mm": sensor_width_mm, "sensor_height_mm": sensor_height_mm,
             "sensor_diagonal_mm": sensor_diagonal_mm, "aspect": aspect, **others}
    given = {k: v for k, v in given.items() if v is not None}
    ways = [{"sensor_width_mm", "sensor_height_mm"}, {"sensor_diagonal_mm", "aspect"},
            *({k} for k in others)]
    if set(given) not in ways:
        got = ", ".join(f"{k}={short(v)}" for k, v in given.items()) or "none of them"
        raise TypeError(f"give the sensor's size one way: {SIZE_WAYS}; got {got}")
    if "sensor_width_mm" in given:
        return (np.asarray(sensor_width_mm, dtype=np.float64),
                np.asarray(sensor_height_mm, dtype=np.float64))
    if "aspect" in given:
        ratio = aspect_ratio(aspect)
        diagonal = np.asarray(sensor_diagonal_mm, dtype=np.float64)
        height = diagonal / math.hypot(ratio, 1.0)
        return height * ratio, height
    return None


def corner_field_angle_deg(width_mm, height_mm, focal_length_mm):
    """degree: the image corner's field angle, atan(half-diagonal / focal length) (half the
    diagonal field of view); the same bits on every CPU (:mod:`epc_fast.portable_math`)."""
    half_diagonal = np.hypot(width_mm, height_mm) / 2.0
    with np.errstate(divide="ignore", invalid="ignore"):
        angle = arctan_deg(half_diagonal / np.asarray(focal_length_mm, np.float64))
    return float(angle) if np.ndim(angle) == 0 else angle


class SizeSlot(NamedTuple):
    """The model's size parameter of one call: its name in messages, its value (pixels or
    mm^2), whether it is a pixel count, and the lengths it was made of (for messages)."""

    name: str
    value: object
    is_pixel_count: bool
    parts: dict


def _size_slot(pixel_count, sensor_area_mm2) -> SizeSlot:
    """The size slot of a sensor given as a pixel count or as an area (the other None)."""
    if pixel_count is not None:
        return SizeSlot("pixel_count", pixel_count, True, {})
    return SizeSlot("sensor_area_mm2", sensor_area_mm2, False, {})


def size_and_field_angle(pixel_count, sensor_area_mm2, sensor_width_mm, sensor_height_mm,
                         sensor_diagonal_mm, aspect, snr_at, field_angle_deg,
                         focal_length_mm) -> tuple:
    """(:class:`SizeSlot`, degree field angle) of one call, from however the caller gave them.

    The area of a width and a height (or a diagonal and an aspect ratio) is their product,
    NaN where a length is outside (0, BIG) so that the point is INVALID. ``snr_at="corner"``
    is atan(half-diagonal / focal length), which needs the sensor's shape; ``"axis"`` is 0;
    None keeps ``field_angle_deg``.
    """
    if (sensor_width_mm is None and sensor_height_mm is None and sensor_diagonal_mm is None
            and aspect is None and snr_at is None
            and (pixel_count is None) != (sensor_area_mm2 is None)):
        # the size as an area or a pixel count, as most calls give it
        return _size_slot(pixel_count, sensor_area_mm2), field_angle_deg
    lengths = [None if v is None else as_float_array(k, v) for k, v in (
        ("sensor_width_mm", sensor_width_mm), ("sensor_height_mm", sensor_height_mm),
        ("sensor_diagonal_mm", sensor_diagonal_mm))]
    shape = sensor_shape(sensor_width_mm, sensor_height_mm, sensor_diagonal_mm, aspect,
                         sensor_area_mm2=sensor_area_mm2, pixel_count=pixel_count)
    if shape is None:
        sensor = _size_slot(pixel_count, sensor_area_mm2)
    else:
        width, height = shape
        length = params.Param("length", None, 0.0, BIG, False, False, "mm")
        valid = params.in_domain(length, width) & params.in_domain(length, height)
        with np.errstate(all="ignore"):
            area = np.where(valid, width * height, np.nan)
        if sensor_width_mm is not None:
            parts = {"sensor_width_mm": width, "sensor_height_mm": height}
        else:
            parts = {"sensor_diagonal_mm": lengths[2]}
        sensor = SizeSlot(" x ".join(parts), area, False, parts)
    if snr_at is None:
        return sensor, field_angle_deg
    check_snr_at(snr_at)
    if np.any(np.asarray(field_angle_deg) != 0.0):
        raise TypeError(f"give snr_at or field_angle_deg, not both (snr_at={snr_at!r}, "
                        f"field_angle_deg={short(field_angle_deg)})")
    if snr_at == "axis":
        return sensor, 0.0
    if shape is None:
        raise TypeError("snr_at='corner' needs the sensor's diagonal: give sensor_width_mm and "
                        "sensor_height_mm, or sensor_diagonal_mm and aspect (not "
                        f"{sensor.name}), or field_angle_deg")
    focal = as_float_array("focal_length_mm", focal_length_mm)
    return sensor, corner_field_angle_deg(shape[0], shape[1], focal)


def physical_pixel_count(sensor_area_mm2, pixel_pitch_um):
    """pixels: a design's physical pixel count, N = S / p², the sensor's area over the pitch
    squared (docs/model.md, "EPC"), unrounded: the N of EPC = N (f50 / f_Nyq)², so EPC reaches
    it where f50 reaches the Nyquist frequency. The package's one rule: a Design's
    ``pixel_count``, the paper's kept fractions, the dotted lines of the paper's figures and of
    a scan's bands all come from here. A float, or an array for arrays."""
    count = (np.asarray(sensor_area_mm2, dtype=float) * 1e6
             / np.asarray(pixel_pitch_um, dtype=float) ** 2)
    return float(count) if count.ndim == 0 else count


def check_snr_at(snr_at) -> str:
    """``snr_at`` when it is one of :data:`SNR_AT`, else a ValueError naming its value."""
    if not isinstance(snr_at, str) or snr_at not in SNR_AT:
        raise ValueError(f"snr_at={short(snr_at)}: expected one of "
                         f"{', '.join(map(repr, SNR_AT))} (or give field_angle_deg)")
    return snr_at


def snr_at_text(snr_at: str | None, field_angle_deg: float, default: bool = False) -> str:
    """Where a design meets its SNR target, for people: ``"corner (27.03 deg)"``, ``"axis"``,
    ``"field angle 12 deg"``; ``default`` marks a place nobody chose:
    ``"corner (27.03 deg, default)"``, ``"axis (default)"``."""
    mark = ", default" if default else ""
    if snr_at == "corner":
        return f"corner ({field_angle_deg:.2f} deg{mark})"
    if snr_at == "axis" or (snr_at is None and field_angle_deg == 0.0):
        return "axis (default)" if default else "axis"
    return f"field angle {field_angle_deg:g} deg" + (" (default)" if default else "")


def design_parameters(entry) -> tuple[dict, str]:
    """(:func:`epc_fast.evaluate` keywords, where the SNR target is met, for people) of one
    design given as a mapping of evaluate keywords, its sensor given any of the four ways.

    Where the target is met: ``snr_at`` (``"axis"`` or ``"corner"``) or ``field_angle_deg``
    when the design says; else the image corner when the design gives its sensor's shape and
    focal length, as the presets do (marked "default"); else the axis (marked "default").
    """
    kwargs = dict(entry)
    snr_at = kwargs.pop("snr_at", None)
    shape_given = {k: kwargs.pop(k) for k in SHAPE_KEYWORDS if k in kwargs}
    shape = None
    for key, value in shape_given.items():
        if key != "aspect" and not (isinstance(value, numbers.Real) and 0.0 < value < BIG):
            raise ValueError(f"{key}={short(value)}: expected a length in (0, {BIG:g}) mm")
    if shape_given:
        others = {k: kwargs.pop(k) for k in ("sensor_area_mm2", "pixel_count") if k in kwargs}
        shape = sensor_shape(**shape_given, **others)
        kwargs["sensor_area_mm2"] = float(shape[0] * shape[1])
    focal = kwargs.get("focal_length_mm")
    if snr_at is not None:
        check_snr_at(snr_at)
        if "field_angle_deg" in kwargs:
            raise TypeError(f"give snr_at or field_angle_deg, not both (snr_at={snr_at!r}, "
                            f"field_angle_deg={short(kwargs['field_angle_deg'])})")
        if snr_at == "axis":
            kwargs["field_angle_deg"] = 0.0
            return kwargs, snr_at_text("axis", 0.0)
        if shape is None or focal is None:
            raise TypeError("snr_at='corner' needs the sensor's diagonal and the focal length: "
                            "give sensor_width_mm and sensor_height_mm (or sensor_diagonal_mm "
                            "and aspect) and focal_length_mm, or field_angle_deg")
    elif "field_angle_deg" in kwargs:
        return kwargs, snr_at_text(None, float(kwargs["field_angle_deg"]))
    elif shape is None or focal is None:
        return kwargs, snr_at_text("axis", 0.0, default=True)
    angle = corner_field_angle_deg(float(shape[0]), float(shape[1]), float(focal))
    kwargs["field_angle_deg"] = angle
    return kwargs, snr_at_text("corner", angle, default=snr_at is None)
