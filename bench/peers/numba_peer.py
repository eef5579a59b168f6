"""The strongest pure-Python peer: the same model in Numba, ``parallel=True``.

Closed-form T_MPE (docs/model.md, "Exposure: T_MPE"), written in the reference's order of
operations, and f50 by a safeguarded Halley iteration on g(f) = MTF(f) - c with analytic first and second
derivatives, inside the bisection bracket [0, f_hi] of docs/model.md, "The cut-off frequency f50":

- the start is a good guess: ln MTF(f) ~ -alpha f - beta f^2 (diffraction falls about
  linearly in f, alpha proportional to lambda F; each sinc about as a Gaussian, beta
  proportional to a^2 + b^2, a the pixel aperture and b the blur), the coefficients set so that
  the guess is exact when one factor alone sets f50, solved for ln(1/c) and clamped into the
  bracket: 3.2 MTF evaluations a point on average on the benchmarks' designs;
- every evaluation shrinks the bracket (g > 0: lo = f, else hi = f), so the root stays inside;
- a Halley step that is not finite or would leave (lo, hi) is replaced by a bisection step;
- it stops when |step| <= rtol * f (rtol = 1e-14), before the safeguard (a converged step
  may round onto a bracket end), or when the bracket is that narrow.

With ``same_algorithm=True`` the peer runs the core's own algorithm instead, to separate what
the algorithm buys from what the C++ buys: the core's accurate start (f50/guesses.h, its
coefficients read from ``epc_fast._core``, threshold 1/2 only: within 4.2e-8 of f50) and the
core's stop test (a lane stops when its step d <= (rtol/10)^(1/3) f and d^3 / p^2 <=
(rtol/10) f, p the step before, the bracket's width at first), so that it too stops after one
MTF evaluation on these designs.

The scene is that of the engine benchmarks (``epc_fast.selfcheck.random_designs``):
monochromatic, on axis, lens transmittance and fill factor 1, no dark current, PRNU, full well
or jitter; statuses OK, UNREACHABLE (no light) and BLUR_UNBOUNDED as the core gives them.
Numba is a bench-only dependency (the ``bench`` extra).
"""

import math

import numba
import numpy as np

from epc_fast import _core
from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2
from epc_fast.status import Status

PI = math.pi
HALF_PI = math.pi / 2.0
DEG = math.pi / 180.0
SMALLEST_NORMAL = float(np.finfo(np.float64).tiny)
OK = int(Status.OK)
UNREACHABLE = int(Status.UNREACHABLE)
BLUR_UNBOUNDED = int(Status.BLUR_UNBOUNDED)
#: Below this |pi x| the sinc's derivatives come from their Taylor series (no cancellation).
SMALL_PI_X = 1e-2
#: The core's accurate start (f50/guesses.h): each factor's own f50 in units of its length, and
#: the polynomial in a = 2 v_d - 1 and z = w^2, rows a^0 .. a^degree of z^0 .. z^((degree-i)/2).
NU50 = 0.4039727532995172
X50 = 0.6033545644016142
START_DEGREE = int(_core.testing.accurate_start_degree)
#: threshold 1/2's row (the benchmarks' threshold)
START_COEFFICIENTS = np.asarray(
    _core.testing.accurate_start_coefficients[
        list(_core.testing.accurate_start_thresholds).index(0.5)],
    dtype=np.float64)


@numba.njit(inline="always")
def _sinc3(x):
    """sinc(x) = sin(pi x)/(pi x) and its first and second derivatives in x."""
    px = PI * x
    if abs(px) < SMALL_PI_X:
        p2 = px * px
        s = 1.0 - p2 / 6.0 + p2 * p2 / 120.0
        ds = PI * px * (-1.0 / 3.0 + p2 / 30.0)
        d2s = PI * PI * (-1.0 / 3.0 + p2 / 10.0)
        return s, ds, d2s
    s = math.sin(px) / px
    ds = (math.cos(px) - s) / x
    return s, ds, -PI * PI * s - 2.0 * ds / x


@numba.njit(inline="always")
def _mtf3(f, lambda_f_mm, aperture_mm, blur_mm):
    """MTF = D P M at f (cycles/mm) and its first and second derivatives in f."""
    nu = min(f * lambda_f_mm, 1.0)
    root = math.sqrt((1.0 - nu) * (1.0 + nu))
    d = (2.0 / PI) * (math.acos(nu) - nu * root)
    dd = -(4.0 / PI) * root * lambda_f_mm
    d2d = (4.0 / PI) * nu / root * lambda_f_mm * lambda_f_mm if root > 0.0 else math.inf
    p, dp, d2p = _sinc3(aperture_mm * f)
    dp *= aperture_mm
    d2p *= aperture_mm * aperture_mm
    m, dm, d2m = _sinc3(blur_mm * f)
    dm *= blur_mm
    d2m *= blur_mm * blur_mm
    value = d * p * m
    slope = dd * p * m + d * dp * m + d * p * dm
    curve = (d2d * p * m + d * d2p * m + d * p * d2m
             + 2.0 * (dd * dp * m + dd * p * dm + d * dp * dm))
    return value, slope, curve


@numba.njit
def _guess_coefficients(threshold):
    """alpha / (lambda F) and beta / length^2 of the guess ln MTF(f) ~ -alpha f - beta f^2,
    each exact where its factor alone sets f50: alpha nu_c = ln(1/c) with D(nu_c) = c, and
    beta x_c^2 = ln(1/c) with sinc(x_c) = c (nu_c = 0.404, x_c = 0.603 for c = 0.5). Both
    crossings are bisected once per call: D and sinc fall monotonically on [0, 1]."""
    lo_d, hi_d, lo_s, hi_s = 0.0, 1.0, 0.0, 1.0
    for _ in range(60):
        nu = 0.5 * (lo_d + hi_d)
        if (2.0 / PI) * (math.acos(nu) - nu * math.sqrt((1.0 - nu) * (1.0 + nu))) > threshold:
            lo_d = nu
        else:
            hi_d = nu
        x = 0.5 * (lo_s + hi_s)
        if math.sin(PI * x) / (PI * x) > threshold:
            lo_s = x
        else:
            hi_s = x
    log_c = math.log(1.0 / threshold)
    return log_c / lo_d, log_c / (lo_s * lo_s), log_c


@numba.njit(inline="always")
def _f50_halley(lambda_f, aperture, blur, threshold, rtol, alpha_per_lambda_f,
                beta_per_length2, log_c):
    """The first f with MTF(f) = threshold, and the number of MTF evaluations it took."""
    hi = 1.0 / lambda_f
    hi = min(hi, 1.0 / aperture)
    if blur > 0.0:
        hi = min(hi, 1.0 / blur)
    lo = 0.0
    # The guess: alpha f + beta f^2 = ln(1/c), the stable root of the quadratic.
    alpha = alpha_per_lambda_f * lambda_f
    beta = beta_per_length2 * (aperture * aperture + blur * blur)
    f = 2.0 * log_c / (alpha + math.sqrt(alpha * alpha + 4.0 * beta * log_c))
    if not (lo < f < hi):
        f = 0.5 * hi
    evaluations = 0
    for _ in range(200):
        g, dg, d2g = _mtf3(f, lambda_f, aperture, blur)
        evaluations += 1
        g -= threshold
        if g > 0.0:
            lo = f
        else:
            hi = f
        denominator = 2.0 * dg * dg - g * d2g
        step = 2.0 * g * dg / denominator if denominator != 0.0 else math.nan
        if abs(step) <= rtol * f:  # converged (False for NaN)
            return f - step, evaluations
        x = f - step
        if not (lo < x < hi):  # left the bracket, or NaN: bisect
            x = lo + 0.5 * (hi - lo)
        if hi - lo <= rtol * lo:
            return x, evaluations
        f = x
    return f, evaluations


@numba.njit(inline="always")
def _accurate_start(lambda_f, aperture, blur, coefficients, degree):
    """The core's start_guess for one wavelength, threshold 1/2 and no jitter (cycles/mm)."""
    d = lambda_f / NU50
    p = aperture / X50
    m = blur / X50
    r = 1.0 / math.sqrt(d * d + p * p + m * m)
    pr, mr = p * r, m * r
    w = (pr - mr) * (pr + mr)
    a, z = 2.0 * (d * r) - 1.0, w * w
    total = 0.0
    end = coefficients.shape[0]
    for i in range(degree, -1, -1):  # Horner in a over the rows, each by Horner in z
        length = (degree - i) // 2 + 1
        start = end - length
        row = 0.0
        for j in range(end - 1, start - 1, -1):
            row = row * z + coefficients[j]
        end = start
        total = total * a + row
    return r * total


@numba.njit(inline="always")
def _f50_core_algorithm(lambda_f, aperture, blur, threshold, rtol, coefficients, degree):
    """f50 as the core solves it at threshold 1/2: safeguarded Halley from the accurate start,
    stopping on the core's estimate of the error left; and the MTF evaluations it took."""
    hi = 1.0 / max(lambda_f, aperture, blur)
    lo = 0.0
    f = _accurate_start(lambda_f, aperture, blur, coefficients, degree)
    if not (lo < f < hi):
        f = 0.5 * hi
    step_rtol = (0.1 * rtol) ** (1.0 / 3.0)
    previous = hi - lo
    evaluations = 0
    for _ in range(200):
        g, dg, d2g = _mtf3(f, lambda_f, aperture, blur)
        evaluations += 1
        g -= threshold
        if g == 0.0:
            return f, evaluations
        if g > 0.0:
            lo = f
        else:
            hi = f
        denominator = 2.0 * dg * dg - g * d2g
        step = -2.0 * g * dg / denominator if denominator != 0.0 else math.nan
        ad = abs(step)
        if ad <= step_rtol * f and ad * (ad / previous) ** 2 <= 0.1 * rtol * f:  # converged
            return min(max(f + step, lo), hi), evaluations
        x = f + step
        if not (lo < x < hi):  # left the bracket, or NaN: bisect
            x = lo + 0.5 * (hi - lo)
        if hi - lo <= rtol * lo:
            return x, evaluations
        previous = abs(x - f)
        f = x
    return f, evaluations


@numba.njit(parallel=True)
def evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor_area_mm2,
             read_noise_e, shake_deg_per_s, k_e_per_lux_s_m2=DEFAULT_ELECTRONS_PER_LUX_S_M2,
             snr_db=30.0, reflectance=0.4, wavelength_nm=550.0, threshold=0.5, rtol=1e-14,
             same_algorithm=False, start_coefficients=START_COEFFICIENTS,
             start_degree=START_DEGREE):
    """t_mpe_s, f50_cyc_per_mm, epc and status (uint8) for 1-D arrays of equal length.

    ``same_algorithm``: f50 by the core's algorithm (threshold 1/2 only), see the module."""
    n = illuminance_lux.shape[0]
    t_out = np.empty(n)
    f50_out = np.empty(n)
    epc_out = np.empty(n)
    status = np.empty(n, dtype=np.uint8)
    if same_algorithm and threshold != 0.5:
        raise ValueError("same_algorithm: the accurate start holds at threshold 0.5 only")
    root_s = 10.0 ** (snr_db / 20.0)
    alpha, beta, log_c = _guess_coefficients(threshold)
    for i in numba.prange(n):
        pitch = pixel_pitch_um[i]
        # The reference's product, in its order (factors of exactly 1 and /4 change nothing).
        rate = (illuminance_lux[i] * reflectance * k_e_per_lux_s_m2 * pitch * pitch * 1e-12
                / 4.0 / f_number[i] / f_number[i])
        if not rate >= SMALLEST_NORMAL:
            t_out[i] = math.inf
            f50_out[i] = math.nan
            epc_out[i] = math.nan
            status[i] = UNREACHABLE
            continue
        electrons = root_s / 2.0 * (root_s + math.hypot(root_s, 2.0 * read_noise_e[i]))
        t = electrons / rate
        t_out[i] = t
        angle = shake_deg_per_s[i] * DEG * t
        if not angle < HALF_PI:
            f50_out[i] = 0.0
            epc_out[i] = 0.0
            status[i] = BLUR_UNBOUNDED
            continue
        blur = focal_length_mm[i] * math.tan(angle)
        if same_algorithm:
            f, _ = _f50_core_algorithm(wavelength_nm * 1e-6 * f_number[i], pitch * 1e-3, blur,
                                       threshold, rtol, start_coefficients, start_degree)
        else:
            f, _ = _f50_halley(wavelength_nm * 1e-6 * f_number[i], pitch * 1e-3, blur,
                               threshold, rtol, alpha, beta, log_c)
        f50_out[i] = f
        epc_out[i] = 4.0 * sensor_area_mm2[i] * f * f
        status[i] = OK
    return t_out, f50_out, epc_out, status


@numba.njit(parallel=True)
def halley_evaluations(pixel_pitch_um, f_number, blur_mm, wavelength_nm=550.0, threshold=0.5,
                       rtol=1e-14, same_algorithm=False, start_coefficients=START_COEFFICIENTS,
                       start_degree=START_DEGREE):
    """MTF evaluations per point of the f50 solver (for the benchmarks' extra_info)."""
    n = pixel_pitch_um.shape[0]
    out = np.empty(n, dtype=np.int64)
    alpha, beta, log_c = _guess_coefficients(threshold)
    for i in numba.prange(n):
        lambda_f, aperture = wavelength_nm * 1e-6 * f_number[i], pixel_pitch_um[i] * 1e-3
        if same_algorithm:
            out[i] = _f50_core_algorithm(lambda_f, aperture, blur_mm[i], threshold, rtol,
                                         start_coefficients, start_degree)[1]
        else:
            out[i] = _f50_halley(lambda_f, aperture, blur_mm[i], threshold, rtol, alpha, beta,
                                 log_c)[1]
    return out
