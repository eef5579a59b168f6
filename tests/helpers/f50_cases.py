"""Lengths and exact f50s shared by the tests of f50's starting guesses (core/test_f50_start.py,
core/test_spectrum_start.py)."""

import numpy as np

from epc_fast import reference


def lengths(n, seed, wavelength_nm, blur_share=0.8):
    """f-numbers, lambda F (mm) and lengths (mm) whose ratios to lambda F span e^-9..e^9 (the
    fits' e^-7..e^7 and past it): pure diffraction, pure pixel, pure motion and every mix, with
    1 - blur_share of the points without motion."""
    rng = np.random.default_rng(seed)
    f_number = rng.uniform(1.0, 16.0, n)
    lambda_f = wavelength_nm * 1e-6 * f_number
    aperture = lambda_f * np.exp(rng.uniform(-9.0, 9.0, n))
    blur = lambda_f * np.exp(rng.uniform(-9.0, 9.0, n)) * (rng.random(n) < blur_share)
    return f_number, lambda_f, aperture, blur


def exact_f50(f_number, aperture_mm, blur_mm, jitter_mm, threshold, wavelengths_nm, weights):
    """The reference's f50 (bisection to adjacent doubles) from lengths, with diffraction
    summed over the wavelengths (nm) with the weights; fill factor 1, so the aperture is the
    pitch."""
    f_number, aperture_mm, blur_mm, jitter_mm, threshold = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (f_number, aperture_mm, blur_mm, jitter_mm,
                                                    threshold)))
    wavelengths_nm = np.asarray(wavelengths_nm, dtype=np.float64)
    weights = np.asarray(weights, dtype=np.float64)
    pitch_um = aperture_mm * 1e3
    jitter_um = jitter_mm * 1e3
    f_hi = reference.f50_bracket(f_number, wavelengths_nm[weights > 0].min(), pitch_um, 1.0,
                                 blur_mm, jitter_um, threshold)

    def mtf(f):
        return reference.mtf_system(f, f_number, pitch_um, 1.0, blur_mm, jitter_um,
                                    wavelengths_nm, weights)

    return reference.f50_bisection(mtf, f_hi, threshold)
