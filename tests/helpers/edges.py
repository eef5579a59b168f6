"""Synthetic slanted edges whose MTF along the normal is known in closed form, for the e-SFR's
tests (tests/simulate/).

A pixel's value is lo + (hi - lo) ESF(d), with d the signed distance (in pixels) of the pixel's
centre (column x, row y) from a straight edge through (x0, y = 0) at ``angle_deg`` from the
vertical: d = (x - x0 - y tan a) cos a. Distances and frequencies are in pixels and cycles a
pixel; each ESF has its MTF beside it.
"""

import numpy as np
from scipy.special import ndtr

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
