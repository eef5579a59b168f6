"""Spectra: from lux to photo-electrons, and wavelength weights for diffraction (docs/model.md,
"Photometry: from lux to electrons").

The sensor counts electrons, the scene is given in lux. The conversion factor is

    K = ∫ QE(λ) · E₁(λ) · λ/(h·c) dλ        [e⁻ / (lux·s·m²)]

with E₁(λ) = S(λ) / (683 lm/W · ∫ S(λ)·V(λ) dλ) the illuminant's spectral irradiance scaled to
1 lux and V the CIE 1924 photopic luminosity function. Both integrals use the same dλ (nanometres
on the sample grid), so that unit cancels and K comes out in e⁻/(lux·s·m²); λ inside λ/(h·c) is
in metres.

The CIE tables come from colour-science, which is imported only inside the functions that read
them: importing this module needs NumPy alone. Tables are linearly interpolated (``numpy.interp``)
onto the sample grid, by default 380..780 nm in 1 nm steps, and integrated with the trapezoid rule.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = [
    "DEFAULT_ELECTRONS_PER_LUX_S_M2",
    "GRID_NM",
    "Spectrum",
    "default_qe",
    "illuminant",
    "photopic_luminosity",
    "electrons_per_lux_s_m2",
    "diffraction_spectrum",
]

PLANCK_J_S = 6.62607015e-34
"""J·s, the Planck constant h (exact, SI 2019)."""

SPEED_OF_LIGHT_M_S = 299792458.0
"""m/s, the speed of light in vacuum c (exact, SI 2019)."""

LUMINOUS_EFFICACY_LM_PER_W = 683.0
"""lm/W, the maximum luminous efficacy K_m of photopic vision."""

GRID_NM = np.arange(380.0, 781.0, 1.0)
"""nm, the default sample grid: 380..780 nm in 1 nm steps (read-only)."""
GRID_NM.flags.writeable = False

DEFAULT_ELECTRONS_PER_LUX_S_M2 = 2557705539053827.5
"""e⁻/(lux·s·m²), K for the defaults of docs/model.md, "Photometry: from lux to electrons" (the
golden reference value).

CIE illuminant D50, rectangle QE 0.7 on [480, 580] nm with the band integrated exactly (half
weight at the two edge samples), CIE tables from colour-science linearly interpolated to 1 nm over
380..780 nm, trapezoid rule, exact SI 2019 h and c. Computed with mpmath; the float64
:func:`electrons_per_lux_s_m2` agrees to about 1e-15 relative.
"""

QE_PEAK = 0.7
"""Dimensionless, the default QE inside its band (the paper's Table 1)."""

QE_BAND_NM = (480.0, 580.0)
"""nm, the default QE band (the paper's "half-width sensitivity 480-580 nm")."""

_PHOTOPIC_NAME = "CIE 1924 Photopic Standard Observer"


@dataclass(frozen=True, eq=False)
class Spectrum:
    """Wavelength samples with weights summing to 1, e.g. for polychromatic diffraction.

    Parameters
    ----------
    wavelengths_nm : array_like
        nm, 1-D, finite and > 0.
    weights : array_like
        Dimensionless, 1-D, same length as ``wavelengths_nm``, finite, >= 0, with a positive sum.
        Stored normalised to sum 1.

    Raises
    ------
    ValueError
        Naming the field and the bad value.

    Notes
    -----
    Both arrays are stored as read-only float64 copies.
    """

    wavelengths_nm: np.ndarray
    weights: np.ndarray

    def __post_init__(self):
        wavelengths = _as_1d_float(self.wavelengths_nm, "Spectrum.wavelengths_nm")
        weights = _as_1d_float(self.weights, "Spectrum.weights")
        if wavelengths.size == 0:
            raise ValueError("Spectrum.wavelengths_nm: must not be empty")
        if weights.size != wavelengths.size:
            raise ValueError(f"Spectrum.weights: length {weights.size} differs from "
                             f"wavelengths_nm length {wavelengths.size}")
        _require_all(np.isfinite(wavelengths) & (wavelengths > 0), wavelengths,
                     "Spectrum.wavelengths_nm", "finite and > 0 nm")
        _require_all(np.isfinite(weights) & (weights >= 0), weights,
                     "Spectrum.weights", "finite and >= 0")
        total = weights.sum()
        if not total > 0:
            raise ValueError(f"Spectrum.weights: must have a positive sum, got {total!r}")
        weights = weights / total
        wavelengths.flags.writeable = False
        weights.flags.writeable = False
        object.__setattr__(self, "wavelengths_nm", wavelengths)
        object.__setattr__(self, "weights", weights)

    @classmethod
    def monochromatic(cls, wavelength_nm):
        """One wavelength with weight 1.

        Parameters
        ----------
        wavelength_nm : float
            nm, finite and > 0.

        Returns
        -------
        Spectrum
        """
        return cls(np.array([wavelength_nm], dtype=float), np.array([1.0]))


def default_qe(wavelengths_nm):
    """The default quantum efficiency: a rectangle of 0.7 on [480, 580] nm.

    Parameters
    ----------
    wavelengths_nm : array_like
        nm, sample wavelengths (the default grid is :data:`GRID_NM`).

    Returns
    -------
    ndarray
        Dimensionless: 0.7 strictly inside the band, 0.35 at exactly 480 and 580 nm, 0 outside.

    Notes
    -----
    The half weight at the two edge samples is what makes the trapezoid rule integrate the
    rectangle exactly over [480, 580] nm on a uniform grid that has samples at the edges (such as
    the 1 nm grid): the trapezoid over [λ−Δ, λ] and [λ, λ+Δ] around an edge sample then adds up to
    0.7·Δ, the rectangle's area over one step. Counting the edges at full weight would widen the
    band by one step (101 nm on the 1 nm grid) and add about 1% to K.
    """
    wavelengths = np.asarray(wavelengths_nm, dtype=float)
    lo, hi = QE_BAND_NM
    qe = np.where((wavelengths > lo) & (wavelengths < hi), QE_PEAK, 0.0)
    return np.where((wavelengths == lo) | (wavelengths == hi), QE_PEAK / 2, qe)


def illuminant(name="D50"):
    """A CIE illuminant's relative spectral power on the default grid.

    Parameters
    ----------
    name : str
        Any key of ``colour.SDS_ILLUMINANTS`` whose table covers 380..780 nm (default "D50").

    Returns
    -------
    wavelengths_nm : ndarray
        nm, :data:`GRID_NM` (380..780 nm, 1 nm steps).
    values : ndarray
        Relative spectral power (arbitrary scale), linearly interpolated from the table.

    Raises
    ------
    ValueError
        For an unknown name, or a table that does not cover 380..780 nm.
    """
    table = _illuminant_table(name, "name")
    return GRID_NM.copy(), _interpolate(table, GRID_NM, f"illuminant {name!r}", "name")


def photopic_luminosity():
    """The CIE 1924 photopic luminosity function V(λ) on the default grid.

    Returns
    -------
    ndarray
        Dimensionless (peak 1 at 555 nm), on :data:`GRID_NM`, linearly interpolated from the
        1 nm table of colour-science.
    """
    return _interpolate(_photopic_table(), GRID_NM, "photopic V", "wavelengths_nm")


def electrons_per_lux_s_m2(illuminant="D50", qe=None, wavelengths_nm=None):
    """K, the photo-electrons per lux·second per m² of sensor (docs/model.md, "Photometry: from
    lux to electrons").

    Parameters
    ----------
    illuminant : str or array_like
        Either a key of ``colour.SDS_ILLUMINANTS`` (default "D50"), interpolated linearly onto the
        grid, or the relative spectral power (arbitrary scale, >= 0) sampled on
        ``wavelengths_nm``.
    qe : None, array_like or callable
        Dimensionless quantum efficiency in [0, 1]: None for :func:`default_qe`, values on the
        grid, or a function of wavelength in nm returning them.
    wavelengths_nm : array_like, optional
        nm, the sample grid: 1-D, strictly increasing, within 360..830 nm (the V table). Required
        when ``illuminant`` is an array; default :data:`GRID_NM`. Need not be uniform.

    Returns
    -------
    float
        e⁻/(lux·s·m²).

    Raises
    ------
    ValueError, TypeError
        Naming the offending argument.

    Notes
    -----
    Trapezoid rule on the grid; V is interpolated linearly onto it. Scaling the illuminant does
    not change K (E₁ is normalised to 1 lux); K is linear in QE.
    """
    grid, flux, qe_values = _sampled_spectra(illuminant, qe, wavelengths_nm)
    return float(np.trapezoid(qe_values * flux, grid))


def diffraction_spectrum(n_samples=16, illuminant="D50", qe=None, band_nm=None,
                         wavelengths_nm=None):
    """Wavelength samples weighted by the electrons they stand for, for polychromatic diffraction.

    Parameters
    ----------
    n_samples : int
        Count, >= 1: the number of wavelengths.
    illuminant, qe, wavelengths_nm
        As in :func:`electrons_per_lux_s_m2`.
    band_nm : tuple of float, optional
        nm, ``(lo, hi)`` with lo < hi inside the grid. Default: from the first to the last grid
        sample where QE > 0 (480..580 nm for the default QE).

    Returns
    -------
    Spectrum
        The midpoints of ``n_samples`` equal sub-bands of the band (n_samples=1 gives its
        centre, 530 nm by default), each weighted by the electrons collected in its sub-band.

    Notes
    -----
    The electrons in a sub-band are the integral of the piecewise-linear interpolant of
    QE·E₁·λ/(h·c) between the grid samples, the function the trapezoid rule integrates, so the
    sub-band electrons add up to :func:`electrons_per_lux_s_m2` (before normalisation): splitting
    the band loses no electrons. Electrons below the band are counted in the first sub-band and
    those above it in the last; with the default QE these are the half-steps the trapezoid rule
    puts next to the half-weight edge samples, which belong to the band's edges.
    """
    if isinstance(n_samples, bool) or not isinstance(n_samples, (int, np.integer)):
        raise TypeError(f"n_samples: must be an int, got {n_samples!r}")
    if n_samples < 1:
        raise ValueError(f"n_samples: must be >= 1, got {n_samples}")
    grid, flux, qe_values = _sampled_spectra(illuminant, qe, wavelengths_nm)
    electrons = qe_values * flux
    lo, hi = _band(band_nm, grid, qe_values)
    edges = np.linspace(lo, hi, n_samples + 1)
    midpoints = (edges[:-1] + edges[1:]) / 2
    edges[0], edges[-1] = grid[0], grid[-1]
    cumulative = _cumulative_linear_integral(grid, electrons, edges)
    return Spectrum(midpoints, np.diff(cumulative))


def _sampled_spectra(illuminant, qe, wavelengths_nm):
    """The grid, the photon flux per lux E₁·λ/(h·c) in (s·m²·nm)⁻¹, and QE, all validated."""
    if wavelengths_nm is None:
        if not isinstance(illuminant, str):
            raise ValueError("wavelengths_nm: required when illuminant is given as an array")
        grid = GRID_NM
    else:
        grid = _grid(wavelengths_nm)
    power = _illuminant_values(illuminant, grid)
    luminosity = _interpolate(_photopic_table(), grid, "photopic V", "wavelengths_nm")
    lux = LUMINOUS_EFFICACY_LM_PER_W * np.trapezoid(power * luminosity, grid)
    if not lux > 0:
        raise ValueError("illuminant: gives no light under the photopic V(λ) on this grid")
    irradiance_per_lux = power / lux
    flux = irradiance_per_lux * (grid * 1e-9) / (PLANCK_J_S * SPEED_OF_LIGHT_M_S)
    return grid, flux, _qe_values(qe, grid)


def _grid(wavelengths_nm):
    grid = _as_1d_float(wavelengths_nm, "wavelengths_nm")
    if grid.size < 2:
        raise ValueError(f"wavelengths_nm: needs at least 2 samples, got {grid.size}")
    _require_all(np.isfinite(grid), grid, "wavelengths_nm", "finite")
    steps = np.diff(grid)
    if not np.all(steps > 0):
        bad = int(np.argmin(steps > 0))
        raise ValueError(f"wavelengths_nm: must be strictly increasing, got {grid[bad]!r} "
                         f"then {grid[bad + 1]!r} at index {bad}")
    return grid


def _illuminant_values(illuminant, grid):
    if isinstance(illuminant, str):
        table = _illuminant_table(illuminant, "illuminant")
        return _interpolate(table, grid, f"illuminant {illuminant!r}", "illuminant")
    if callable(illuminant) or isinstance(illuminant, (bytes, dict)):
        raise TypeError(f"illuminant: must be a name or an array of spectral values, "
                        f"got {type(illuminant).__name__}")
    values = _on_grid(illuminant, grid, "illuminant")
    _require_all(values >= 0, values, "illuminant", ">= 0")
    return values


def _qe_values(qe, grid):
    if qe is None:
        return default_qe(grid)
    if isinstance(qe, (str, bytes, dict)):
        raise TypeError(f"qe: must be None, an array or a callable, got {type(qe).__name__}")
    values = _on_grid(qe(grid.copy()) if callable(qe) else qe, grid, "qe")
    _require_all((values >= 0) & (values <= 1), values, "qe",
                 "in [0, 1] (a fraction, not a percentage)")
    return values


def _on_grid(values, grid, argname):
    array = _as_1d_float(values, argname)
    if array.shape != grid.shape:
        raise ValueError(f"{argname}: has {array.size} samples, wavelengths_nm has {grid.size}")
    _require_all(np.isfinite(array), array, argname, "finite")
    return array


def _band(band_nm, grid, qe_values):
    if band_nm is None:
        inside = np.flatnonzero(qe_values > 0)
        if inside.size == 0:
            raise ValueError("qe: is zero everywhere, so there is no band to sample")
        return grid[inside[0]], grid[inside[-1]]
    try:
        lo, hi = (float(x) for x in band_nm)
    except (TypeError, ValueError):
        raise TypeError(f"band_nm: must be a pair (lo, hi) of numbers, got {band_nm!r}") from None
    if not (grid[0] <= lo < hi <= grid[-1]):
        raise ValueError(f"band_nm: must satisfy {grid[0]} <= lo < hi <= {grid[-1]} nm, "
                         f"got {band_nm!r}")
    return lo, hi


def _cumulative_linear_integral(grid, values, points):
    """∫ from grid[0] to each point of the piecewise-linear interpolant of ``values``.

    At the grid samples this is the cumulative trapezoid rule; in between, the exact integral of
    the linear piece (a quadratic in the distance from the previous sample).
    """
    steps = np.diff(grid)
    cumulative = np.concatenate([[0.0], np.cumsum(steps * (values[:-1] + values[1:]) / 2)])
    i = np.clip(np.searchsorted(grid, points, side="right") - 1, 0, grid.size - 2)
    t = points - grid[i]
    slope = (values[i + 1] - values[i]) / steps[i]
    return cumulative[i] + values[i] * t + slope * t * t / 2


def _interpolate(table, grid, what, argname):
    wavelengths, values = table
    if grid[0] < wavelengths[0] or grid[-1] > wavelengths[-1]:
        raise ValueError(f"{argname}: the {what} table covers {wavelengths[0]:g}.."
                         f"{wavelengths[-1]:g} nm, not the grid's {grid[0]:g}..{grid[-1]:g} nm")
    return np.interp(grid, wavelengths, values)


def _illuminant_table(name, argname):
    names = _illuminant_names()
    if name not in names:
        raise ValueError(f"{argname}: unknown illuminant {name!r}; expected a key of "
                         f"colour.SDS_ILLUMINANTS, such as 'D50', 'D65' or 'A'")
    return _load_table("illuminant", name)


@lru_cache(maxsize=1)
def _illuminant_names():
    return frozenset(_colour().SDS_ILLUMINANTS)


def _photopic_table():
    return _load_table("photopic", _PHOTOPIC_NAME)


@lru_cache(maxsize=None)
def _load_table(kind, name):
    """(wavelengths in nm, values) of one colour-science table, as read-only float arrays."""
    colour = _colour()
    with warnings.catch_warnings():
        # colour-science warns on first table access when optional packages (SciPy,
        # Matplotlib) are missing; the raw tables read here need neither.
        warnings.filterwarnings("ignore", message='.*related API features are not available')
        if kind == "illuminant":
            sd = colour.SDS_ILLUMINANTS[name]
        else:
            sd = colour.colorimetry.SDS_LEFS_PHOTOPIC[name]
    wavelengths = np.array(sd.wavelengths, dtype=float)
    values = np.array(sd.values, dtype=float)
    wavelengths.flags.writeable = False
    values.flags.writeable = False
    return wavelengths, values


def _colour():
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message='.*related API features are not available')
            import colour
    except ImportError as error:
        raise ImportError("epc_fast.spectra needs colour-science for the CIE tables: "
                          "pip install colour-science") from error
    return colour


def _as_1d_float(values, name):
    try:
        array = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: must be a 1-D array of numbers, got {values!r}") from None
    if array.ndim != 1:
        raise ValueError(f"{name}: must be 1-D, got shape {array.shape}")
    return array


def _require_all(ok, values, name, condition):
    if not np.all(ok):
        bad = int(np.argmin(ok))
        raise ValueError(f"{name}: must be {condition}, got {values[bad]!r} at index {bad}")
