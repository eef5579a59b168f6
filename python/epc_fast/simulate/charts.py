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

__all__ = ["Chart", "slanted_edge", "flat", "image", "MIN_EDGE_PX", "EDGE_ANGLES_DEG",
           "band_limited_step", "STEP_TOLERANCE"]

#: Pixels, the fewest rows and columns of a slanted-edge chart: the e-SFR needs rows enough to
#: fit the edge's line and columns enough for its spread on either side.
MIN_EDGE_PX = 16
#: Degrees, the slanted edge's angles from the vertical (either sign): a near-vertical edge,
#: measured across the columns, or a near-horizontal one, measured across the rows (the
#: e-SFR's 1 to 30 degrees from the horizontal, 89 to 60 from the vertical).
EDGE_ANGLES_DEG = ((1.0, 30.0), (60.0, 89.0))


@dataclass(frozen=True, eq=False)
class Chart:
    """A test chart in linear reflectance, laid out in output pixels.

    Attributes
    ----------
    kind : {"slanted_edge", "flat", "image"}
    shape : (rows, columns), output pixels.
    low, high : 1, the edge's dark and light reflectances (``slanted_edge``); ``high`` is the
        patch's reflectance for ``flat``.
    angle_deg : degrees, the edge's angle from the vertical (``slanted_edge``): near the
        vertical (1 to 30 either way) or near the horizontal (60 to 89 either way).
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
            the optics pass. ``inf`` gives the sharp step. On a grid (``y_px`` a column,
            ``x_px`` a row) Si comes from :func:`band_limited_step`, within
            :data:`STEP_TOLERANCE` of the exact value; elsewhere from ``scipy.special.sici``.
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
        if math.isinf(band):
            d_mm = ((x - centre_x) * math.cos(angle) - (y - centre_y) * math.sin(angle)) \
                * pitch_um * 1e-3
            step = np.where(d_mm > 0, 1.0, np.where(d_mm < 0, 0.0, 0.5))
        else:
            # The step's argument 2 pi band d, a term of the column plus a term of the row.
            scale = 2.0 * math.pi * band * pitch_um * 1e-3
            u_x = (x - centre_x) * (scale * math.cos(angle))
            u_y = (y - centre_y) * (-scale * math.sin(angle))
            if u_y.ndim == 2 and u_x.ndim == 2 and u_y.shape[1] == 1 and u_x.shape[0] == 1:
                step = band_limited_step(u_y[:, 0], u_x[0])
            else:
                from scipy.special import sici

                step = 0.5 + sici(u_y + u_x)[0] / math.pi
        step *= self.high - self.low  # in place: the fine grid's array is large
        step += self.low
        return step


#: 1, the most :func:`band_limited_step` differs from 1/2 + Si(u)/pi: Si's asymptotic series
#: cut after three terms each leaves at most 720/U^7 + 5040/U^8 for abs(u) >= U (each remainder
#: is bounded by its first neglected term, DLMF 6.12.ii), 5.8e-11 after dividing by pi at
#: U = 64 (4.2e-11 is the most seen); the rest is float64 rounding, under 1e-14.
STEP_TOLERANCE = 1e-10
#: Radians: where |u| is below this, band_limited_step takes Si from scipy.special.sici.
_SI_SERIES_FROM = 64.0
#: Elements of a block of rows band_limited_step computes at once (its temporaries stay in
#: the cache).
_BLOCK_ELEMENTS = 32768


def band_limited_step(u_rows, u_cols) -> np.ndarray:
    """1/2 + Si(u)/pi on the grid u[i, j] = u_rows[i] + u_cols[j], shape (rows, columns):
    the sharp step through an ideal low-pass, u = 2 pi band d at normal distance d.

    scipy.special.sici costs some 30 ns a point, a capture's fine grid millions of points.
    Here Si comes from sici only where abs(u) < 64 (a few dozen columns a row); elsewhere from
    its asymptotic expansion Si(u) = sign(u) pi/2 - f(u) cos u - g(u) sin u, with
    f = (1 - 2/u^2 + 24/u^4)/u and g = (1 - 6/u^2 + 120/u^4)/u^2, and cos u and sin u from
    those of the rows' and the columns' terms by the angle-addition formulas (no
    trigonometry per point): some 10 ns a point, within :data:`STEP_TOLERANCE` of sici.
    """
    from scipy.special import sici

    u_rows = np.asarray(u_rows, dtype=float)
    u_cols = np.asarray(u_cols, dtype=float)
    rows, cols = u_rows.size, u_cols.size
    out = np.empty((rows, cols))
    # The columns' cosines and sines carry -1/pi, so cb and sb below are -cos u/pi, -sin u/pi.
    cos_c, sin_c = np.cos(u_cols) / -math.pi, np.sin(u_cols) / -math.pi
    cos_r, sin_r = np.cos(u_rows)[:, None], np.sin(u_rows)[:, None]
    block = max(1, _BLOCK_ELEMENTS // max(cols, 1))
    u, w, w2, c, s, t = (np.empty((min(block, rows), cols)) for _ in range(6))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for i in range(0, rows, block):
            n = min(block, rows - i)
            ub, wb, w2b, cb, sb, tb = (a[:n] for a in (u, w, w2, c, s, t))
            r = slice(i, i + n)
            ob = out[r]
            np.add(u_rows[r, None], u_cols, out=ub)
            np.divide(1.0, ub, out=wb)
            np.multiply(wb, wb, out=w2b)
            np.multiply(cos_r[r], cos_c, out=cb)
            cb -= np.multiply(sin_r[r], sin_c, out=tb)
            np.multiply(sin_r[r], cos_c, out=sb)
            sb += np.multiply(cos_r[r], sin_c, out=tb)
            # -(f cos u + g sin u) / pi = w (cos u P + w sin u Q) / -pi, P and Q in w^2.
            np.multiply(w2b, 24.0, out=tb)
            tb -= 2.0
            tb *= w2b
            tb += 1.0
            cb *= tb
            np.multiply(w2b, 120.0, out=tb)
            tb -= 6.0
            tb *= w2b
            tb += 1.0
            tb *= wb
            sb *= tb
            cb += sb
            cb *= wb
            np.greater(ub, 0.0, out=ob, casting="unsafe")  # 1/2 + sign(u)/2
            ob += cb
            # The columns within the series' reach of some row of the block, exactly.
            near = np.flatnonzero((u_cols > -_SI_SERIES_FROM - u_rows[r].max())
                                  & (u_cols < _SI_SERIES_FROM - u_rows[r].min()))
            if near.size:
                ob[:, near] = 0.5 + sici(u_rows[r, None] + u_cols[near])[0] / math.pi
    return out


def _size(size_px, minimum: int, what: str) -> tuple[int, int]:
    """(rows, columns) from an int or a pair, each an integer >= minimum."""
    pair = (size_px, size_px) if np.ndim(size_px) == 0 else tuple(size_px)
    if len(pair) != 2:
        raise ValueError(f"size_px: an integer or (rows, columns), got {short(size_px)}")
    out = []
    for v in pair:
        if isinstance(v, (bool, np.bool_)) or not is_real(v) or not float(v).is_integer():
            raise ValueError(f"size_px: whole numbers of pixels, got {short(size_px)}")
        if int(v) < minimum:
            raise ValueError(f"size_px: {what} needs at least {minimum} pixels a side, "
                             f"got {short(size_px)}")
        out.append(int(v))
    return out[0], out[1]


def is_real(v) -> bool:
    """Whether ``v`` is a finite real number (not complex)."""
    try:
        return math.isfinite(float(v)) and not isinstance(v, (complex, np.complexfloating))
    except (TypeError, ValueError):
        return False


def checked_reflectance(value, name: str) -> float:
    """1: ``value`` as a reflectance in [0, 1], or a ValueError naming ``name`` and it."""
    if not is_real(value) or isinstance(value, (bool, np.bool_)) or not 0.0 <= float(value) <= 1.0:
        raise ValueError(f"{name}: a reflectance in [0, 1], got {short(value)}")
    return float(value)


def slanted_edge(size_px=256, angle_deg: float = 5.0, *, low: float = 0.1,
                 high: float = 0.4) -> Chart:
    """A slanted edge as ISO 12233 uses it: through the chart's centre at ``angle_deg`` from
    the vertical, running to larger columns down the rows for a positive angle; the upright
    edge turned by that angle from dark on the left and light on the right (a
    near-horizontal edge is dark below at a positive angle, dark above at a negative one).

    Parameters
    ----------
    size_px : int or (rows, columns)
        Output pixels, at least :data:`MIN_EDGE_PX` a side. Motion blur runs along the rows,
        so a long blur across a near-vertical edge wants many columns (the e-SFR needs the
        blur well inside them); a near-horizontal edge wants rows for its spread.
    angle_deg : degrees, in [1, 30] or [60, 89] in magnitude (:data:`EDGE_ANGLES_DEG`): a
        near-vertical edge, whose e-SFR is the MTF along the rows (about 5 is ISO's slant),
        or a near-horizontal one, whose e-SFR is the MTF along the columns (about 85).
    low, high : 1, the reflectances either side (default 4:1, ISO 12233:2017's contrast,
        with the light side at the model's default target reflectance, 0.4).
    """
    rows, cols = _size(size_px, MIN_EDGE_PX, "a slanted edge (the e-SFR)")
    if not is_real(angle_deg) or not any(low <= abs(float(angle_deg)) <= high
                                         for low, high in EDGE_ANGLES_DEG):
        raise ValueError(f"angle_deg: the edge's angle from the vertical, 1 to 30 degrees "
                         f"(near vertical) or 60 to 89 (near horizontal) either way, got "
                         f"{short(angle_deg)}")
    low, high = checked_reflectance(low, "low"), checked_reflectance(high, "high")
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
    return Chart("flat", (rows, cols), high=checked_reflectance(reflectance, "reflectance"))


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
