"""A Siemens star: spokes round a centre whose period shrinks towards it, so that one picture
shows every frequency at once and where a design stops resolving them.

The star is an :func:`~epc_fast.simulate.charts.image` chart: one reflectance per output pixel,
each the star's average over the pixel's square (area-sampled on SUBSAMPLES x SUBSAMPLES points a
pixel), so the chart itself aliases little. Given a width in µm and a design's pitch, the star
covers the same patch of scene for every design, in as many of its pixels as fit.
"""

from __future__ import annotations

import math

import numpy as np

from .._validation import short
from .charts import Chart, checked_reflectance, image, is_real

__all__ = ["siemens_star", "star_size_px", "SUBSAMPLES", "MIN_STAR_PX", "MAX_STAR_PX",
           "PROFILES"]

#: Sub-samples a pixel a side: the star's value in a pixel is the mean of 8 x 8 points.
SUBSAMPLES = 8
#: Pixels, the smallest star: fewer leave no spoke resolved anywhere.
MIN_STAR_PX = 8
#: Pixels, the largest star a side: 8,192 squared is 0.5 GiB a float64 image.
MAX_STAR_PX = 8192
#: The spokes' profiles round the star: a sine of the angle, or a square wave.
PROFILES = ("sine", "binary")


def star_size_px(width_um: float, pitch_um: float) -> int:
    """Pixels: the side of a star ``width_um`` wide in the pixels of pitch ``pitch_um``,
    ``round(width_um / pitch_um)``: the same patch of scene for every design. A ValueError
    naming ``width_um`` when that is more than :data:`MAX_STAR_PX`."""
    for name, value in (("width_um", width_um), ("pitch_um", pitch_um)):
        if (isinstance(value, (bool, np.bool_)) or not is_real(value)
                or not 0 < float(value) < math.inf):
            raise ValueError(f"{name}: a length > 0 in µm, got {short(value)}")
    pixels = round(float(width_um) / float(pitch_um))
    if pixels > MAX_STAR_PX:
        raise ValueError(f"width_um: {float(width_um):g} µm is {pixels:,} pixels of "
                         f"{float(pitch_um):g} µm; a star has at most {MAX_STAR_PX:,} a side")
    return int(pixels)


def siemens_star(size_px: int = 256, spokes: int = 36, low: float = 0.1, high: float = 0.4, *,
                 profile: str = "sine", width_um: float | None = None,
                 pitch_um: float | None = None) -> Chart:
    """A Siemens star as an :func:`~epc_fast.simulate.image` chart.

    Parameters
    ----------
    size_px : int
        Output pixels a side, at least :data:`MIN_STAR_PX`: the star is the disc inscribed in
        the square; outside it the chart is the spokes' mean reflectance.
    spokes : int
        The cycles round the star (dark and light spoke pairs), at least 4. At radius r pixels
        the period along the circle is 2 pi r / spokes pixels.
    low, high : 1, the darkest and lightest reflectances (default 4:1, as the slanted edge).
    profile : "sine" or "binary"
        Reflectance round the star: mean + amplitude cos(spokes theta), or its sign (a square
        wave).
    width_um, pitch_um : µm, optional
        Given together, they replace ``size_px`` by :func:`star_size_px`: the star covers
        ``width_um`` of the scene in pixels of pitch ``pitch_um``.

    Returns
    -------
    Chart
        ``kind == "image"``, the star centred on the chart's centre.
    """
    if (width_um is None) != (pitch_um is None):
        raise ValueError(f"width_um and pitch_um: give both or neither, got width_um="
                         f"{short(width_um)}, pitch_um={short(pitch_um)}")
    if width_um is not None:
        size_px = star_size_px(width_um, pitch_um)
    if (isinstance(size_px, (bool, np.bool_)) or not is_real(size_px)
            or not float(size_px).is_integer() or int(size_px) < MIN_STAR_PX):
        raise ValueError(f"size_px: a whole number of pixels >= {MIN_STAR_PX}, got "
                         f"{short(size_px)}")
    if int(size_px) > MAX_STAR_PX:
        raise ValueError(f"size_px: a whole number of pixels from {MIN_STAR_PX} to "
                         f"{MAX_STAR_PX:,}, got {short(size_px)}")
    if (isinstance(spokes, (bool, np.bool_)) or not is_real(spokes)
            or not float(spokes).is_integer() or int(spokes) < 4):
        raise ValueError(f"spokes: a whole number >= 4, got {short(spokes)}")
    if profile not in PROFILES:
        raise ValueError(f"profile: one of {', '.join(PROFILES)}, got {short(profile)}")
    low, high = checked_reflectance(low, "low"), checked_reflectance(high, "high")
    if not high > low:
        raise ValueError(f"high: must exceed low for a star, got low={low!r}, high={high!r}")
    return image(_star(int(size_px), int(spokes), low, high, profile))


def _star(n: int, spokes: int, low: float, high: float, profile: str) -> np.ndarray:
    """The star's mean over each pixel's square, from SUBSAMPLES**2 points a pixel."""
    mean, amplitude = (low + high) / 2.0, (high - low) / 2.0
    centre = (n - 1) / 2.0
    pixel = np.arange(n, dtype=float) - centre
    total = np.zeros((n, n))
    for k in range(SUBSAMPLES):
        y = (pixel + (k + 0.5) / SUBSAMPLES - 0.5)[:, None]
        for m in range(SUBSAMPLES):
            x = (pixel + (m + 0.5) / SUBSAMPLES - 0.5)[None, :]
            wave = np.cos(spokes * np.arctan2(y, x))
            if profile == "binary":
                wave = np.where(wave >= 0.0, 1.0, -1.0)
            inside = np.hypot(y, x) <= n / 2.0
            total += np.where(inside, mean + amplitude * wave, mean)
    return np.clip(total / SUBSAMPLES**2, 0.0, 1.0)
