"""The strongest Numba peer a user would write for the default call's two outputs, f50 and EPC:
closed-form T_MPE, f50 by two Halley steps from the fitted guess of ``numba_peer`` (ln MTF ~
-alpha f - beta f^2), no bracket and no stop test, in Numba's own ``prange`` loop, into
preallocated arrays. Its f50 agrees with the core to about 1e-9 on the engine benchmarks'
designs (the two steps' cubic convergence from a guess within a few percent); points that are
not OK are NaN (no light) or 0 (unbounded blur), as the core writes them."""

import math

import numba
import numpy as np

from peers.numba_peer import DEG, HALF_PI, SMALLEST_NORMAL, _guess_coefficients, _mtf3
from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2

STEPS = 2


@numba.njit(parallel=True, fastmath=False)
def _evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor_area_mm2,
              read_noise_e, shake_deg_per_s, k, root_s, reflectance, wavelength_nm, threshold,
              alpha, beta_per_length2, log_c, f50_out, epc_out):
    for i in numba.prange(illuminance_lux.shape[0]):
        pitch = pixel_pitch_um[i]
        rate = (illuminance_lux[i] * reflectance * k * pitch * pitch * 1e-12
                / 4.0 / f_number[i] / f_number[i])
        if not rate >= SMALLEST_NORMAL:
            f50_out[i] = math.nan
            epc_out[i] = math.nan
            continue
        electrons = root_s / 2.0 * (root_s + math.hypot(root_s, 2.0 * read_noise_e[i]))
        angle = shake_deg_per_s[i] * DEG * (electrons / rate)
        if not angle < HALF_PI:
            f50_out[i] = 0.0
            epc_out[i] = 0.0
            continue
        blur = focal_length_mm[i] * math.tan(angle)
        lambda_f = wavelength_nm * 1e-6 * f_number[i]
        aperture = pitch * 1e-3
        a = alpha * lambda_f
        b = beta_per_length2 * (aperture * aperture + blur * blur)
        f = 2.0 * log_c / (a + math.sqrt(a * a + 4.0 * b * log_c))
        for _ in range(STEPS):
            g, dg, d2g = _mtf3(f, lambda_f, aperture, blur)
            g -= threshold
            f -= 2.0 * g * dg / (2.0 * dg * dg - g * d2g)
        f50_out[i] = f
        epc_out[i] = 4.0 * sensor_area_mm2[i] * f * f


def evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor_area_mm2,
             read_noise_e, shake_deg_per_s, f50_out, epc_out, snr_db=30.0, reflectance=0.4,
             wavelength_nm=550.0, threshold=0.5):
    """f50 (cycles/mm) and EPC into ``f50_out`` and ``epc_out``, for 1-D arrays."""
    alpha, beta, log_c = _guess_coefficients(threshold)
    _evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor_area_mm2,
              read_noise_e, shake_deg_per_s, DEFAULT_ELECTRONS_PER_LUX_S_M2,
              10.0 ** (snr_db / 20.0), reflectance, wavelength_nm, threshold, alpha, beta,
              log_c, f50_out, epc_out)
    return f50_out, epc_out
