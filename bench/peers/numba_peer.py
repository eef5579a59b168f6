"""The strongest pure-Python peer: the same model in Numba, ``parallel=True``.

Closed-form T_MPE (MODEL.md section 3) and f50 by Newton's method on MTF(f) - c with an
analytic derivative, safeguarded by the bisection bracket of MODEL.md section 6: a step that
would leave the bracket is replaced by a bisection step. Monochromatic, no jitter (the scene of
the engine benchmarks). Numba is a bench-only dependency.
"""

import math

import numba
import numpy as np

PI = math.pi


@numba.njit(inline="always")
def _sinc_and_slope(x):
    """sinc(x) and d sinc / dx."""
    if x == 0.0:
        return 1.0, 0.0
    px = PI * x
    s = math.sin(px) / px
    return s, (math.cos(px) - s) / x


@numba.njit(inline="always")
def _mtf_and_slope(f, lambda_f_mm, aperture_mm, blur_mm):
    nu = min(f * lambda_f_mm, 1.0)
    root = math.sqrt((1.0 - nu) * (1.0 + nu))
    d = (2.0 / PI) * (math.acos(nu) - nu * root)
    dd = -(4.0 / PI) * root * lambda_f_mm
    p, dp = _sinc_and_slope(aperture_mm * f)
    m, dm = _sinc_and_slope(blur_mm * f)
    return d * p * m, dd * p * m + d * dp * aperture_mm * m + d * p * dm * blur_mm


@numba.njit(parallel=True)
def evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor_area_mm2,
             read_noise_e, shake_deg_per_s, k_e_per_lux_s_m2, snr_db=30.0, reflectance=0.4,
             wavelength_nm=550.0, threshold=0.5, rtol=1e-14):
    """t_mpe_s, f50_cyc_per_mm and epc for 1-D arrays of equal length (OK points only)."""
    n = illuminance_lux.shape[0]
    t_out = np.empty(n)
    f50_out = np.empty(n)
    epc_out = np.empty(n)
    root_s = 10.0 ** (snr_db / 20.0)
    s = root_s * root_s
    for i in numba.prange(n):
        p_m = pixel_pitch_um[i] * 1e-6
        rate = (illuminance_lux[i] * reflectance / (4.0 * f_number[i] ** 2)
                * k_e_per_lux_s_m2 * p_m * p_m)
        electrons = 0.5 * (s + math.hypot(s, 2.0 * read_noise_e[i] * root_s))
        t = electrons / rate
        blur = focal_length_mm[i] * math.tan(shake_deg_per_s[i] * PI / 180.0 * t)
        lambda_f = wavelength_nm * 1e-6 * f_number[i]
        aperture = pixel_pitch_um[i] * 1e-3
        hi = min(1.0 / lambda_f, 1.0 / aperture)
        if blur > 0.0:
            hi = min(hi, 1.0 / blur)
        lo = 0.0
        f = 0.5 * hi
        for _ in range(100):
            m, dm = _mtf_and_slope(f, lambda_f, aperture, blur)
            if m > threshold:
                lo = f
            else:
                hi = f
            step = (m - threshold) / dm if dm != 0.0 else 0.0
            x = f - step
            if not (lo < x < hi):
                x = lo + 0.5 * (hi - lo)
            if abs(x - f) <= rtol * x or hi - lo <= rtol * lo:
                f = x
                break
            f = x
        t_out[i] = t
        f50_out[i] = f
        epc_out[i] = 4.0 * sensor_area_mm2[i] * f * f
    return t_out, f50_out, epc_out
