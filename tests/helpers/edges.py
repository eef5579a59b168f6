"""Synthetic slanted edges whose MTF along the normal is known in closed form, for the e-SFR's
tests (tests/simulate/).

A pixel's value is lo + (hi - lo) ESF(d), with d the signed distance (in pixels) of the pixel's
centre (column x, row y) from a straight edge through (x0, y = 0) at ``angle_deg`` from the
vertical: d = (x - x0 - y tan a) cos a. Distances and frequencies are in pixels and cycles a
pixel; each ESF has its MTF beside it.
"""

import math

import numpy as np
from scipy.special import ndtr

from epc_fast.simulate import blur, pupil

LO, HI = 100.0, 1100.0


def edge_image(esf, rows=64, cols=64, angle_deg=5.0, x0=None, lo=LO, hi=HI):
    """A rows x cols image of ``esf(d)`` across an edge at ``angle_deg`` from the vertical,
    crossing row 0 at column x0 (the edge's centre row on the middle column by default)."""
    a = np.radians(angle_deg)
    if x0 is None:
        x0 = (cols - 1) / 2 - (rows - 1) / 2 * np.tan(a)
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    d = (x - x0 - y * np.tan(a)) * np.cos(a)
    return lo + (hi - lo) * esf(d)


def gaussian_esf(sigma):
    """The ESF of a Gaussian blur of standard deviation ``sigma`` pixels, point-sampled."""
    return lambda d: ndtr(d / sigma)


def gaussian_mtf(sigma, f):
    return np.exp(-2 * np.pi**2 * sigma**2 * np.asarray(f) ** 2)


def box_esf(width):
    """The ESF of a box blur ``width`` pixels wide, point-sampled."""
    return lambda d: np.clip(d / width + 0.5, 0.0, 1.0)


def box_mtf(width, f):
    return np.abs(np.sinc(width * np.asarray(f)))


def _psi2(x):
    """The second antiderivative of the normal CDF: ((x^2 + 1) Phi(x) + x phi(x)) / 2."""
    return ((x * x + 1) * ndtr(x) + x * np.exp(-x * x / 2) / np.sqrt(2 * np.pi)) / 2


def pixel_esf(angle_deg, sigma):
    """The ESF of a square pixel of side 1 integrating a Gaussian edge (``sigma`` pixels;
    small for a sharp edge): projected on the normal the pixel is two boxes, cos a and sin a
    wide, so the ESF is P(U1 + U2 + sigma Z < d), Phi integrated twice."""
    a = np.radians(abs(angle_deg))
    c, s = np.cos(a), np.sin(a)

    def esf(d):
        t = [(d + (c + s) / 2) / sigma, (d + (c - s) / 2) / sigma,
             (d - (c - s) / 2) / sigma, (d - (c + s) / 2) / sigma]
        return sigma**2 / (c * s) * (_psi2(t[0]) - _psi2(t[1]) - _psi2(t[2]) + _psi2(t[3]))

    return esf


def pixel_mtf(angle_deg, sigma, f):
    a = np.radians(angle_deg)
    f = np.asarray(f)
    return np.abs(np.sinc(f * np.cos(a)) * np.sinc(f * np.sin(a))) * gaussian_mtf(sigma, f)


# The exact image of a straight edge, computed in one dimension, to hold the capture's 2-D
# image against (tests/simulate/test_camera.py).
#
# An infinite straight edge imaged by a shift-invariant system is a function of the distance d
# to the edge alone: lo + (hi - lo) ESF(d), the ESF the integral of the line spread function,
# whose spectrum is the system's 2-D transfer on the edge's normal (the projection-slice
# theorem). On a 1-D grid the line spread can be given a period of 40 mm, where the Airy pattern's tail
# beyond half of it holds under 1e-5 of the light (2 lambda F / (pi^3 x) at x = 20 mm), which
# the 2-D grid cannot afford.

def edge_spread(d_mm, *, angle_deg, f_number, wavelength_nm, pitch_um, fill_factor=1.0,
                jitter_mm=0.0, motion=None, motion_angle_deg=0.0, period_mm=40.0,
                spacing_mm=5e-5):
    """The ESF (0 to 1) at normal distances ``d_mm`` of the simulator's own transfers on the
    normal of an edge ``angle_deg`` from the vertical; ``motion`` = (T, f_L, omega) or None,
    along ``motion_angle_deg`` from the rows (the normal, (cos a, -sin a), sees the motion
    times cos(a + motion angle))."""
    n = int(period_mm / spacing_mm)
    n += n % 2
    f_all = np.fft.rfftfreq(n, spacing_mm)
    cutoff = pupil.cutoff_cyc_per_mm(f_number, wavelength_nm)
    f = f_all[f_all < cutoff]  # the lens passes nothing above its cut-off
    a = math.radians(angle_deg)
    h = pupil.diffraction_transfer(f, f_number, [wavelength_nm], [1.0]).astype(complex)
    width = math.sqrt(fill_factor) * pitch_um * 1e-3
    h *= blur.aperture_transfer(f * math.cos(a), width)
    h *= blur.aperture_transfer(f * math.sin(a), width)
    h *= blur.jitter_transfer(f * math.cos(a), jitter_mm)
    h *= blur.jitter_transfer(f * math.sin(a), jitter_mm)
    if motion is not None:
        h *= blur.motion_transfer(f * math.cos(a + math.radians(motion_angle_deg)), *motion)[0]
    h = np.concatenate([h, np.zeros(f_all.size - f.size)])
    lsf = np.roll(np.fft.irfft(h, n), n // 2)  # the line spread times the spacing, centred
    x = (np.arange(n) - n // 2 + 0.5) * spacing_mm  # the right edge of each sample's cell
    return np.interp(d_mm, x, np.cumsum(lsf))
