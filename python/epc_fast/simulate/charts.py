"""Test charts for the capture simulator: a slanted edge (ISO 12233), a flat grey patch and any
reflectance image, each a scene the simulator can render at any point of the sensor plane.

A chart is laid out in output pixels: pixel (i, j) of the capture is centred on the chart's
point (y, x) = (i, j), and a chart answers for any continuous point, also beyond its own size
(the scene goes on past the crop: :meth:`Chart.reflectance_at`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import short

__all__ = ["Chart", "slanted_edge", "flat", "image", "MIN_EDGE_PX"]

#: Pixels, the fewest rows and columns of a slanted-edge chart: the e-SFR needs rows enough to
#: fit the edge's line and columns enough for its spread on either side.
MIN_EDGE_PX = 16


@dataclass(frozen=True, eq=False)
class Chart:
    """A test chart in linear reflectance, laid out in output pixels.

    Attributes
    ----------
    kind : {"slanted_edge", "flat", "image"}
    shape : (rows, columns), output pixels.
    low, high : 1, the edge's dark and light reflectances (``slanted_edge``); ``high`` is the
        patch's reflectance for ``flat``.
    angle_deg : degrees, the edge's angle from the vertical (``slanted_edge``).
    values : the reflectance of each output pixel (``image``), read-only float64.
    """

    kind: str
    shape: tuple[int, int]
    low: float = math.nan
    high: float = math.nan
    angle_deg: float = math.nan
    values: np.ndarray | None = None

    def reflectance(self) -> np.ndarray:
        """The chart's reflectance at the output pixels' centres, shape ``self.shape``
        (the edge of a slanted edge sharp, as the scene has it)."""
        if self.kind == "image":
            return self.values.copy()
        rows, cols = self.shape
        y, x = np.meshgrid(np.arange(rows, dtype=float), np.arange(cols, dtype=float),
                           indexing="ij")
        return self.reflectance_at(y, x, pitch_um=1.0, band_cyc_per_mm=math.inf)

    def reflectance_at(self, y_px, x_px, *, pitch_um: float,
                       band_cyc_per_mm: float) -> np.ndarray:
        """The reflectance at points (y_px, x_px) given in output pixels.

        Parameters
        ----------
        y_px, x_px : arrays broadcasting together, output pixels (pixel (i, j) is centred at
            (i, j)); points beyond the chart see the scene continue: the edge and the patch
            go on, an image repeats its border pixels.
        pitch_um : µm, the output pitch: it scales the edge's distances to mm.
        band_cyc_per_mm : cycles/mm. The slanted edge is rendered band-limited along its
            normal: the sharp step convolved with an ideal low-pass at this frequency,
            1/2 + Si(2 pi band d)/pi at normal distance d. Its spectrum is then exactly the
            step's up to the band and nothing above, so sampling it on a grid with
            1/spacing >= band + (the optics' cut-off) aliases nothing into the frequencies
            the optics pass. ``inf`` gives the sharp step.
        An image gives each point the pixel its point falls in: exact area sampling when the
        points are the centres of cells that tile the pixels.
        """
        y = np.asarray(y_px, dtype=float)
        x = np.asarray(x_px, dtype=float)
        if self.kind == "flat":
            return np.full(np.broadcast_shapes(y.shape, x.shape), self.high)
        if self.kind == "image":
            rows, cols = self.shape
            i = np.clip(np.floor(y + 0.5).astype(np.int64), 0, rows - 1)
            j = np.clip(np.floor(x + 0.5).astype(np.int64), 0, cols - 1)
            return self.values[i, j]
        return self._edge(y, x, pitch_um, band_cyc_per_mm)

    def _edge(self, y, x, pitch_um, band):
        rows, cols = self.shape
        angle = math.radians(self.angle_deg)
        centre_y, centre_x = (rows - 1) / 2.0, (cols - 1) / 2.0
        # Signed distance to the edge along its normal, mm: the edge is the line through the
        # chart's centre at angle_deg from the vertical, dark on the left.
        d_mm = ((x - centre_x) * math.cos(angle) - (y - centre_y) * math.sin(angle)) \
            * pitch_um * 1e-3
        if math.isinf(band):
            step = np.where(d_mm > 0, 1.0, np.where(d_mm < 0, 0.0, 0.5))
        else:
            from scipy.special import sici

            step = 0.5 + sici(2.0 * math.pi * band * d_mm)[0] / math.pi
        return self.low + (self.high - self.low) * step


def _size(size_px, minimum: int, what: str) -> tuple[int, int]:
    """(rows, columns) from an int or a pair, each an integer >= minimum."""
    pair = (size_px, size_px) if np.ndim(size_px) == 0 else tuple(size_px)
    if len(pair) != 2:
        raise ValueError(f"size_px: an integer or (rows, columns), got {short(size_px)}")
    out = []
    for v in pair:
        if isinstance(v, (bool, np.bool_)) or not _is_real(v) or not float(v).is_integer():
            raise ValueError(f"size_px: whole numbers of pixels, got {short(size_px)}")
        if int(v) < minimum:
            raise ValueError(f"size_px: {what} needs at least {minimum} pixels a side, "
                             f"got {short(size_px)}")
        out.append(int(v))
    return out[0], out[1]


def _is_real(v) -> bool:
    try:
        return math.isfinite(float(v)) and not isinstance(v, (complex, np.complexfloating))
    except (TypeError, ValueError):
        return False


def _reflectance(value, name: str) -> float:
    if not _is_real(value) or isinstance(value, (bool, np.bool_)) or not 0.0 <= float(value) <= 1.0:
        raise ValueError(f"{name}: a reflectance in [0, 1], got {short(value)}")
    return float(value)


def slanted_edge(size_px=256, angle_deg: float = 5.0, *, low: float = 0.1,
                 high: float = 0.4) -> Chart:
    """A slanted edge as ISO 12233 uses it: dark on the left, light on the right, through the
    chart's centre at ``angle_deg`` from the vertical.

    Parameters
    ----------
    size_px : int or (rows, columns)
        Output pixels, at least :data:`MIN_EDGE_PX` a side. Motion blur runs along the rows,
        so a long blur wants many columns (the e-SFR needs the blur well inside them).
    angle_deg : degrees, in [1, 30] in magnitude (the e-SFR needs a slant: about 5 is ISO's).
    low, high : 1, the reflectances either side (default 4:1, ISO 12233:2017's contrast,
        with the light side at the model's default target reflectance, 0.4).
    """
    rows, cols = _size(size_px, MIN_EDGE_PX, "a slanted edge (the e-SFR)")
    if not _is_real(angle_deg) or not 1.0 <= abs(float(angle_deg)) <= 30.0:
        raise ValueError(f"angle_deg: the edge's slant from the vertical, 1 to 30 degrees "
                         f"either way, got {short(angle_deg)}")
    low, high = _reflectance(low, "low"), _reflectance(high, "high")
    if not high > low:
        raise ValueError(f"high: must exceed low for an edge, got low={low!r}, high={high!r}")
    return Chart("slanted_edge", (rows, cols), low=low, high=high, angle_deg=float(angle_deg))


def flat(size_px=256, reflectance: float = 0.4) -> Chart:
    """A uniform grey patch, for the SNR.

    Parameters
    ----------
    size_px : int or (rows, columns), output pixels, at least 2 a side.
    reflectance : 1, in [0, 1] (default the model's default target, 0.4).
    """
    rows, cols = _size(size_px, 2, "a flat patch (its noise)")
    return Chart("flat", (rows, cols), high=_reflectance(reflectance, "reflectance"))


def image(reflectance_array) -> Chart:
    """Any scene: one reflectance per output pixel (linear, in [0, 1]), each pixel's square of
    the scene uniform.

    Parameters
    ----------
    reflectance_array : 2-D array_like of real numbers in [0, 1], at least 1 x 1.
    """
    a = np.asarray(reflectance_array)
    if a.ndim != 2:
        raise ValueError(f"reflectance_array: a 2-D array, got {a.ndim} dimension(s), "
                         f"shape {a.shape}")
    if a.dtype == bool or a.dtype.kind not in "iuf":
        raise TypeError(f"reflectance_array: real numbers, got dtype {a.dtype}")
    if a.size == 0:
        raise ValueError(f"reflectance_array: at least 1 x 1 pixels, got shape {a.shape}")
    values = a.astype(np.float64)
    bad = ~(np.isfinite(values) & (values >= 0.0) & (values <= 1.0))
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"reflectance_array: reflectances in [0, 1], got "
                         f"{values[where]!r} at index {where}")
    values.flags.writeable = False
    return Chart("image", values.shape, values=values)
