"""The sensor's side of a capture: photo-electrons, dark electrons, their noise, PRNU, the full
well and the read-out, drawn from a seeded generator."""

from __future__ import annotations

import numpy as np

__all__ = ["read_out", "POISSON_NORMAL_ABOVE"]

#: e-, a mean above which a count is drawn from the normal distribution of the same mean and
#: variance instead of Poisson's (NumPy's Poisson refuses means near 1e19; at 1e12 the two
#: differ by a skewness of 1e-6).
POISSON_NORMAL_ABOVE = 1e12


def _counts(rng, mean):
    mean = np.asarray(mean, dtype=float)
    small = mean <= POISSON_NORMAL_ABOVE
    out = np.empty(mean.shape)
    out[small] = rng.poisson(mean[small])
    big = ~small
    if big.any():
        out[big] = rng.normal(mean[big], np.sqrt(mean[big]))
    return out


def read_out(photo_mean_e, *, exposure_s: float, dark_current_e_per_s: float,
             read_noise_e: float, prnu: float, full_well_e: float,
             rng: np.random.Generator) -> np.ndarray:
    """e-, each pixel's signal as the camera reports it.

    Each pixel's photo-response is scaled by 1 + u g (g a standard normal drawn per pixel: the
    PRNU's fixed pattern); it then collects a Poisson number of photo-electrons of that mean
    and a Poisson number of dark electrons of mean D T; the well holds at most
    ``full_well_e``; the read-out adds Gaussian noise of rms ``read_noise_e``; the mean dark
    signal D T is subtracted (the camera's black level), its noise stays.

    Parameters
    ----------
    photo_mean_e : array, e-, the expected photo-electrons of each pixel.
    """
    mean = np.asarray(photo_mean_e, dtype=float)
    if prnu > 0.0:
        gain = 1.0 + prnu * rng.standard_normal(mean.shape)
        mean = mean * np.maximum(gain, 0.0)
    electrons = _counts(rng, mean)
    dark = dark_current_e_per_s * exposure_s
    if dark > 0.0:
        electrons += _counts(rng, np.full(mean.shape, dark))
    if np.isfinite(full_well_e):
        np.minimum(electrons, full_well_e, out=electrons)
    if read_noise_e > 0.0:
        electrons += rng.normal(0.0, read_noise_e, mean.shape)
    return electrons - dark
