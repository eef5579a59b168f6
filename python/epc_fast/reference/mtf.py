"""The NumPy reference of the MTF factors (docs/model.md, "System MTF"): diffraction, the pixel
aperture (binned or not), motion, jitter and a burst's alignment residual, one formula a
function, each with the same name as in ``cpp/include/epc_fast/mtf.h``. Their product is
:func:`epc_fast.reference.model.mtf_system`.

Units: lengths in mm (the pitch and the jitter in um, as their names say), spatial frequencies
in cycles/mm.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "sinpi",
    "sinc",
    "mtf_diffraction",
    "mtf_pixel",
    "mtf_binned_pixel",
    "mtf_motion",
    "mtf_jitter",
    "gaussian_blur_mm",
    "mtf_alignment",
]


def sinpi(x):
    """1: sin(pi x), from r = x - round(x), which is exact: sin(pi x) = (-1)^round(x) sin(pi r).

    sin(np.pi * x) would lose the digits of x's distance to the nearest integer (the zeros).
    """
    x = np.asarray(x, dtype=np.float64)
    k = np.round(x)
    s = np.sin(np.pi * (x - k))
    return np.where(np.fmod(k, 2.0) == 0.0, s, -s)


def sinc(x):
    """1: the normalised sinc, sin(pi x) / (pi x), equal to 1 at x = 0."""
    x = np.asarray(x, dtype=np.float64)
    safe = np.where(x == 0.0, 1.0, x)
    return np.where(x == 0.0, 1.0, sinpi(safe) / (np.pi * safe))


#: x - sin x = x^3 * sum_k (-1)^k x^(2k) / (2k+3)!: enough terms for 2e-17 relative at x <= 2.1.
_X_MINUS_SIN_SERIES = [(-1) ** k / math.factorial(2 * k + 3) for k in range(13)]


def mtf_diffraction(f_cyc_per_mm, wavelength_nm, f_number):
    """1: aberration-free circular-pupil diffraction MTF at normalised frequency nu = f lambda F.

    D = (2/pi) (acos nu - nu sqrt(1 - nu^2)) for nu < 1, else 0. Up to nu = 1/2 this is
    evaluated as written (1 - nu^2 as (1 - nu)(1 + nu)). Above, its two terms cancel as
    nu -> 1, and D is written with phi = acos nu as (2 phi - sin 2 phi) / pi: phi is
    2 asin(sqrt((1 - nu)/2)), exact near nu = 1, and 2 phi - sin 2 phi (2 phi <= 2 pi/3) is
    summed from its Taylor series, whose terms alternate and fall fast: D keeps its relative
    precision down to the cut-off, where it vanishes as (1 - nu)^(3/2).
    """
    nu = np.minimum(f_cyc_per_mm * (wavelength_nm * 1e-6) * f_number, 1.0)
    low = (2.0 / np.pi) * (np.arccos(nu) - nu * np.sqrt((1.0 - nu) * (1.0 + nu)))
    x = 4.0 * np.arcsin(np.sqrt(0.5 * (1.0 - nu)))  # 2 phi
    high = x**3 * np.polynomial.polynomial.polyval(x * x, _X_MINUS_SIN_SERIES) / np.pi
    return np.where(nu <= 0.5, low, high)


def mtf_pixel(f_cyc_per_mm, pixel_pitch_um, fill_factor):
    """1: square pixel aperture of side sqrt(a) p: ``|sinc(sqrt(a) p f)|``, p in mm."""
    return np.abs(sinc(np.sqrt(fill_factor) * (pixel_pitch_um * 1e-3) * f_cyc_per_mm))


def mtf_binned_pixel(f_cyc_per_mm, pixel_pitch_um, fill_factor, binning):
    """1: k x k pixels read as one: ``|sinc(sqrt(a) p f) sin(k pi p f) / (k sin(pi p f))|``.

    Where sin(pi p f) = 0 (p f a whole number) the ratio takes its limit, cos(k pi p f) /
    cos(pi p f) = +-1. At k = 1 the ratio is 1 and this is :func:`mtf_pixel` (whatever p f: a
    small fill factor takes f50 far past 1/p); at a = 1 it is sinc(k p f).
    """
    y = (pixel_pitch_um * 1e-3) * f_cyc_per_mm
    k = np.asarray(binning, dtype=np.float64)
    sin_y = sinpi(y)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(sin_y == 0.0, sinpi(k * y + 0.5) / sinpi(y + 0.5),
                         sinpi(k * y) / (k * sin_y))
    ratio = np.where(k == 1.0, 1.0, ratio)
    return np.abs(sinc(np.sqrt(fill_factor) * (pixel_pitch_um * 1e-3) * f_cyc_per_mm) * ratio)


def mtf_motion(f_cyc_per_mm, blur_mm):
    """1: linear motion of length b: ``|sinc(b f)|``."""
    return np.abs(sinc(blur_mm * f_cyc_per_mm))


def mtf_jitter(f_cyc_per_mm, jitter_um):
    """1: Gaussian jitter of rms sigma_j: exp(-2 pi^2 (sigma_j f)^2), sigma_j in mm."""
    return np.exp(-2.0 * np.pi**2 * (jitter_um * 1e-3 * f_cyc_per_mm) ** 2)


def gaussian_blur_mm(jitter_um, alignment_error_um, frames):
    """mm: jitter and a burst's alignment residual as one Gaussian, J(f) A(f), of rms
    sqrt(sigma_j^2 + sigma_a^2 (1 - 1/n)): what bounds f50's bracket where they are the only
    factors that fall."""
    residual_um = alignment_error_um * np.sqrt(1.0 - 1.0 / np.asarray(frames, dtype=np.float64))
    return np.hypot(jitter_um, residual_um) * 1e-3


def mtf_alignment(f_cyc_per_mm, alignment_error_um, frames):
    """1: the alignment residual of a burst of n frames, each aligned to within sigma_a rms:
    the frames' offsets about their mean, of variance sigma_a^2 (1 - 1/n), blur the sum by
    exp(-2 pi^2 sigma_a^2 (1 - 1/n) f^2), sigma_a in mm (1 for one frame)."""
    variance_mm2 = (alignment_error_um * 1e-3) ** 2 * (1.0 - 1.0 / np.asarray(frames, dtype=np.float64))
    return np.exp(-2.0 * np.pi**2 * variance_mm2 * f_cyc_per_mm**2)
