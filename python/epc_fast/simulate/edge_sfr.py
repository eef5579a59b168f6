"""The slanted-edge spatial frequency response: ISO 12233:2017's e-SFR (Annex D).

An image of a straight edge a few degrees off the vertical (or off the horizontal) gives the
MTF along the edge's normal, above the pixel grid's Nyquist frequency: each row meets the edge
at another sub-pixel phase, so the rows' pixels, projected onto the normal, sample the edge
spread function (ESF) a few times per pixel. The steps, as the standard's Annex D and Burns'
sfrmat3/sfrmat4 take them:

1. each row's derivative along x (the FIR [-0.5, +0.5]) and its centroid: the row's edge
   location; a second pass weights each row's derivative by a Hamming window as wide as the
   row, centred on the first pass's line, against noise far from the edge;
2. a least-squares line x_edge(row) through the centroids, whose slope gives the edge angle
   (1 to 30 degrees from the vertical, else the image is refused);
3. every pixel's centre projected onto the edge's normal, d = (x - x_edge(row)) cos(angle) (the
   2017 edition's correction: distances and frequencies along the normal, not along the row),
   over a whole number of phase cycles of rows, averaged in bins of width pitch / oversampling
   (an empty bin takes the linear interpolation of its neighbours);
4. the line spread function (LSF): the binned ESF's central difference [-0.5, 0, +0.5];
5. a Hamming window centred on the LSF's centroid, as wide as the data (or none);
6. the discrete Fourier transform's magnitude, normalised to 1 at f = 0;
7. the derivative's transfer sin(2 pi f D) / (2 pi f D) divided out (D the bin width), and
   with ``bin_correction`` also the bin's average, sinc(f D); the correction is capped at
   10, as sfrmat caps the derivative's.

The default, ``bin_correction=False``, is the standard's e-SFR as test labs compute it
(ISO 12233:2017 Annex D, Burns' sfrmat3/sfrmat4: the derivative's transfer divided out, the
bins' left in), so a lab's figure and this one compare. The bin correction goes beyond the
standard. Averaging the samples that fall in a bin is the ESF convolved with a box of width D,
whose transfer sinc(f D) the standard leaves in the result: with the default 4 bins a pixel it
lowers the MTF by 2.5 % at the pixel Nyquist frequency and by 10 % at twice it, a bias of the
method, not of the camera; MTF50 comes out 0.3 % lower at 0.19 cycles/pixel, 1.0 % at 0.37 and
2.2 % at 0.6 (Gaussian edges and a sharp edge on square pixels, tests/simulate/test_edge_sfr.py). ``bin_correction=True`` divides it out: the camera's own MTF, which the
simulator's agreement with the model (:mod:`epc_fast.simulate.agreement`) measures.

:meth:`EdgeSFR.mtf_at` evaluates the windowed LSF's transform at any frequency (the discrete-time
Fourier transform, a sum over the bins), so :meth:`EdgeSFR.crossing` brackets a level on the
frequency grid and then bisects on the exact transform: MTF50 carries no error of the grid's
spacing, 1 / (the LSF's length), which is coarse next to a long blur's low MTF50.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validation import as_float_array, integer, short

__all__ = ["EdgeSFR", "esfr", "mtf50", "image_in_roi", "MIN_SIDE_PIXELS",
           "ANGLE_RANGE_DEG", "DERIVATIVE_CORRECTION_CAP", "MIN_SHARED_PIXELS"]

#: The fewest rows and columns an image (after its roi) must have.
MIN_SIDE_PIXELS = 16
#: The fewest pixels along the edge's normal that every row must share (where the ESF is
#: binned): fewer leave no room for the edge's transition and the flat sides around it.
MIN_SHARED_PIXELS = 4
#: The edge angles from the vertical (degrees, either sign) the measurement accepts: below
#: 1 degree the rows meet the edge at too few phases, above 30 it is no near-vertical edge.
ANGLE_RANGE_DEG = (1.0, 30.0)
#: The largest factor the derivative's correction multiplies the MTF by (sfrmat's cap).
DERIVATIVE_CORRECTION_CAP = 10.0
#: Terms (frequencies x bins) :meth:`EdgeSFR.mtf_at` sums at a time: 16 MiB of complex phases.
_DTFT_TERMS = 2**20
#: Bisection steps of :meth:`EdgeSFR.crossing`: the bracket shrinks by 2**-60.
_BISECTIONS = 60


@dataclass(frozen=True, eq=False)
class EdgeSFR:
    """The e-SFR of one edge.

    Attributes
    ----------
    frequency_cyc_per_mm : ndarray
        cycles/mm along the edge's normal, from 0 to oversampling / 2 cycles/pixel (twice the
        pixel Nyquist frequency and more for oversampling >= 2), the DFT's grid.
    mtf : ndarray
        1: the MTF at those frequencies, 1 at f = 0, with the derivative's transfer divided
        out (and the bins' with ``bin_correction``; see the module).
    edge_angle_deg : float
        degrees: the fitted edge's angle from the vertical, positive when the edge moves to
        larger columns down the rows (of the transposed image for a near-horizontal edge).
    pitch_um : float
        um: the pixel pitch.
    lsf : ndarray
        the windowed LSF, one value a bin, whose transform :meth:`mtf_at` evaluates.
    bin_width_mm : float
        mm: the bins' width along the normal, pitch / oversampling.
    bin_correction : bool
        whether sinc(f D) is divided out.
    transposed : bool
        whether the edge was near-horizontal and the image measured transposed.
    """

    frequency_cyc_per_mm: np.ndarray
    mtf: np.ndarray
    edge_angle_deg: float
    pitch_um: float
    lsf: np.ndarray = field(repr=False)
    bin_width_mm: float = field(repr=False)
    bin_correction: bool = field(repr=False, default=False)
    transposed: bool = False

    def mtf_at(self, frequency_cyc_per_mm) -> np.ndarray:
        """1: the MTF, corrected as :attr:`mtf` is, at any frequencies (cycles/mm,
        array_like), from the windowed LSF's transform evaluated directly (not interpolated on
        the grid)."""
        f = as_float_array("frequency_cyc_per_mm", frequency_cyc_per_mm)
        x = np.arange(self.lsf.size) * self.bin_width_mm
        flat = f.reshape(-1)
        transform = np.empty(flat.size, dtype=complex)
        step = max(1, _DTFT_TERMS // self.lsf.size)
        for start in range(0, flat.size, step):
            phase = np.exp(-2j * np.pi * np.multiply.outer(flat[start:start + step], x))
            transform[start:start + step] = phase @ self.lsf
        magnitude = np.abs(transform).reshape(f.shape) / abs(self.lsf.sum())
        return magnitude * _correction(f, self.bin_width_mm, self.bin_correction)

    @property
    def mtf50_cyc_per_mm(self) -> float:
        """cycles/mm: where the MTF first falls to 0.5 (NaN if it never does)."""
        return self.crossing(0.5)

    def crossing(self, level=0.5) -> float:
        """cycles/mm: the first frequency where the MTF falls to ``level`` (1, in (0, 1)),
        bracketed on the grid and bisected on :meth:`mtf_at`; NaN if it never does within
        :attr:`frequency_cyc_per_mm`."""
        level = float(level)
        if not 0.0 < level < 1.0:
            raise ValueError(f"level must be in (0, 1), got {level!r}")
        below = np.flatnonzero(self.mtf <= level)
        if below.size == 0:
            return math.nan
        hi = float(self.frequency_cyc_per_mm[below[0]])
        lo = float(self.frequency_cyc_per_mm[below[0] - 1])
        for _ in range(_BISECTIONS):
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            if self.mtf_at(mid) > level:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)


def esfr(image, pitch_um, *, roi=None, oversampling=4, window="hamming",
         bin_correction=False) -> EdgeSFR:
    """The ISO 12233:2017 e-SFR of a slanted edge (see the module for the steps).

    Parameters
    ----------
    image : array_like
        the signal in linear units (e.g. electrons), 2-D, real and finite: a straight edge
        1 to 30 degrees from the vertical (the signal changes along the rows) or from the
        horizontal. A near-horizontal edge (summed absolute differences down the columns
        larger than along the rows) is measured on the transposed image, and the result says
        so (``transposed``). At least 16 rows and 16 columns (after ``roi``).
    pitch_um : float
        um: the pixel pitch, > 0.
    roi : (row0, row1, col0, col1), optional
        pixel indices: the crop image[row0:row1, col0:col1].
    oversampling : int
        bins a pixel along the normal, >= 1 (4, the standard's).
    window : "hamming" or None
        the window on the LSF: the standard's Hamming centred on its centroid, or none.
    bin_correction : bool
        False (the standard's e-SFR, a lab's); True: also divide out the bins' average,
        sinc(f D) (beyond the standard, the "e-SFR with bin-width correction"; see the
        module).

    Raises
    ------
    TypeError, ValueError
        naming the argument and its value; a ValueError naming the image when no edge is
        found (a row whose signal does not change, or rows that change in opposite
        directions), when its angle is outside 1 to 30 degrees, or when the rows share fewer
        than 4 pixels along the normal.
    """
    data = image_in_roi(image, roi, MIN_SIDE_PIXELS)
    pitch = _pitch(pitch_um)
    bins_a_pixel = integer("oversampling", oversampling)
    if bins_a_pixel < 1:
        raise ValueError(f"oversampling must be an integer >= 1, got {bins_a_pixel}")
    if not (window is None or (isinstance(window, str) and window == "hamming")):
        raise ValueError(f"window must be 'hamming' or None, got {short(window)}")
    if not isinstance(bin_correction, (bool, np.bool_)):
        raise TypeError(f"bin_correction must be True or False, got {short(bin_correction)}")

    transposed = bool(_is_horizontal(data))
    if transposed:
        data = data.T
    slope, offset = _edge_line(data)
    angle_deg = math.degrees(math.atan(slope))
    low, high = ANGLE_RANGE_DEG
    if not low <= abs(angle_deg) <= high:
        raise ValueError(f"image: the edge is {angle_deg:.2f} degrees from the "
                         f"{'horizontal' if transposed else 'vertical'}; the e-SFR needs "
                         f"{low:g} to {high:g} degrees (fewer phases below, no near-"
                         f"{'horizontal' if transposed else 'vertical'} edge above)")
    esf = _binned_esf(data, slope, offset, bins_a_pixel)
    lsf = _lsf(esf, window)
    bin_mm = pitch * 1e-3 / bins_a_pixel
    spectrum = np.abs(np.fft.rfft(lsf)) / abs(lsf.sum())
    frequency = np.fft.rfftfreq(lsf.size, d=bin_mm)
    return EdgeSFR(frequency_cyc_per_mm=frequency,
                   mtf=spectrum * _correction(frequency, bin_mm, bool(bin_correction)),
                   edge_angle_deg=angle_deg, pitch_um=pitch, lsf=lsf, bin_width_mm=bin_mm,
                   bin_correction=bool(bin_correction), transposed=transposed)


def mtf50(image, pitch_um, **kwargs) -> float:
    """cycles/mm: the e-SFR's MTF50, ``esfr(image, pitch_um, **kwargs).mtf50_cyc_per_mm``."""
    return esfr(image, pitch_um, **kwargs).mtf50_cyc_per_mm


def image_in_roi(image, roi, min_side: int) -> np.ndarray:
    """``image`` as a float64 2-D array cropped to ``roi``, or a TypeError/ValueError naming
    the argument: real, finite, and at least ``min_side`` rows and columns after the crop."""
    data = as_float_array("image", image)
    if data.ndim != 2:
        raise ValueError(f"image must be 2-D, got {data.ndim} dimension(s), shape {data.shape}")
    if roi is not None:
        data = data[_roi_slices(roi, data.shape)]
    if min(data.shape) < min_side:
        raise ValueError(f"image must have at least {min_side} rows and {min_side} columns"
                         f"{' in its roi' if roi is not None else ''}, got {data.shape}")
    if not np.isfinite(data).all():
        raise ValueError(f"image holds {np.count_nonzero(~np.isfinite(data))} NaN or "
                         "infinite value(s); pass finite values (or a roi that avoids them)")
    return data


def _roi_slices(roi, shape) -> tuple:
    """(rows, columns) slices of roi = (row0, row1, col0, col1), checked against ``shape``."""
    try:
        values = tuple(roi)
    except TypeError:
        raise TypeError(f"roi must be (row0, row1, col0, col1), got {short(roi)}") from None
    if len(values) != 4:
        raise ValueError(f"roi must be (row0, row1, col0, col1), got {short(roi)}")
    row0, row1, col0, col1 = (integer("roi", v) for v in values)
    rows, cols = shape
    if not (0 <= row0 < row1 <= rows and 0 <= col0 < col1 <= cols):
        raise ValueError(f"roi={short(roi)} must satisfy 0 <= row0 < row1 <= {rows} and "
                         f"0 <= col0 < col1 <= {cols} (the image's shape {shape})")
    return slice(row0, row1), slice(col0, col1)


def _pitch(pitch_um) -> float:
    """um: ``pitch_um`` checked, a finite number > 0."""
    if isinstance(pitch_um, (bool, np.bool_, str, bytes)) or np.ndim(pitch_um) != 0:
        raise TypeError(f"pitch_um must be a number, got {short(pitch_um)}")
    try:
        pitch = float(pitch_um)
    except (TypeError, ValueError):
        raise TypeError(f"pitch_um must be a number, got {short(pitch_um)}") from None
    if not (math.isfinite(pitch) and pitch > 0.0):
        raise ValueError(f"pitch_um must be finite and > 0, got {pitch_um!r}")
    return pitch


def _is_horizontal(data: np.ndarray) -> bool:
    """Whether the signal changes more from the first row to the last, summed over the
    columns, than from the first column to the last, summed over the rows. The ends' differences
    count the edge's step once a line, and a pixel's noise only at the ends: summing every
    neighbour's absolute difference instead would count the noise of every pixel, and noise
    of a few percent would outweigh the edge."""
    down = np.abs(data[-1, :] - data[0, :]).sum() / data.shape[1]
    along = np.abs(data[:, -1] - data[:, 0]).sum() / data.shape[0]
    return down > along


def _centroids(derivative: np.ndarray) -> np.ndarray:
    """Each row's centroid of ``derivative`` (samples at x = column + 0.5), in columns."""
    x = np.arange(derivative.shape[1]) + 0.5
    return (derivative @ x) / derivative.sum(axis=1)


def _edge_line(data: np.ndarray) -> tuple:
    """(slope, offset) of x_edge(row) = offset + slope row: the least-squares line through the
    rows' centroids of the derivative, each row's derivative Hamming-windowed about a first
    line. The first line goes through each row's crossing of its mid-level (the row smoothed
    over 9 pixels), which noise far from the edge cannot move as it moves an unwindowed
    centroid; the window's half-width is twice the edge's 10-90% rise, at least 8 pixels
    (the whole row at most), and the fit is made twice."""
    derivative = 0.5 * np.diff(data, axis=1)
    step = derivative.sum(axis=1)
    contrast = np.abs(data).max()
    if not (np.abs(step) > 1e-9 * contrast).all() or contrast == 0.0:
        raise ValueError("image: no edge found (a row's signal does not change from its first "
                         "column to its last); the e-SFR needs a slanted edge across every row")
    if (np.sign(step) != np.sign(step.mean())).any():
        raise ValueError("image: no single edge found (the rows' signals change in opposite "
                         "directions); pass a roi around one edge")
    sign = np.sign(step.mean())
    derivative *= sign
    rows = np.arange(data.shape[0])
    cols = derivative.shape[1]
    slope, offset = np.polyfit(rows, _mid_crossings(data * sign), 1)
    x = np.arange(cols) + 0.5
    for _ in range(2):
        half = min(cols / 2.0, max(8.0, 2.0 * _rise_px(data * sign, slope, offset)))
        distance = x[None, :] - (offset + slope * rows)[:, None]
        inside = np.abs(distance) < half
        weights = np.where(inside, 0.54 + 0.46 * np.cos(np.pi * distance / half), 0.0)
        centroids = _centroids(derivative * weights)
        if not np.isfinite(centroids).all():
            raise ValueError("image: no edge found (a row's windowed derivative sums to 0)")
        slope, offset = np.polyfit(rows, centroids, 1)
    return float(slope), float(offset)


def _mid_crossings(data: np.ndarray) -> np.ndarray:
    """Columns: where each row, smoothed over 9 pixels, first rises through the level midway
    between its first and last tenths' means (the signal rising along the row)."""
    cols = data.shape[1]
    k = min(9, cols)
    kernel = np.ones(k) / k
    smooth = np.array([np.convolve(row, kernel, mode="valid") for row in data])
    tenth = max(1, cols // 10)
    mid = 0.5 * (data[:, :tenth].mean(axis=1) + data[:, -tenth:].mean(axis=1))
    above = smooth >= mid[:, None]
    first = np.argmax(above, axis=1)
    first = np.maximum(first, 1)
    lo = smooth[np.arange(len(first)), first - 1]
    hi = smooth[np.arange(len(first)), first]
    frac = np.where(hi > lo, (mid - lo) / np.where(hi > lo, hi - lo, 1.0), 0.5)
    return first - 1 + np.clip(frac, 0.0, 1.0) + (k - 1) / 2.0


def _rise_px(data: np.ndarray, slope: float, offset: float) -> float:
    """Pixels: the 10-90% rise of the ESF binned a pixel wide along the rows about the line."""
    rows, cols = data.shape
    distance = np.arange(cols)[None, :] - (offset + slope * np.arange(rows))[:, None]
    index = np.floor(distance).astype(np.int64)
    index -= index.min()
    counts = np.bincount(index.ravel())
    esf = np.bincount(index.ravel(), weights=data.ravel()) / np.maximum(counts, 1)
    esf = esf[counts >= max(1, rows // 2)]
    if esf.size < 3:
        return cols / 4.0
    lo, hi = esf[: max(1, esf.size // 10)].mean(), esf[-max(1, esf.size // 10):].mean()
    level = (esf - lo) / (hi - lo) if hi != lo else np.zeros_like(esf)
    above10 = np.flatnonzero(level >= 0.1)
    above90 = np.flatnonzero(level >= 0.9)
    if above10.size == 0 or above90.size == 0:
        return cols / 4.0
    return float(max(1, above90[0] - above10[0]))


def _binned_esf(data: np.ndarray, slope: float, offset: float, bins_a_pixel: int) -> np.ndarray:
    """The ESF along the normal, averaged in bins of 1 / bins_a_pixel pixels over the rows of a
    whole number of phase cycles (all rows when they hold less than one), where every row
    has samples; empty bins interpolated."""
    rows, cols = data.shape
    cycles = math.floor(rows * abs(slope))
    used = min(rows, round(cycles / abs(slope))) if cycles >= 1 else rows
    y = np.arange(used)
    cos_angle = 1.0 / math.sqrt(1.0 + slope * slope)
    edge = offset + slope * y
    distance = (np.arange(cols)[None, :] - edge[:, None]) * cos_angle
    start = distance[:, 0].max()
    stop = distance[:, -1].min()
    first = math.ceil(start * bins_a_pixel)
    count = math.floor(stop * bins_a_pixel) - first
    if stop - start < MIN_SHARED_PIXELS:
        raise ValueError(f"image: the rows share only {stop - start:.3g} pixels along the edge "
                         f"normal, fewer than {MIN_SHARED_PIXELS}; pass more columns or a "
                         "smaller edge angle")
    index = np.floor(distance * bins_a_pixel).astype(np.int64) - first
    inside = (index >= 0) & (index < count)
    index, values = index[inside], data[:used][inside]
    sums = np.bincount(index, weights=values, minlength=count)
    counts = np.bincount(index, minlength=count)
    filled = counts > 0
    centres = np.arange(count)
    return np.interp(centres, centres[filled], sums[filled] / counts[filled])


def _lsf(esf: np.ndarray, window) -> np.ndarray:
    """The LSF, the ESF's central difference, times a Hamming window centred on its centroid
    and reaching 0.08 at the farther end (``window="hamming"``), or as it is (None)."""
    lsf = np.zeros_like(esf)
    lsf[1:-1] = 0.5 * (esf[2:] - esf[:-2])
    lsf[0], lsf[-1] = lsf[1], lsf[-2]
    if window is None:
        return lsf
    k = np.arange(lsf.size)
    centre = (k @ lsf) / lsf.sum()
    half_width = max(centre, lsf.size - 1 - centre)
    return lsf * (0.54 + 0.46 * np.cos(np.pi * (k - centre) / half_width))


def _correction(frequency, bin_mm: float, bin_correction: bool) -> np.ndarray:
    """The factor that divides out the central difference's transfer sin(2 pi f D)/(2 pi f D)
    and, with ``bin_correction``, the bin's sinc(f D): 1 / their product, capped at
    DERIVATIVE_CORRECTION_CAP (and the cap where the product is 0 or negative)."""
    f_bin = np.asarray(frequency) * bin_mm
    transfer = np.sinc(2.0 * f_bin) * (np.sinc(f_bin) if bin_correction else 1.0)
    capped = transfer <= 1.0 / DERIVATIVE_CORRECTION_CAP
    return np.where(capped, DERIVATIVE_CORRECTION_CAP, 1.0 / np.where(capped, 1.0, transfer))
