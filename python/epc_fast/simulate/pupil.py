"""The lens's optical transfer function, from its pupil by Fourier transform.

The aberration-free lens has a uniform circular pupil. Its point spread function is the squared
magnitude of the pupil's Fourier transform, and its optical transfer function (OTF) the Fourier
transform of that PSF: both are computed here by FFT on a sampled pupil, not from a formula.
The OTF of a circular pupil depends on the frequency's magnitude only and scales with the
wavelength: at wavelength lambda and f-number F it is O(nu * lambda * F), where O is computed
once, in units of the cut-off frequency 1/(lambda F).

A lens given by its MTF table (``lens_mtf``) has no pupil here: its OTF is the table's
(:func:`table_transfer`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["PUPIL_RADIUS_SAMPLES", "ABERRATIONS", "pupil", "otf_profile", "diffraction_transfer",
           "cutoff_cyc_per_mm", "table_transfer", "table_cutoff_cyc_per_mm"]

#: Samples, the pupil's radius on its grid. The OTF is the pupil's autocorrelation, sampled at
#: lags of 1/(2 R) of the cut-off: at R = 480 the sampled disc's autocorrelation is within
#: 5e-5 of the continuous disc's at every lag, and the profile's linear interpolation within
#: 2e-7 away from the cut-off.
PUPIL_RADIUS_SAMPLES = 480


#: Zernike polynomials (rms 1 over the pupil) of the aberrations a wavefront error can take,
#: as functions of the pupil's normalised radius rho (Noll's normalisation).
ABERRATIONS = {
    "defocus": lambda rho: math.sqrt(3.0) * (2.0 * rho ** 2 - 1.0),
    "spherical": lambda rho: math.sqrt(5.0) * (6.0 * rho ** 4 - 6.0 * rho ** 2 + 1.0),
}


def pupil(radius_samples: int = PUPIL_RADIUS_SAMPLES, wavefront_rms_waves: float = 0.0,
          aberration: str = "defocus") -> np.ndarray:
    """The circular pupil on a square grid: in the cells whose centre lies within
    ``radius_samples`` of cell (n/2, n/2), exp(2 pi i W Z(rho)) (1 without a wavefront error,
    W in waves rms, Z the aberration's Zernike polynomial), 0 elsewhere; n the FFT-friendly
    size of at least 4 radii + 4, so that its autocorrelation does not wrap."""
    from scipy.fft import next_fast_len

    n = next_fast_len(4 * int(radius_samples) + 4)
    k = np.arange(n, dtype=float) - n // 2
    rho = np.hypot(k[:, None], k[None, :]) / radius_samples
    inside = rho <= 1.0
    if wavefront_rms_waves == 0.0:
        return inside.astype(float)
    phase = 2.0 * math.pi * wavefront_rms_waves * ABERRATIONS[aberration](rho)
    return np.where(inside, np.exp(1j * phase), 0.0)


@functools.lru_cache(maxsize=8)
def otf_profile(wavefront_rms_waves: float = 0.0,
                aberration: str = "defocus") -> tuple[np.ndarray, np.ndarray]:
    """The lens's OTF along one axis, in units of the cut-off frequency, for a wavefront error
    of ``wavefront_rms_waves`` of the ``aberration`` (both radially symmetric, so the OTF is).

    Returns
    -------
    (nu, otf) : nu from 0 to 1 in steps of 1/(2 R) (R = :data:`PUPIL_RADIUS_SAMPLES`), then
        a last sample past the cut-off where the OTF is 0; otf the real part of the normalised
        OTF there (1 at 0; the imaginary part of a radially symmetric pupil's OTF is 0).
        Computed once each: PSF = |FFT(pupil)|^2, OTF = FFT(PSF) / its value at 0.
    """
    from scipy import fft

    p = pupil(wavefront_rms_waves=wavefront_rms_waves, aberration=aberration)
    psf = np.abs(fft.fft2(p, workers=-1)) ** 2
    otf = fft.ifft2(psf, workers=-1).real
    lags = 2 * PUPIL_RADIUS_SAMPLES + 2
    profile = otf[0, :lags] / otf[0, 0]
    nu = np.arange(lags) / (2.0 * PUPIL_RADIUS_SAMPLES)
    # From a diameter's lag on, the discs no longer overlap: the lattice's count keeps a cell
    # touching at exactly one diameter, and the FFT its rounding.
    profile[nu >= 1.0] = 0.0
    if wavefront_rms_waves == 0.0:
        profile[profile < 0.0] = 0.0
    profile.flags.writeable = False
    nu.flags.writeable = False
    return nu, profile


def diffraction_transfer(frequency_cyc_per_mm, f_number: float, wavelengths_nm,
                         weights, wavefront_rms_waves: float = 0.0,
                         aberration: str = "defocus") -> np.ndarray:
    """The lens's OTF at spatial frequencies of magnitude ``frequency_cyc_per_mm``, averaged
    over the spectrum's wavelengths with their weights (the image of each wavelength adds in
    electrons), with a wavefront error of ``wavefront_rms_waves`` waves at every wavelength."""
    f = np.asarray(frequency_cyc_per_mm, dtype=float)
    nu, otf = otf_profile(float(wavefront_rms_waves), aberration)
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


def table_transfer(frequency_cyc_per_mm, table) -> np.ndarray:
    """A lens's OTF from its MTF table (an :class:`epc_fast.mtf_table.MtfTable`, cycles/mm):
    radially symmetric and real, the table's monotone interpolant at the frequency's magnitude
    up to the table's end (:func:`table_cutoff_cyc_per_mm`), 0 beyond. A table is an MTF, the
    OTF's magnitude: taking it as the OTF assumes no phase (a radially symmetric pupil with
    a real, non-negative OTF, as one free of odd aberrations and below its first zero has)."""
    f = np.asarray(frequency_cyc_per_mm, dtype=float)
    return np.where(f <= table_cutoff_cyc_per_mm(table), table(f), 0.0)


def table_cutoff_cyc_per_mm(table) -> float:
    """cycles/mm, the frequency above which a lens of MTF table ``table`` passes nothing: the
    table's first frequency with MTF 0, or its last frequency."""
    zero = np.flatnonzero(table.values == 0.0)
    return float(table.frequencies[zero[0]]) if zero.size else table.last_frequency
