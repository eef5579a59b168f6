"""Tabulated MTFs: a lens's MTF from its data sheet (``lens_mtf=``) and a demosaicker's
luminance MTF, each a falling curve given at a few frequencies and interpolated monotonically
(docs/model.md, "Tabulated MTFs").

The interpolant is the piecewise cubic Hermite of Fritsch and Carlson with the knot slopes of
Fritsch and Butland (F. N. Fritsch and R. E. Carlson, "Monotone piecewise cubic interpolation",
SIAM J. Numer. Anal. 17 (1980) 238-246; F. N. Fritsch and J. Butland, "A method for constructing
local monotone piecewise cubic interpolants", SIAM J. Sci. Stat. Comput. 5 (1984) 300-304), the
scheme of SciPy's ``PchipInterpolator``: on data that never rises it never rises, and it passes
through every point. Each segment k is stored as the cubic
y_k + d_k s + c2_k s^2 + c3_k s^3 in s = f - f_k, the form the core evaluates too, so that both
backends compute the same polynomial. Past the last frequency the table holds its last value;
what a point does there is the caller's (an f50 beyond a lens table is a status, not a number).
"""

from __future__ import annotations

from dataclasses import dataclass

import warnings

import numpy as np

from ._validation import short

__all__ = ["MtfTable", "mtf_table", "lens_tables_of", "check_lens_tables",
           "DIFFRACTION_TOLERANCE", "pchip_slopes", "mtf_tabulated"]

#: 1 (absolute MTF): how far a lens table may lie above the diffraction MTF before it is
#: refused. A lens bench's MTF carries an error of about 0.01-0.02 (its calibration, the
#: target's and the relay's residual MTF, noise), and a sharp lens's measured MTF lies on
#: diffraction within it; a table read in lines/mm as cycles/mm lies far above (twice the
#: frequency for each value).
DIFFRACTION_TOLERANCE = 0.02


def pchip_slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The knot slopes dy/dx of the monotone interpolant: 0 where the data's secant slopes
    change sign or either is 0; else their weighted harmonic mean (Fritsch-Butland); at the two
    ends the three-point formula, set to 0 if its sign differs from the end segment's and
    limited to three times that segment's slope where the secants change sign. Two points: the
    straight line."""
    h = np.diff(x)
    delta = np.diff(y) / h
    if x.size == 2:
        return np.array([delta[0], delta[0]])
    d = np.zeros_like(y)
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    same = (delta[:-1] * delta[1:]) > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        harmonic = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    d[1:-1] = np.where(same, harmonic, 0.0)
    d[0] = _end_slope(h[0], h[1], delta[0], delta[1])
    d[-1] = _end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _end_slope(h0, h1, delta0, delta1) -> float:
    d = ((2.0 * h0 + h1) * delta0 - h0 * delta1) / (h0 + h1)
    if np.sign(d) != np.sign(delta0):
        return 0.0
    if np.sign(delta0) != np.sign(delta1) and abs(d) > abs(3.0 * delta0):
        return 3.0 * delta0
    return float(d)


@dataclass(frozen=True)
class MtfTable:
    """A checked, falling MTF table and its interpolant's segments.

    ``frequencies``: the knots f_0 = 0 < f_1 < ... (in the table's own unit: cycles/mm for a
    lens, cycles/pixel for a demosaicker); ``values``: the MTF there, 1 at 0 and never rising;
    ``coefficients``: shape (knots - 1, 4), segment k's (y_k, d_k, c2_k, c3_k).
    """

    frequencies: np.ndarray
    values: np.ndarray
    coefficients: np.ndarray

    @property
    def last_frequency(self) -> float:
        return float(self.frequencies[-1])

    def __call__(self, f):
        """The interpolated MTF at ``f`` (held at the last value past the last frequency)."""
        return mtf_tabulated(f, self)[0]


def _real_array(name: str, part: str, values) -> np.ndarray:
    """``values`` as a float64 array when they are real numbers (integers or floats); a
    ValueError naming the table, the part and the values for anything else (strings, which
    NumPy would read as the numbers they spell, booleans, objects)."""
    try:
        array = np.asarray(values)
    except (TypeError, ValueError):
        array = None
    if array is None or array.dtype.kind not in "iuf":
        raise ValueError(f"{name}'s {part} must be real numbers, got {short(values)}")
    return array.astype(np.float64, copy=False)


def mtf_table(name: str, table) -> MtfTable:
    """``table`` = (frequencies, mtf), two 1-D arrays of the same length, checked and made an
    :class:`MtfTable`; a ValueError of one line naming ``name`` for anything else: values that
    are not real numbers (strings, booleans), fewer than two points, a NaN or infinite value, a negative or unsorted (or repeated) frequency, an MTF
    outside [0, 1] or one that rises, a value other than 1 at frequency 0. A table that starts
    above 0 gets the point (0, 1): every MTF is 1 at 0."""
    if isinstance(table, MtfTable):
        return table
    try:
        frequencies, values = table
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a pair (frequencies, mtf) of 1-D arrays, got "
                         f"{short(table)}") from None
    f = _real_array(name, "frequencies", frequencies)
    m = _real_array(name, "mtf", values)
    if f.ndim != 1 or m.ndim != 1 or f.size != m.size:
        raise ValueError(f"{name}: frequencies and mtf must be 1-D arrays of one length, got "
                         f"shapes {f.shape} and {m.shape}")
    if f.size < 2:
        raise ValueError(f"{name} has {f.size} point(s); a table needs at least 2")
    bad = ~np.isfinite(f) | ~np.isfinite(m)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name} holds a NaN or infinite value at index {i} "
                         f"(frequency {float(f[i])!r}, mtf {float(m[i])!r})")
    if f[0] < 0.0:
        raise ValueError(f"{name}'s first frequency is {float(f[0])!r}; frequencies are >= 0")
    step = np.diff(f)
    if np.any(step <= 0.0):
        i = int(np.flatnonzero(step <= 0.0)[0])
        raise ValueError(f"{name}'s frequencies must increase strictly: {float(f[i])!r} at "
                         f"index {i} is followed by {float(f[i + 1])!r}")
    if np.any((m < 0.0) | (m > 1.0)):
        i = int(np.flatnonzero((m < 0.0) | (m > 1.0))[0])
        raise ValueError(f"{name}'s mtf {float(m[i])!r} at index {i} is outside [0, 1]")
    rise = np.diff(m)
    if np.any(rise > 0.0):
        i = int(np.flatnonzero(rise > 0.0)[0])
        raise ValueError(f"{name} rises from {float(m[i])!r} to {float(m[i + 1])!r} between "
                         f"frequencies {float(f[i])!r} and {float(f[i + 1])!r}; an MTF table "
                         "must never rise")
    if f[0] == 0.0 and m[0] != 1.0:
        raise ValueError(f"{name}'s mtf at frequency 0 is {float(m[0])!r}; every MTF is 1 there "
                         "(divide the table by it)")
    if f[0] > 0.0:
        f, m = np.concatenate(([0.0], f)), np.concatenate(([1.0], m))
    d = pchip_slopes(f, m)
    h = np.diff(f)
    delta = np.diff(m) / h
    c2 = (3.0 * delta - 2.0 * d[:-1] - d[1:]) / h
    c3 = (d[:-1] + d[1:] - 2.0 * delta) / (h * h)
    coefficients = np.stack([m[:-1], d[:-1], c2, c3], axis=1)
    for array in (f, m, coefficients):
        array.setflags(write=False)
    return MtfTable(f, m, coefficients)


def lens_tables_of(lens_mtf, wavefront_rms_waves=0.0) -> tuple:
    """``lens_mtf`` (one pair (frequencies_cyc_per_mm, mtf), or a list of them) as a tuple of
    checked :class:`MtfTable`, each named in errors as ``lens_mtf`` or ``lens_mtf[i]``. A
    ValueError for a wavefront error other than 0 with it: a lens's table has its aberrations.
    """
    w = np.asarray(wavefront_rms_waves, dtype=np.float64)
    if np.any(w != 0.0):
        raise ValueError("give lens_mtf or wavefront_rms_waves, not both: a lens's MTF table "
                         f"includes its aberrations (wavefront_rms_waves={short(w)})")
    if isinstance(lens_mtf, MtfTable) or _is_pair(lens_mtf):
        return (mtf_table("lens_mtf", lens_mtf),)
    try:
        tables = list(lens_mtf)
    except TypeError:
        raise ValueError("lens_mtf must be a pair (frequencies_cyc_per_mm, mtf) of 1-D arrays "
                         f"or a list of them, got {short(lens_mtf)}") from None
    if not tables:
        raise ValueError("lens_mtf is an empty list; give at least one table")
    return tuple(mtf_table(f"lens_mtf[{i}]", t) for i, t in enumerate(tables))


def check_lens_tables(tables, f_number, wavelength_nm, pixel_pitch_um, lens) -> None:
    """Each lens table against the points that use it (``lens`` == its index; a point whose
    f-number, wavelength or pitch is not finite and positive is left out: it is INVALID).

    A ValueError of one line when a table's MTF at one of its frequencies lies above the
    aberration-free diffraction MTF by more than :data:`DIFFRACTION_TOLERANCE`: no lens can
    have it. The diffraction limit is the most permissive among the points: the smallest
    product of f-number and wavelength (nm; ``wavelength_nm`` each point's, or a spectrum's
    shortest). A UserWarning when a table's last frequency is below 1/100 of the pixels'
    Nyquist frequency 1/(2p) (the smallest pitch ``pixel_pitch_um`` among its points, before
    binning): its frequencies look like cycles/pixel. The arrays broadcast against each other.
    """
    f_n, wavelength, pitch, index = (np.asarray(a, dtype=np.float64) for a in
                                     (f_number, wavelength_nm, pixel_pitch_um, lens))
    if index.ndim == 0 and all(_positive_and_finite(a) for a in (f_n, wavelength, pitch)):
        # every point valid and using one table: its limits are the arrays' own least values,
        # found without broadcasting them against each other
        i = float(index)
        if i.is_integer() and 0 <= i < len(tables):
            product = f_n * wavelength
            at = int(np.argmin(product))
            n_min = float(np.broadcast_to(f_n, product.shape).reshape(-1)[at])
            wavelength_min = float(np.broadcast_to(wavelength, product.shape).reshape(-1)[at])
            _check_table(tables, int(i), n_min, wavelength_min, float(np.min(pitch)))
        return
    n, wavelength, pitch, index = np.broadcast_arrays(f_n, wavelength, pitch, index)
    product = n * wavelength
    valid = ((product > 0.0) & np.isfinite(product) & (pitch > 0.0) & np.isfinite(pitch))
    for i in range(len(tables)):
        used = valid & (index == i)
        if not used.any():
            continue
        at = np.flatnonzero(used.reshape(-1))[np.argmin(product[used])]
        _check_table(tables, i, float(n.reshape(-1)[at]), float(wavelength.reshape(-1)[at]),
                     float(np.min(pitch[used])))


def _positive_and_finite(values: np.ndarray) -> bool:
    """Whether every value is finite and > 0 (two reductions; False for NaN)."""
    return bool(np.min(values) > 0.0) and bool(np.isfinite(np.max(values)))


def _check_table(tables, i: int, n_min: float, wavelength_min: float, pitch_min_um: float):
    """check_lens_tables for table ``i`` at the least f-number times wavelength among its
    points (``n_min`` at ``wavelength_min`` nm) and their least pitch (um)."""
    from .reference.mtf import mtf_diffraction  # the reference imports this module

    table = tables[i]
    name = "lens_mtf" if len(tables) == 1 else f"lens_mtf[{i}]"
    limit = mtf_diffraction(table.frequencies, wavelength_min, n_min)
    excess = table.values - limit
    k = int(np.argmax(excess))
    if excess[k] > DIFFRACTION_TOLERANCE:
        raise ValueError(
            f"{name} lies above diffraction: its MTF at {table.frequencies[k]:.6g} "
            f"cycles/mm is {table.values[k]:.4g}, the diffraction MTF there at f/"
            f"{n_min:.4g} and {wavelength_min:.4g} nm (the smallest f-number times "
            f"wavelength among its points) is {limit[k]:.4g}, and no lens exceeds it by "
            f"more than {DIFFRACTION_TOLERANCE:g}: are its frequencies in lines/mm? they "
            "must be cycles/mm (line pairs/mm)")
    nyquist = 500.0 / pitch_min_um  # 1/(2p), p in mm
    if table.last_frequency < nyquist / 100.0:
        warnings.warn(
            f"{name} ends at {table.last_frequency:.6g} cycles/mm, below 1/100 of the "
            f"pixels' Nyquist frequency {nyquist:.6g} cycles/mm: are its frequencies in "
            "cycles/pixel? they must be cycles/mm", UserWarning, stacklevel=5)


def _is_pair(value) -> bool:
    """Whether ``value`` is one table, a pair whose first item is a 1-D array of numbers
    (a list of tables holds pairs there, not numbers)."""
    try:
        first = value[0]
        return len(value) == 2 and np.asarray(first, dtype=np.float64).ndim == 1
    except (TypeError, ValueError, IndexError, KeyError):
        return False


def mtf_tabulated(f, table: MtfTable):
    """(T, T', T''): the table's interpolant and its first two derivatives in f at ``f``, any
    shape. Segment k = the last knot <= f; s = f - f_k; T = y + s (d + s (c2 + s c3)),
    T' = d + s (2 c2 + 3 c3 s), T'' = 2 c2 + 6 c3 s. Past the last frequency: the last value,
    slopes 0."""
    f = np.asarray(f, dtype=np.float64)
    knots = table.frequencies
    k = np.clip(np.searchsorted(knots, f, side="right") - 1, 0, knots.size - 2)
    y, d, c2, c3 = (table.coefficients[k, j] for j in range(4))
    s = f - knots[k]
    value = y + s * (d + s * (c2 + s * c3))
    slope = d + s * (2.0 * c2 + 3.0 * c3 * s)
    curvature = 2.0 * c2 + 6.0 * c3 * s
    past = f > table.last_frequency
    return (np.where(past, table.values[-1], value), np.where(past, 0.0, slope),
            np.where(past, 0.0, curvature))
