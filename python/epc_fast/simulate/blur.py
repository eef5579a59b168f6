"""What moving and averaging the image does to its spectrum: the camera's motion during the
exposure, jitter, and the pixel integrating the image over its aperture.

Each is an average of shifted copies of the image: over the exposure's time (motion), over the
distribution of random displacements (jitter), over the points of the pixel's aperture (the
pixel's integral). Shifting by s multiplies the image's spectrum by exp(-2 pi i f s) exactly
when the image is band-limited on its grid (the capture makes sure it is), so each average is
computed here as that average of phase factors, by quadrature over time, displacement or
aperture: the images are moved and summed, not given a formula's transfer.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["motion_path_mm", "motion_transfer", "motion_transfer_2d", "jitter_transfer",
           "aperture_transfer"]

_NODES = 8  # Gauss-Legendre nodes a segment: exact for polynomials to degree 15


def motion_path_mm(t_s, focal_length_mm: float, shake_rad_per_s: float) -> np.ndarray:
    """mm, where the image of the point on the optical axis has moved after time ``t_s`` of a
    camera turning at ``shake_rad_per_s``: f_L tan(omega t), along the rows."""
    return focal_length_mm * np.tan(shake_rad_per_s * np.asarray(t_s, dtype=float))


def _legendre(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return x / 2.0, w / 2.0  # on [-1/2, 1/2] in units of the interval, weights summing to 1


def motion_transfer(frequency_cyc_per_mm, exposure_s: float, focal_length_mm: float,
                    shake_rad_per_s: float, start_s: float = 0.0):
    """The spectrum's factor from the image moving along the rows during an exposure.

    The time average over [t0, t0 + T] (t0 = ``start_s``, T = ``exposure_s``) of
    exp(-2 pi i f (s(t) - s_mean)), s the path of :func:`motion_path_mm` and s_mean its time
    average (the capture registers each frame on its mean position), by composite
    Gauss-Legendre quadrature in time with segments short enough that the phase at the highest
    frequency turns under one cycle in each.

    Returns
    -------
    (transfer, extent_mm, mean_mm) : the complex factor at each frequency, the distance the
        image travels, and its mean position.
    """
    f = np.asarray(frequency_cyc_per_mm, dtype=float)
    if exposure_s == 0.0 or shake_rad_per_s == 0.0:
        return np.ones(f.shape, dtype=complex), 0.0, 0.0
    f_max = float(np.max(np.abs(f))) if f.size else 0.0
    weights, shift, extent, mean = _motion_nodes(exposure_s, focal_length_mm, shake_rad_per_s,
                                                 start_s, f_max)
    transfer = np.zeros(f.shape, dtype=complex)
    flat = f.ravel()
    out = transfer.ravel()
    step = max(1, 2_000_000 // max(1, flat.size))  # time nodes a block, to bound memory
    for start in range(0, shift.size, step):
        s = shift[start:start + step]
        out += np.exp(-2j * math.pi * np.multiply.outer(flat, s)) @ weights[start:start + step]
    return out.reshape(f.shape), extent, mean


def _motion_nodes(exposure_s, focal_length_mm, shake_rad_per_s, start_s, f_max):
    """(weights, shifts about the mean in mm, extent in mm, mean in mm) of the time nodes of
    :func:`motion_transfer`'s quadrature for frequencies up to ``f_max`` cycles/mm."""
    end = start_s + exposure_s
    ends = motion_path_mm(np.array([start_s, end]), focal_length_mm, shake_rad_per_s)
    extent = float(ends[1] - ends[0])
    # The path is fastest at its end: sec^2 of the angle there against its mean speed.
    peak_over_mean = (shake_rad_per_s * exposure_s * focal_length_mm
                      / (math.cos(shake_rad_per_s * end) ** 2 * extent))
    segments = max(1, math.ceil(f_max * extent * peak_over_mean))
    x, w = _legendre(_NODES)
    edges = np.linspace(start_s, end, segments + 1)
    times = (edges[:-1, None] + (x[None, :] + 0.5) * (edges[1] - edges[0])).ravel()
    weights = np.tile(w, segments) / segments
    path = motion_path_mm(times, focal_length_mm, shake_rad_per_s)
    mean = float(np.dot(weights, path))
    return weights, path - mean, extent, mean


def motion_transfer_2d(fy_cyc_per_mm, fx_cyc_per_mm, exposure_s: float,
                       focal_length_mm: float, shake_rad_per_s: float, direction_rad: float,
                       start_s: float = 0.0) -> np.ndarray:
    """The spectrum's factor, on the grid (fy[i], fx[j]), from the image moving along the
    direction ``direction_rad`` from the rows (towards larger rows for a positive angle)
    during an exposure: :func:`motion_transfer`'s time average at the frequency along the
    motion, u = fx cos(angle) + fy sin(angle), shape (fy.size, fx.size).

    Each time node's phase exp(-2 pi i u s) is the product of a row's factor
    exp(-2 pi i fy sin(angle) s) and a column's exp(-2 pi i fx cos(angle) s), so the average
    over the nodes is a matrix product of the two (fy x nodes) @ (nodes x fx): exact as the
    quadrature is, at a cost of fy.size fx.size multiply-adds a node.
    """
    fy = np.asarray(fy_cyc_per_mm, dtype=float).ravel()
    fx = np.asarray(fx_cyc_per_mm, dtype=float).ravel()
    if exposure_s == 0.0 or shake_rad_per_s == 0.0:
        return np.ones((fy.size, fx.size), dtype=complex)
    sy, sx = math.sin(direction_rad), math.cos(direction_rad)
    f_max = ((float(np.max(np.abs(fy))) if fy.size else 0.0) * abs(sy)
             + (float(np.max(np.abs(fx))) if fx.size else 0.0) * abs(sx))
    weights, shift, _, _ = _motion_nodes(exposure_s, focal_length_mm, shake_rad_per_s, start_s,
                                         f_max)
    out = np.zeros((fy.size, fx.size), dtype=complex)
    step = max(1, 4_000_000 // max(1, fy.size + fx.size))  # time nodes a block
    for start in range(0, shift.size, step):
        s = shift[start:start + step]
        rows = np.exp(-2j * math.pi * sy * np.multiply.outer(fy, s))
        cols = np.exp(-2j * math.pi * sx * np.multiply.outer(s, fx))
        out += (rows * weights[start:start + step]) @ cols
    return out


def jitter_transfer(frequency_cyc_per_mm, jitter_mm: float, nodes: int = 48) -> np.ndarray:
    """The spectrum's factor, along one axis, from random displacements of rms ``jitter_mm``
    (Gaussian, independent per axis): the expected phase factor over the displacement's
    distribution by Gauss-Hermite quadrature, exact to rounding with 48 nodes up to
    f sigma = 0.9, where the factor has fallen below 1e-6; beyond, the displacements have
    averaged the image out and the factor is 0."""
    f = np.asarray(frequency_cyc_per_mm, dtype=float)
    if jitter_mm == 0.0:
        return np.ones(f.shape)
    x, w = np.polynomial.hermite.hermgauss(nodes)
    shifts = math.sqrt(2.0) * jitter_mm * x
    factor = np.cos(2.0 * math.pi * np.multiply.outer(f, shifts)) @ (w / math.sqrt(math.pi))
    return np.where(np.abs(f) * jitter_mm > 0.9, 0.0, factor)


def aperture_transfer(frequency_cyc_per_mm, width_mm: float) -> np.ndarray:
    """The spectrum's factor, along one axis, from integrating the image over an aperture
    ``width_mm`` wide centred on the pixel: the average of the image over the aperture's points
    by Gauss-Legendre quadrature, with nodes enough for 2 per cycle across the aperture at the
    highest frequency plus 16 (exact to rounding there)."""
    f = np.asarray(frequency_cyc_per_mm, dtype=float)
    f_max = float(np.max(np.abs(f))) if f.size else 0.0
    n = 16 + 2 * math.ceil(f_max * width_mm)
    x, w = _legendre(n)
    return np.cos(2.0 * math.pi * np.multiply.outer(f, x * width_mm)) @ w
