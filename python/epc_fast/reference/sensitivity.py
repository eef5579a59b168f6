"""The NumPy reference of what limits a design and how sensitive it is: each MTF factor's share
of the loss at f50, and the elasticity d ln EPC / d ln theta of every parameter.

Every function carries the same name as its C++ counterpart in
``cpp/include/epc_fast/sensitivity.h``; the core is tested against this module, and this module
against 40-digit mpmath central differences (tests/test_sensitivity.py).

**Shares.** At f50 the system MTF is c, so ln D + ln P + ln M + ln J + ln A + ln(D_W/D) +
ln H + ln(L/D) = ln c: the share of a factor is ln MTF_i(f50) / ln MTF_sys(f50) (= ln c at the
root), and the eight shares sum to 1. The binned pixel P_k is the pixel's share; a burst's
alignment residual A, the wavefront error's ATF (D_W the aberrated diffraction MTF), denoising's
H and a lens table's L against the aberration-free D have their own. Denoising's target s g puts d ln g / d ln sigma on T_MPE's d ln T / d ln s.

**Elasticities.** EPC = 4 S f50^2, so d ln EPC / d ln theta = d ln S / d ln theta +
2 d ln f50 / d ln theta. f50 is defined by ln MTF(f50; theta) = ln c; differentiating it,

    d ln f50 / d ln theta = (d ln MTF / d ln theta) / A,   A = -d ln MTF / d ln f > 0,

both at f50 (A is the MTF's log-slope the solvers use). A parameter reaches the MTF directly
(the f-number and the wavelength through diffraction, the pitch and the fill factor through the
pixel aperture, the focal length through the blur, the jitter, the threshold c) and through
T_MPE, which sets the blur angle. T_MPE is the positive root of

    Q(T) = r^2 w T^2 - s (r + D) T - s sigma_r^2 = 0,   w = 1 - s u^2,

so d ln T / d ln x = -x dQ/dx / (T dQ/dT). With e = r T the electrons and the positive
``spread`` = e + D T + 2 sigma_r^2 (T dQ/dT / s, written with Q = 0 so that nothing cancels):

    d ln T / d ln r       = -(e + 2 D T + 2 sigma_r^2) / spread
    d ln T / d ln D       = D T / spread
    d ln T / d ln sigma_r = 2 sigma_r^2 / spread
    d ln T / d ln s       = (u^2 e^2 + e + D T + sigma_r^2) / spread
    d ln T / d ln u       = 2 u^2 e^2 / spread

Every one is a ratio of sums of positive terms. With binning and bursts, T_MPE is that of the
output pixel of the burst (epc_fast.reference.model.binned_pixels): its rate k^2 r, dark
current k^2 D, read noise sigma_r sqrt(n k^2) or sigma_r sqrt(n), PRNU u / k, each proportional
to its input, so the same log-slopes hold with these values; the blur angle is divided by n as
by the stabilisation. binning, frames, lens and binning_readout are whole numbers: they have
no elasticity (NaN).

With a lens table, L(f) takes the place of D(f) D_W(f)/D(f): its log-slope f L'/L is the
optics' slope in A, and the f-number and the wavelength no longer reach the MTF (L is the
table's alone): the f-number moves only the light, through the rate, and the wavelength nothing.

An elasticity is theta times the partial
derivative of ln EPC, all other parameters of docs/model.md, "Quantities, units and defaults"
held: with a pixel count the pitch's includes the area N p^2, with a sensor area it does not.
"""

from __future__ import annotations

import math

import numpy as np

from ..elasticity_outputs import ELASTICITY_PARAMETERS
from ..outputs import SHARE_NAMES
from ..status import Status
from .model import binned_pixels, burst_read_noise_e, mtf_diffraction, scaled_product, sinpi
from .cfa import demosaic_log_factor
from .lens import lens_log_factor, mtf_lens
from .optics import SHANNON_W0, denoise_log_factor, noise_gain_log_slope

__all__ = [
    "ZETA_EVEN",
    "log_sinc",
    "sinc_log_slope",
    "diffraction_loss",
    "diffraction_log_slope_numerator",
    "log_mtf_diffraction",
    "aberration_log_factor",
    "mtf_log_factors",
    "mtf_loss_shares",
    "t_mpe_log_slopes",
    "blur_angle_log_slope",
    "field_angle_rate_log_slope",
    "epc_elasticities",
    "sensitivity_points",
    "PINNED_RTOL",
]



#: zeta(2), zeta(4), ..., zeta(30), rounded to float64 (tests/test_sensitivity.py checks them
#: against mpmath.zeta): the coefficients of the series of ln sinc.
ZETA_EVEN = (
    1.6449340668482264, 1.0823232337111381, 1.0173430619844492, 1.0040773561979444,
    1.000994575127818, 1.000246086553308, 1.0000612481350588, 1.0000152822594086,
    1.000003817293265, 1.0000009539620338, 1.0000002384505027, 1.000000059608189,
    1.0000000149015549, 1.000000003725334, 1.0000000009313275,
)

#: Below this y the series of ln sinc are used: their 15 terms reach 4^-30 = 1e-18 of the first
#: at y = 1/4; above it the direct formulas lose at most 3 bits to cancellation.
SERIES_BELOW = 0.25
#: nm per mm: mtf_diffraction(nu, _NM_PER_MM, 1) is D at nu itself.
_NM_PER_MM = 1e6


def _even_series(y, coefficients):
    """sum_k coefficients[k] y^(2k + 2), by Horner in y^2."""
    t = np.asarray(y, dtype=np.float64) ** 2
    total = np.zeros_like(t)
    for c in reversed(coefficients):
        total = (total + c) * t
    return total


def log_sinc(y):
    """1: ln sinc(y) for 0 <= y < 1; -sum_k zeta(2k) y^(2k) / k below :data:`SERIES_BELOW`
    (where ln of a value near 1 would lose its digits)."""
    y = np.asarray(y, dtype=np.float64)
    series = -_even_series(y, [z / (k + 1) for k, z in enumerate(ZETA_EVEN)])
    with np.errstate(divide="ignore", invalid="ignore"):
        direct = np.log(sinpi(y) / (np.pi * y))
    return np.where(y < SERIES_BELOW, series, direct)


def sinc_log_slope(y):
    """1: y d ln sinc(y) / dy = pi y cot(pi y) - 1 for 0 <= y < 1; -2 sum_k zeta(2k) y^(2k)
    below :data:`SERIES_BELOW` (where the two terms cancel)."""
    y = np.asarray(y, dtype=np.float64)
    series = -2.0 * _even_series(y, list(ZETA_EVEN))
    with np.errstate(divide="ignore", invalid="ignore"):
        direct = np.pi * y * sinpi(0.5 - y) / sinpi(y) - 1.0
    return np.where(y < SERIES_BELOW, series, direct)


def diffraction_loss(nu):
    """1: 1 - D(nu), the diffraction MTF's loss; (2/pi) (asin nu + nu sqrt(1 - nu^2)) up to
    nu = 1/2 (no cancellation where D is near 1), 1 - D above, 1 past the cut-off."""
    v = np.minimum(np.asarray(nu, dtype=np.float64), 1.0)
    low = (2.0 / np.pi) * (np.arcsin(np.minimum(v, 0.5)) + v * np.sqrt((1.0 - v) * (1.0 + v)))
    return np.where(v <= 0.5, low, 1.0 - mtf_diffraction(v, _NM_PER_MM, 1.0))  # nu = f 1 mm 1


def diffraction_log_slope_numerator(nu):
    """1: nu dD/dnu = -(4/pi) nu sqrt(1 - nu^2) below the cut-off, 0 past it."""
    v = np.minimum(np.asarray(nu, dtype=np.float64), 1.0)
    return -(4.0 / np.pi) * v * np.sqrt((1.0 - v) * (1.0 + v))


def log_mtf_diffraction(value, loss):
    """1: ln D, from D and its loss 1 - D (:func:`diffraction_loss`; both summed over a
    spectrum with its weights): log1p(-loss) where the loss is below 1/2 (it keeps a small
    loss's digits), ln D elsewhere (D's own digits, down to the cut-off)."""
    value = np.asarray(value, dtype=np.float64)
    loss = np.asarray(loss, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(loss < 0.5, np.log1p(-np.minimum(loss, 0.5)), np.log(value))


def mtf_log_factors(f_cyc_per_mm, f_number, pixel_pitch_um, fill_factor, blur_mm, jitter_um,
                    wavelengths_nm, weights, binning=1.0, alignment_error_um=0.0, frames=1.0,
                    wavefront_rms_waves=0.0, denoise_sigma_px=0.0, lens=0.0, lens_tables=None,
                    demosaic_table=None):
    """1: (ln D, ln P_k, ln M, ln J, ln A, ln(D_W/D), ln H, ln(L/D), ln M_dem) at f, and
    (nu dD/dnu / D, f dlnP_k/df, y_m dlnM/dy_m, y_a dln sinc(y_a)/dy_a, f dln(D_W/D)/df,
    W dlnD_W/dW, f dlnH/df, sigma dlnH/dsigma, f dlnM_dem/df): each factor's log and the log-slopes the elasticities need,
    the fourth the pixel's own aperture y_a = sqrt(a) p f alone (what the fill factor moves; the
    binned pixel adds its array factor sinc(k p f) / sinc(p f) to P), the last four the
    wavefront error's (:func:`aberration_log_factor`) and denoising's
    (:func:`epc_fast.reference.optics.denoise_log_factor`), 0 where they are off.
    ``wavelengths_nm`` and ``weights`` as in :func:`epc_fast.reference.mtf_system` (a
    per-point wavelength array with weight 1 for a monochromatic scene). With ``lens_tables``,
    ln(L/D) is the lens table's (:func:`epc_fast.reference.lens.lens_log_factor`) and the first
    slope is the optics' own, f L'/L (0 for ln(L/D) without tables). With ``demosaic_table``,
    the demosaicker's (:func:`epc_fast.reference.cfa.demosaic_log_factor`), 0 without."""
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    loss = 0.0
    slope_numerator = 0.0
    value = 0.0
    for lam, w in zip(wavelengths_nm, weights):
        nu = f * (np.asarray(lam) * 1e-6) * f_number
        loss = loss + w * diffraction_loss(nu)
        slope_numerator = slope_numerator + w * diffraction_log_slope_numerator(nu)
        value = value + w * mtf_diffraction(f, lam, f_number)
    y_pixel = np.sqrt(fill_factor) * (pixel_pitch_um * 1e-3) * f
    y_motion = np.asarray(blur_mm, dtype=np.float64) * f
    sigma_f = jitter_um * 1e-3 * f
    residual_f = alignment_error_um * np.sqrt(1.0 - 1.0 / np.asarray(frames, np.float64)) * 1e-3 * f
    binned = np.asarray(binning) > 1.0
    y_whole = np.where(binned, binning * (pixel_pitch_um * 1e-3) * f, 0.0)
    y_one = np.where(binned, (pixel_pitch_um * 1e-3) * f, 0.0)
    log_pixel = log_sinc(y_pixel) + np.where(binned, log_sinc(y_whole) - log_sinc(y_one), 0.0)
    slope_fill = sinc_log_slope(y_pixel)
    slope_pixel = slope_fill + np.where(binned, sinc_log_slope(y_whole) - sinc_log_slope(y_one),
                                        0.0)
    zero = np.zeros_like(f)
    aberration = (zero, zero, zero)
    if np.any(np.asarray(wavefront_rms_waves) != 0.0):
        aberration = aberration_log_factor(f, f_number, wavelengths_nm, weights,
                                           wavefront_rms_waves, value, slope_numerator)
    denoise = (zero, zero, zero)
    if np.any(np.asarray(denoise_sigma_px) != 0.0):
        denoise = denoise_log_factor(f, denoise_sigma_px, pixel_pitch_um * np.asarray(binning))
    log_lens, optics_slope = zero, slope_numerator / value
    log_d = log_mtf_diffraction(value, loss)
    if lens_tables is not None:
        log_lens, optics_slope = lens_log_factor(f, lens, lens_tables, value)
        # where the aberration-free D is 0 at f50 (a table that passes frequencies beyond the
        # cut-off at the point's f-number: a table of another aperture), ln(L/D) is undefined:
        # the table's whole ln L is the lens's share and diffraction's is 0
        past = np.broadcast_to(value, np.shape(log_lens)) == 0.0
        log_lens = np.where(past, np.log(mtf_lens(f, lens, lens_tables)), log_lens)
        log_d = np.where(past, 0.0, log_d)
    demosaic = (zero, zero)
    if demosaic_table is not None:
        demosaic = demosaic_log_factor(f, pixel_pitch_um * np.asarray(binning), demosaic_table)
    logs = (log_d, log_pixel, log_sinc(y_motion),
            -2.0 * np.pi**2 * sigma_f * sigma_f, -2.0 * np.pi**2 * residual_f * residual_f,
            aberration[0], denoise[0], log_lens, demosaic[0])
    slopes = (optics_slope, slope_pixel, sinc_log_slope(y_motion), slope_fill,
              aberration[1], aberration[2], denoise[1], denoise[2], demosaic[1])
    return logs, slopes


def aberration_log_factor(f_cyc_per_mm, f_number, wavelengths_nm, weights, wavefront_rms_waves,
                          diffraction_value, diffraction_slope_numerator):
    """1: (ln(D_W / D), f d ln(D_W / D) / df, W d ln D_W / dW) at f: the wavefront error's
    factor of the diffraction MTF, D_W = sum_i w_i D_i ATF_i against D = sum_i w_i D_i (given as
    ``diffraction_value``, with ``diffraction_slope_numerator`` = sum_i w_i nu_i dD_i/dnu): its
    log (its share's numerator), its log-slope in f, and in W. D_W - D = -sum_i w_i D_i a (1 -
    4 (nu_i - 1/2)^2), a = (W/0.18)^2, is formed without cancellation, and so its log1p."""
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    a = (np.asarray(wavefront_rms_waves, dtype=np.float64) / SHANNON_W0) ** 2
    deficit, slope_numerator = 0.0, 0.0  # D - D_W, and sum_i w_i nu_i d(D_i ATF_i)/dnu
    for lam, w in zip(wavelengths_nm, weights):
        nu = np.minimum(f * (np.asarray(lam) * 1e-6) * f_number, 1.0)
        d_i = mtf_diffraction(f, lam, f_number)
        atf = 1.0 - a * (1.0 - 4.0 * (nu - 0.5) ** 2)
        deficit = deficit + w * d_i * a * (1.0 - 4.0 * (nu - 0.5) ** 2)
        slope_numerator = slope_numerator + w * (diffraction_log_slope_numerator(nu) * atf
                                                 + d_i * 8.0 * a * nu * (nu - 0.5))
    aberrated = diffraction_value - deficit
    with np.errstate(divide="ignore", invalid="ignore"):
        log_factor = np.log1p(-deficit / diffraction_value)
        slope = slope_numerator / aberrated - diffraction_slope_numerator / diffraction_value
        w_slope = -2.0 * deficit / aberrated
    # a point without a wavefront error has the factor 1 (its log and slopes 0), even where D
    # is 0 at f (0/0 otherwise)
    off = a == 0.0
    return (np.where(off, 0.0, log_factor), np.where(off, 0.0, slope),
            np.where(off, 0.0, w_slope))


#: The relative distance of sum_i ln MTF_i(f50) from ln c beyond which f50 is a factor's zero to
#: within rounding (a threshold of 1e-6 and less): that factor is "pinned".
PINNED_RTOL = 1e-3


def mtf_loss_shares(log_factors, mtf_threshold):
    """1: each factor's share ln MTF_i / sum_i ln MTF_i of the loss at f50 (diffraction, pixel,
    motion, jitter, alignment); the sum is ln MTF_sys(f50) = ln c at the root, so the shares sum to 1.

    With a threshold so small that f50 is a factor's zero to within rounding, the logs at the
    computed f50 do not add up to ln c (one may be -inf or NaN): the factor with the least log
    takes ln c less the others', and the shares divide by ln c.
    """
    logs = np.stack(np.broadcast_arrays(*log_factors)).astype(np.float64)
    ln_c = np.log(np.asarray(mtf_threshold, dtype=np.float64))
    total = logs.sum(axis=0)
    with np.errstate(invalid="ignore"):
        pinned = ~(np.abs(total - ln_c) <= PINNED_RTOL * np.abs(ln_c))
    least = np.argmin(np.where(np.isnan(logs), -np.inf, logs), axis=0)
    rows = np.arange(logs.shape[0])[:, None]
    is_least = rows == least
    others = np.where(is_least, 0.0, logs).sum(axis=0)
    logs = np.where(pinned & is_least, ln_c - others, logs)
    total = np.where(pinned, ln_c, total)
    return tuple(logs / total)


def t_mpe_log_slopes(electrons, t_mpe_s, read_noise_e, dark_current_e_per_s, prnu):
    """1: d ln T_MPE / d ln x for x = the rate r, dark current D, read noise sigma_r, the
    target s = 10^(snr_db/10) and the PRNU u (module docstring), as a dict keyed ``rate``,
    ``dark``, ``read``, ``target``, ``prnu``. Each is written in the ratios q = D T / e and
    v = 2 sigma_r^2 / e, so that a huge dark term gives its limit, not inf / inf."""
    e = np.asarray(electrons, dtype=np.float64)
    q = dark_current_e_per_s * t_mpe_s / e
    v = 2.0 * read_noise_e**2 / e
    ue = prnu * prnu * e
    inverse = 1.0 / (1.0 + q + v)
    # q / (1 + q + v), as 1 / (1 + (1 + v) / q): 1 at q = inf, 0 at q = 0
    with np.errstate(divide="ignore"):
        dark = np.where(q > 0, 1.0 / (1.0 + (1.0 + v) / q), 0.0)
    return {"rate": -1.0 - dark, "dark": dark, "read": v * inverse,
            "target": 1.0 - 0.5 * v * inverse + ue * inverse, "prnu": 2.0 * ue * inverse}


def blur_angle_log_slope(blur_mm, focal_length_mm, shake_deg_per_s, stabilization, t_mpe_s):
    """1: d ln b / d ln alpha = alpha (1 + tan^2 alpha) / tan alpha for the blur angle alpha
    (1 at alpha = 0, growing without bound towards pi/2), with tan alpha = b / f_L."""
    angle = scaled_product([shake_deg_per_s, np.pi / 180.0, t_mpe_s], [stabilization])
    t = np.asarray(blur_mm, dtype=np.float64) / focal_length_mm
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = angle * (1.0 + t * t) / t
    return np.where(t > 0, slope, 1.0)


def field_angle_rate_log_slope(field_angle_deg):
    """1: d ln r / d ln theta = -4 theta tan theta (the cos^4 falloff), theta in radians;
    cos theta as sin(90 deg - abs(theta)), as :func:`epc_fast.reference.electron_rate` does."""
    theta = np.deg2rad(np.abs(field_angle_deg))
    return -4.0 * theta * np.sin(theta) / np.sin(np.deg2rad(90.0 - np.abs(field_angle_deg)))


def epc_elasticities(q, size_is_pixel_count, f50_cyc_per_mm, electrons, t_mpe_s, blur_mm,
                     wavelengths_nm, weights, lens_tables=None, demosaic_table=None):
    """1: d ln EPC / d ln theta for every parameter of :data:`ELASTICITY_PARAMETERS`, a dict
    of arrays, at points whose status is OK (f50 > 0); ``q`` holds the parameters by name (as
    :func:`epc_fast.reference.evaluate_points` does), the rest are the model's outputs there.
    """
    binning, frames = q["binning"], q["frames"]
    logs, slopes = mtf_log_factors(
        f50_cyc_per_mm, q["f_number"], q["pixel_pitch_um"], q["fill_factor"], blur_mm,
        q["jitter_um"], wavelengths_nm, weights, binning, q["alignment_error_um"], frames,
        q["wavefront_rms_waves"], q["denoise_sigma_px"], q["lens"], lens_tables, demosaic_table)
    g_fill = slopes[3]
    g_ab, w_ab, g_h, s_h, g_dm = slopes[4:]
    slopes = slopes[:3]
    # where f50 is a factor's zero to within rounding (a tiny threshold), its log-slope is not
    # finite: every slope over |that slope|, the limit as it goes to -infinity (f50 follows the
    # zero); the threshold's own term, -1, goes to 0 with the others
    slopes = np.stack(np.broadcast_arrays(*slopes)).astype(np.float64)
    infinite = ~np.isfinite(slopes)
    limit = infinite.any(axis=0)
    k = np.argmax(infinite, axis=0)
    scaled = np.where(np.arange(3)[:, None] == k, -1.0, 0.0)
    g_d, g_p, g_m = np.where(limit, scaled, slopes)
    # the fill factor's slope in that limit: -1 where the pixel's own aperture is the zero
    g_fill = np.where(limit, np.where((binning == 1) & ~np.isfinite(g_fill), -1.0, 0.0), g_fill)
    log_j = np.where(limit, 0.0, logs[3])
    log_a = np.where(limit, 0.0, logs[4])
    threshold_term = np.where(limit, 0.0, 1.0)
    # the wavefront error's and denoising's slopes are finite: 0 in that limit
    g_ab, w_ab, g_h, s_h, g_dm = (np.where(limit, 0.0, g) for g in (g_ab, w_ab, g_h, s_h, g_dm))
    # -d ln MTF / d ln f > 0
    a_slope = -(g_d + g_ab + g_p + g_h + g_dm + g_m + 2.0 * (log_j + log_a))
    # T_MPE of the output pixel of the burst (its inputs each proportional to the parameter's)
    t = t_mpe_log_slopes(electrons, t_mpe_s,
                         burst_read_noise_e(q["read_noise_e"], binning, frames,
                                            q["binning_readout"]),
                         q["dark_current_e_per_s"] * binned_pixels(binning), q["prnu"] / binning)
    # d ln MTF / d ln alpha: the motion factor's slope through the blur angle (T/n a frame)
    mu = g_m * blur_angle_log_slope(blur_mm, q["focal_length_mm"], q["shake_deg_per_s"],
                                    q["stabilization"] * frames, t_mpe_s)
    via_rate = mu * t["rate"]
    snr_scale = q["snr_db"] * (math.log(10.0) / 10.0)  # d ln s / d ln snr_db
    zero = np.zeros_like(a_slope)
    # F d ln MTF / dF = lambda d ln MTF / d lambda: diffraction's and the ATF's (functions of
    # nu = f lambda F), none for a lens table
    optics = zero if lens_tables is not None else g_d + g_ab
    mtf_slopes = {
        "illuminance_lux": via_rate,
        "pixel_pitch_um": g_p + g_h + g_dm + 2.0 * via_rate,
        "f_number": optics - 2.0 * via_rate,
        "focal_length_mm": g_m,
        "size": zero,
        "reflectance": via_rate,
        "lens_transmittance": via_rate,
        "field_angle_deg": via_rate * field_angle_rate_log_slope(q["field_angle_deg"]),
        "fill_factor": 0.5 * g_fill + via_rate,
        "electrons_per_lux_s_m2": via_rate,
        "read_noise_e": mu * t["read"],
        "dark_current_e_per_s": mu * t["dark"],
        "prnu": mu * t["prnu"],
        "full_well_e": zero,
        "snr_db": mu * t["target"] * snr_scale,
        "shake_deg_per_s": mu,
        "stabilization": -mu,
        "jitter_um": 2.0 * log_j,
        "wavelength_nm": optics,
        "mtf_threshold": zero - threshold_term,
        "binning": zero + np.nan,
        "frames": zero + np.nan,
        "alignment_error_um": 2.0 * log_a,
        # 0 where the term is off (W d ln ATF / dW and sigma d ln H / d sigma vanish with W and
        # sigma); denoising moves the MTF and, through the target s g, T_MPE and the blur
        "wavefront_rms_waves": w_ab,
        "denoise_sigma_px": s_h + mu * t["target"] * noise_gain_log_slope(q["denoise_sigma_px"]),
        "lens": zero + np.nan,
        # the CFA's transmittance is the rate's, its noise gain the target's s g
        "cfa_transmittance": via_rate,
        "color_noise_gain": mu * t["target"],
        "binning_readout": zero + np.nan,
    }
    area = {"size": 1.0, "pixel_pitch_um": 2.0 if size_is_pixel_count else 0.0}
    return {name: area.get(name, 0.0) + 2.0 * mtf_slopes[name] / a_slope
            for name in ELASTICITY_PARAMETERS}


def sensitivity_points(p, size_is_pixel_count, wavelengths_nm, weights, result, shares=True,
                       elasticities=True, lens_tables=None, demosaic_table=None):
    """The shares and elasticities of 1-D points, from their :func:`epc_fast.reference.
    evaluate_points` ``result``: one ``share_<name>`` per
    :data:`epc_fast.outputs.SHARE_NAMES` entry (each 1-D) and ``elasticities`` (one row per
    :data:`ELASTICITY_PARAMETERS` entry), as asked for.

    Only OK points have them; elsewhere they are NaN, but where the blur is unbounded (f50 = 0,
    EPC = 0: motion takes all of the loss) motion's share is 1 and the others 0. ``p``,
    ``wavelengths_nm``, ``weights``, ``lens_tables`` and ``demosaic_table`` as
    :func:`epc_fast.reference.evaluate_points` takes them.
    """
    status = result["status"]
    ok = status == Status.OK
    # non-OK points compute on the first OK point's values (or stand-ins), then masked
    stand = {name: np.where(ok, v, 1.0 if name != "mtf_threshold" else 0.5)
             for name, v in p.items()}
    f50 = np.where(ok, result["f50_cyc_per_mm"], 1.0)
    blur = np.where(ok, result["blur_mm"], 0.0)
    electrons = np.where(ok, result["electrons"], 1.0)
    t_mpe = np.where(ok, result["t_mpe_s"], 1.0)
    if wavelengths_nm is None:
        wavelengths, spectral_weights = [stand["wavelength_nm"]], [1.0]
    else:
        wavelengths, spectral_weights = list(wavelengths_nm), list(weights)
    out = {}
    with np.errstate(all="ignore"):
        if shares:
            logs, _ = mtf_log_factors(f50, stand["f_number"], stand["pixel_pitch_um"],
                                      stand["fill_factor"], blur, stand["jitter_um"],
                                      wavelengths, spectral_weights, stand["binning"],
                                      stand["alignment_error_um"], stand["frames"],
                                      stand["wavefront_rms_waves"], stand["denoise_sigma_px"],
                                      stand["lens"], lens_tables, demosaic_table)
            unbounded = status == Status.BLUR_UNBOUNDED
            for name, share in zip(SHARE_NAMES, mtf_loss_shares(logs, stand["mtf_threshold"])):
                limit = 1.0 if name == "motion" else 0.0
                out[f"share_{name}"] = np.where(ok, share, np.where(unbounded, limit, np.nan))
        if elasticities:
            values = epc_elasticities(stand, size_is_pixel_count, f50, electrons, t_mpe, blur,
                                      wavelengths, spectral_weights, lens_tables,
                                      demosaic_table)
            out["elasticities"] = np.stack(
                [np.where(ok, np.broadcast_to(values[name], ok.shape), np.nan)
                 for name in ELASTICITY_PARAMETERS])
    return out
