"""The lens's optical transfer function, from its pupil by Fourier transform.

The aberration-free lens has a uniform circular pupil. Its point spread function is the squared
magnitude of the pupil's Fourier transform, and its optical transfer function (OTF) the Fourier
transform of that PSF: both are computed here by FFT on a sampled pupil, not from a formula.
The OTF of a circular pupil depends on the frequency's magnitude only and scales with the
wavelength: at wavelength lambda and f-number F it is O(nu * lambda * F), where O is computed
once, in units of the cut-off frequency 1/(lambda F).
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["PUPIL_RADIUS_SAMPLES", "pupil", "otf_profile", "diffraction_transfer",
           "cutoff_cyc_per_mm"]

#: Samples, the pupil's radius on its grid. The OTF is the pupil's autocorrelation, sampled at
#: lags of 1/(2 R) of the cut-off: at R = 480 the sampled disc's autocorrelation is within
#: 5e-5 of the continuous disc's at every lag, and the profile's linear interpolation within
#: 2e-7 away from the cut-off.
PUPIL_RADIUS_SAMPLES = 480


def pupil(radius_samples: int = PUPIL_RADIUS_SAMPLES) -> np.ndarray:
    """The uniform circular pupil on a square grid: 1 in the cells whose centre lies within
    ``radius_samples`` of cell (n/2, n/2), 0 elsewhere, on an n x n grid with n the
    FFT-friendly size of at least 4 radii + 4, so that its autocorrelation does not wrap."""
    from scipy.fft import next_fast_len

    n = next_fast_len(4 * int(radius_samples) + 4)
    k = np.arange(n, dtype=float) - n // 2
    return (np.hypot(k[:, None], k[None, :]) <= radius_samples).astype(float)


@functools.lru_cache(maxsize=1)
def otf_profile() -> tuple[np.ndarray, np.ndarray]:
    """The aberration-free OTF along one axis, in units of the cut-off frequency.

    Returns
    -------
    (nu, otf) : nu from 0 to 1 in steps of 1/(2 R) (R = :data:`PUPIL_RADIUS_SAMPLES`), then
        a last sample past the cut-off where the OTF is 0; otf the normalised OTF there
        (1 at 0). Computed once: PSF = |FFT(pupil)|^2, OTF = FFT(PSF) / its value at 0.
    """
    from scipy import fft

    p = pupil()
    psf = np.abs(fft.fft2(p, workers=-1)) ** 2
    otf = fft.ifft2(psf, workers=-1).real
    lags = 2 * PUPIL_RADIUS_SAMPLES + 2
    profile = otf[0, :lags] / otf[0, 0]
    nu = np.arange(lags) / (2.0 * PUPIL_RADIUS_SAMPLES)
    # From a diameter's lag on, the discs no longer overlap: the lattice's count keeps a cell
    # touching at exactly one diameter, and the FFT its rounding.
    profile[(nu >= 1.0) | (profile < 0.0)] = 0.0
    profile.flags.writeable = False
    nu.flags.writeable = False
    return nu, profile


def diffraction_transfer(frequency_cyc_per_mm, f_number: float, wavelengths_nm,
                         weights) -> np.ndarray:
    """The lens's OTF at spatial frequencies of magnitude ``frequency_cyc_per_mm``, averaged
    over the spectrum's wavelengths with their weights (the image of each wavelength adds in
    electrons)."""
    f = np.asarray(frequency_cyc_per_mm, dtype=float)
    nu, otf = otf_profile()
    wavelengths = np.asarray(wavelengths_nm, dtype=float)
    w = np.asarray(weights, dtype=float)
    if wavelengths.size == 1:
        return np.interp(f * wavelengths[0] * 1e-6 * f_number, nu, otf, right=0.0)
    # One profile for the whole spectrum, in units of the shortest wavelength's cut-off, then
    # one interpolation on the frequency grid.
    shortest = float(wavelengths.min())
    grid = np.linspace(0.0, 1.0, 16 * nu.size)
    combined = sum(wi * np.interp(grid * (li / shortest), nu, otf, right=0.0)
                   for li, wi in zip(wavelengths, w))
    cutoff = 1.0 / (shortest * 1e-6 * f_number)
    return np.interp(f / cutoff, grid, combined, right=0.0)


def cutoff_cyc_per_mm(f_number: float, shortest_wavelength_nm: float) -> float:
    """cycles/mm, the frequency above which the lens passes nothing: 1/(lambda F)."""
    return 1.0 / (shortest_wavelength_nm * 1e-6 * f_number) if f_number > 0 else math.inf
