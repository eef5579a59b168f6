"""The textbook peer: per point, in plain Python, f50 by ``scipy.optimize.brentq``.

What one would write first: closed-form T_MPE (docs/model.md, "Exposure: T_MPE", in the
reference's order of operations) and f50 by Brent's method on g(f) = MTF(f) - c over the bracket [0, f_hi] of
docs/model.md, "The cut-off frequency f50", one ``brentq`` call per point, the MTF from the
``math`` module. Tolerances:
``rtol=1e-14`` (the core's default f50_rtol) and ``xtol=1e-15 f_hi`` (f50 >= 0.2 f_hi in these
scenes, so the absolute term stays below 5e-15 relative).

The scene is that of ``numba_peer``: monochromatic, on axis, lens transmittance and fill factor
1, no dark current, PRNU, full well or jitter. SciPy is a bench-only dependency (the ``bench``
extra).
"""

import math

import numpy as np
from scipy.optimize import brentq

from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2
from epc_fast.status import Status

PI = math.pi
DEG = math.pi / 180.0
SMALLEST_NORMAL = float(np.finfo(np.float64).tiny)


def _sinc(x):
    if x == 0.0:
        return 1.0
    px = PI * x
    return math.sin(px) / px


def _mtf(f, lambda_f_mm, aperture_mm, blur_mm):
    nu = min(f * lambda_f_mm, 1.0)
    d = (2.0 / PI) * (math.acos(nu) - nu * math.sqrt((1.0 - nu) * (1.0 + nu)))
    return d * _sinc(aperture_mm * f) * _sinc(blur_mm * f)


def evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor_area_mm2,
             read_noise_e, shake_deg_per_s, k_e_per_lux_s_m2=DEFAULT_ELECTRONS_PER_LUX_S_M2,
             snr_db=30.0, reflectance=0.4, wavelength_nm=550.0, threshold=0.5, rtol=1e-14):
    """t_mpe_s, f50_cyc_per_mm, epc and status (uint8) for 1-D arrays of equal length."""
    n = len(illuminance_lux)
    t_out = np.empty(n)
    f50_out = np.empty(n)
    epc_out = np.empty(n)
    status = np.empty(n, dtype=np.uint8)
    root_s = 10.0 ** (snr_db / 20.0)
    columns = (np.asarray(illuminance_lux).tolist(), np.asarray(pixel_pitch_um).tolist(),
               np.asarray(f_number).tolist(), np.asarray(focal_length_mm).tolist(),
               np.asarray(sensor_area_mm2).tolist(), np.asarray(read_noise_e).tolist(),
               np.asarray(shake_deg_per_s).tolist())
    for i, (lux, pitch, f_num, focal, area, read, shake) in enumerate(zip(*columns)):
        rate = lux * reflectance * k_e_per_lux_s_m2 * pitch * pitch * 1e-12 / 4.0 / f_num / f_num
        if not rate >= SMALLEST_NORMAL:
            t_out[i], f50_out[i], epc_out[i], status[i] = math.inf, math.nan, math.nan, \
                Status.UNREACHABLE
            continue
        t = root_s / 2.0 * (root_s + math.hypot(root_s, 2.0 * read)) / rate
        t_out[i] = t
        angle = shake * DEG * t
        if not angle < PI / 2.0:
            f50_out[i], epc_out[i], status[i] = 0.0, 0.0, Status.BLUR_UNBOUNDED
            continue
        blur = focal * math.tan(angle)
        lambda_f = wavelength_nm * 1e-6 * f_num
        aperture = pitch * 1e-3
        f_hi = min(1.0 / lambda_f, 1.0 / aperture, 1.0 / blur if blur > 0.0 else math.inf)
        f = brentq(lambda x: _mtf(x, lambda_f, aperture, blur) - threshold, 0.0, f_hi,
                   xtol=1e-15 * f_hi, rtol=rtol)
        f50_out[i] = f
        epc_out[i] = 4.0 * area * f * f
        status[i] = Status.OK
    return t_out, f50_out, epc_out, status
