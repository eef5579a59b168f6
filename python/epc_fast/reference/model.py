"""The NumPy reference implementation of the EPC model, readable as the spec (docs/model.md).

Every function is one formula of docs/model.md, written with whole-array NumPy expressions, and
carries the same name as its C++ counterpart in ``cpp/include/epc_fast/``. The C++ core is
tested against this module; this module is tested against closed forms and the mpmath golden
values. It favours clarity over speed: f50 is bisected until the bracket cannot shrink any
further in float64, whatever tolerance the core was asked for.

Units: lengths in the MTF are in mm, spatial frequencies in cycles/mm, time in seconds.
"""

from __future__ import annotations

import numpy as np

from ..status import Cause, Status
from .cfa import mtf_demosaic
from .lens import lens_bracket, mtf_lens
from .mtf import __all__ as _mtf_names
from .mtf import (gaussian_blur_mm, mtf_alignment, mtf_binned_pixel, mtf_diffraction, mtf_jitter,
                  mtf_motion, mtf_pixel, sinc, sinpi)
from .optics import mtf_aberration, mtf_denoise, noise_gain_denoise

__all__ = [
    "scaled_product",
    "electron_rate",
    "root_target",
    "prnu_product",
    "prnu_capped",
    "prnu_margin",
    "binned_pixels",
    "burst_read_noise_e",
    "signal_electrons",
    "t_mpe_closed_form",
    "snr_db_at",
    "blur_length_mm",
    *_mtf_names,  # the MTF factors (reference/mtf.py), importable from here as before
    "mtf_system",
    "f50_bracket",
    "f50_bisection",
    "effective_pixel_count",
    "evaluate_points",
]


# --- Photometry and exposure (docs/model.md, "Exposure: T_MPE") ------------------------------

#: The smallest normal float64: a rate below it is no light (see :func:`electron_rate`).
SMALLEST_NORMAL = float(np.finfo(np.float64).tiny)


def scaled_product(factors, divisors=()):
    """The product of ``factors`` over the product of ``divisors``, with no intermediate
    overflow or underflow.

    Each value is split into a mantissa in [0.5, 1) and a power of two (np.frexp); the
    mantissas are multiplied in the order given (a dozen of them stay far inside float64's
    range) and the exponents added, and the two are joined once (np.ldexp). The result rounds
    like the plain product, and is inf or 0 only when the exact value is beyond float64's range.
    """
    mantissa, exponent = np.float64(1.0), 0
    for value in factors:
        m, e = np.frexp(value)
        mantissa, exponent = mantissa * m, exponent + e
    for value in divisors:
        m, e = np.frexp(value)
        mantissa, exponent = mantissa / m, exponent - e
    return np.ldexp(mantissa, exponent)


def electron_rate(illuminance_lux, reflectance, lens_transmittance, field_angle_deg, f_number,
                  electrons_per_lux_s_m2, fill_factor, pixel_pitch_um):
    """e-/s: photo-electron rate of one pixel.

    E = L R tau cos^4(theta) / (4 F^2) lux on the focal plane; r = E K a (p 1e-6 m)^2.
    cos(theta) is evaluated as ``sin(90 deg - |theta|)``, whose argument is exact near 90 deg, so
    the falloff keeps its digits at grazing field angles. The product is a
    :func:`scaled_product`: no factor's size can push an intermediate out of range. A rate below
    the smallest normal float64 (2.2e-308 e-/s) is returned as 0 (no light): it would carry too
    few digits to divide by.
    """
    cos_theta = np.sin(np.deg2rad(90.0 - np.abs(field_angle_deg)))
    cos2 = cos_theta * cos_theta
    rate = scaled_product(
        [illuminance_lux, reflectance, lens_transmittance, cos2, cos2, electrons_per_lux_s_m2,
         fill_factor, pixel_pitch_um, pixel_pitch_um, 1e-12],
        [4.0, f_number, f_number])
    return np.where(rate >= SMALLEST_NORMAL, rate, 0.0)


def _split(a):
    """Veltkamp's split of a into hi + lo, each with at most 26 significant bits."""
    c = 134217729.0 * a  # 2^27 + 1
    hi = c - (c - a)
    return hi, a - hi


def root_target(snr_db, noise_gain=1.0):
    """1: sqrt(s g), s = 10^(snr_db/10), g denoising's noise gain (every noise variance times g:
    :func:`noise_gain_denoise`). sqrt(1) = 1: without denoising, 10^(snr_db/20) bit for bit."""
    return 10.0 ** (np.asarray(snr_db, dtype=np.float64) / 20.0) * np.sqrt(noise_gain)


def prnu_product(prnu, snr_db, noise_gain=1.0):
    """1: u sqrt(s g) = p + e exactly, s = 10^(snr_db/10): (p, e) with e the rounding error of p.

    e comes from Dekker's exact product (the core uses a fused multiply-add); it is kept where
    p is near 1, the only place it matters, and is 0 elsewhere.
    """
    root_s = root_target(snr_db, noise_gain)
    u = np.asarray(prnu, dtype=np.float64)
    p = u * root_s
    near = np.abs(p - 1.0) < 0.5
    with np.errstate(over="ignore", invalid="ignore"):
        u_hi, u_lo = _split(np.where(near, u, 0.0))
        r_hi, r_lo = _split(np.where(near, root_s, 0.0))
        e = ((u_hi * r_hi - p) + u_hi * r_lo + u_lo * r_hi) + u_lo * r_lo
    return p, np.where(near, e, 0.0)


def prnu_capped(prnu, snr_db, noise_gain=1.0):
    """bool: PRNU caps the SNR below the target, u sqrt(s g) >= 1, decided on the exact product
    (exactly, whenever sqrt(s) = 10^(snr_db/20) is a double: 0, 20, 40, ... dB)."""
    p, e = prnu_product(prnu, snr_db, noise_gain)
    return (p > 1.0) | ((p == 1.0) & (e >= 0.0))


def prnu_margin(prnu, snr_db, noise_gain=1.0):
    """1: w = 1 - s g u^2 as (1 - u sqrt(s g))(1 + u sqrt(s g)), from the exact product
    u sqrt(s g): 1 - p is exact near the cap, so w keeps its digits however close it is to 1."""
    p, e = prnu_product(prnu, snr_db, noise_gain)
    return ((1.0 - p) - e) * ((1.0 + p) + e)


def binned_pixels(binning):
    """1: k^2, the pixels a binned output pixel reads as one.

    Binning and bursts (docs/model.md, "Exposure: T_MPE") enter the exposure as one output pixel
    of the burst: rate k^2 r, dark current k^2 D, PRNU u / k, full well n k^2 W over the burst
    (k^2 W a frame), read noise :func:`burst_read_noise_e` and the shake of T/n a frame (the
    stabilisation times n); with k = n = 1 each is its input, bit for bit.
    """
    return binning * binning


def burst_read_noise_e(read_noise_e, binning, frames, binning_readout=0.0):
    """e- rms: the read noise of one output pixel of a burst of n frames, n reads of k^2 pixels
    each (``binning_readout`` 0, digital: sigma_r sqrt(n k^2)) or of one (1, charge: the k x k
    pixels' charge summed before the read, sigma_r sqrt(n))."""
    reads = frames * np.where(np.asarray(binning_readout) == 1.0, 1.0, binned_pixels(binning))
    return read_noise_e * np.sqrt(reads)


def signal_electrons(rate_e_per_s, snr_db, read_noise_e, dark_current_e_per_s, prnu,
                     noise_gain=1.0):
    """e-: the photo-electrons r T_MPE needed to reach ``snr_db``.

    T_MPE is the positive root of r^2 (1 - s u^2) T^2 - s (r + D) T - s sigma_r^2 = 0 with
    s = 10^(snr_db/10). Multiplied by r, with q = 1 + D/r and w = 1 - s u^2
    (:func:`prnu_margin`), the root reads

        r T = q a,   a = sqrt(s) / (2 w) * (sqrt(s) + hypot(sqrt(s), 2 sigma_r sqrt(w) / q))

    which adds only positive terms (no cancellation) and squares nothing; s itself is never
    formed (it under- or overflows beyond 3080 dB from 0 dB). q a is formed as a + a D / r (a
    :func:`scaled_product`), which overflows only when the answer does, and q alone only
    divides (where it overflows, the read-noise term takes its true limit, 0). a >= s >= 1e-300
    inside the domain, so the answer is a normal double. Returns +inf where PRNU caps the SNR
    (:func:`prnu_capped`) and NaN where r = 0.

    Denoising multiplies every noise variance by its noise gain g (:func:`noise_gain_denoise`):
    the target is met after the filter, so s is s g throughout (:func:`root_target`).
    """
    root_s = root_target(snr_db, noise_gain)
    w = prnu_margin(prnu, snr_db, noise_gain)
    capped = prnu_capped(prnu, snr_db, noise_gain)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        q = 1.0 + dark_current_e_per_s / rate_e_per_s
        read_term = 2.0 * read_noise_e * np.sqrt(np.maximum(w, 0.0)) / q
        a = root_s / (2.0 * w) * (root_s + np.hypot(root_s, read_term))
        electrons = a + scaled_product([a, dark_current_e_per_s], [rate_e_per_s])
    electrons = np.where(capped, np.inf, electrons)
    return np.where(rate_e_per_s > 0, electrons, np.nan)


def t_mpe_closed_form(rate_e_per_s, snr_db, read_noise_e, dark_current_e_per_s, prnu,
                      noise_gain=1.0):
    """s: minimum photometric exposure T_MPE, the closed-form root (see :func:`signal_electrons`).

    +inf where the target is unreachable by PRNU or there is no light.
    """
    electrons = signal_electrons(rate_e_per_s, snr_db, read_noise_e, dark_current_e_per_s, prnu,
                                 noise_gain)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = electrons / rate_e_per_s
    return np.where(rate_e_per_s > 0, t, np.inf)


def snr_db_at(t_s, rate_e_per_s, read_noise_e, dark_current_e_per_s, prnu, noise_gain=1.0):
    """dB: SNR after an exposure of ``t_s`` seconds, 20 log10(S / sigma) in electrons, after a
    denoising filter of noise gain g (every variance times g)."""
    signal = rate_e_per_s * t_s
    variance = noise_gain * (signal + dark_current_e_per_s * t_s + read_noise_e**2
                             + (prnu * signal) ** 2)
    return 20.0 * np.log10(signal / np.sqrt(variance))


# --- Blur (docs/model.md, "Blur during the exposure") ----------------------------------------


def blur_length_mm(focal_length_mm, shake_deg_per_s, stabilization, t_mpe_s):
    """mm: blur length f_L tan(omega / k * T_MPE); +inf once the angle reaches pi/2.

    The angle is a :func:`scaled_product`, so that a huge shake over a tiny exposure (or the
    reverse) gives its true size rather than inf * 0. "Reaches" compares with fl(pi/2), which is
    6e-17 below pi/2: an angle of exactly fl(pi/2) counts as unbounded.
    """
    angle_rad = scaled_product([shake_deg_per_s, np.pi / 180.0, t_mpe_s], [stabilization])
    with np.errstate(invalid="ignore"):
        bounded = angle_rad < np.pi / 2
        return np.where(bounded, focal_length_mm * np.tan(np.where(bounded, angle_rad, 0.0)),
                        np.inf)


# --- The system MTF (docs/model.md, "System MTF"): the factors are in mtf.py ------------


def mtf_system(f_cyc_per_mm, f_number, pixel_pitch_um, fill_factor, blur_mm, jitter_um,
               wavelengths_nm, weights, binning=1.0, alignment_error_um=0.0, frames=1.0,
               wavefront_rms_waves=0.0, denoise_sigma_px=0.0, lens=0.0, lens_tables=None,
               demosaic_table=None):
    """1: D(f) P_k(f) M(f) J(f) A(f) H(f), with D = sum_i w_i D_i(f) ATF_i(f) over a spectrum
    (weights sum to 1; ATF_i Shannon's at wavelength i, :func:`mtf_aberration`), P_k the binned
    pixel (:func:`mtf_binned_pixel`; P at k = 1) and H the denoising filter
    (:func:`mtf_denoise`, on the output pitch k p). With ``lens_tables`` (a list of
    :class:`epc_fast.mtf_table.MtfTable`), D is L(f), the table each point's ``lens`` index
    picks (:func:`epc_fast.reference.lens.mtf_lens`): the spectrum plays no part then. With
    ``demosaic_table``, times a Bayer demosaicker's M_dem(f p_out)
    (:func:`epc_fast.reference.cfa.mtf_demosaic`).

    ``wavelengths_nm`` and ``weights`` are 1-D and shared by every point; a monochromatic
    scene passes one wavelength with weight 1. ATF and H enter only calls that have them.
    """
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    aberrated = np.any(np.asarray(wavefront_rms_waves) != 0.0)
    if lens_tables is not None:
        diffraction = mtf_lens(f, lens, lens_tables)
    else:
        diffraction = sum(w * mtf_diffraction(f, lam, f_number)
                          * (mtf_aberration(f, lam, f_number, wavefront_rms_waves)
                             if aberrated else 1.0)
                          for lam, w in zip(wavelengths_nm, weights))
    m = (diffraction * mtf_binned_pixel(f, pixel_pitch_um, fill_factor, binning)
         * mtf_motion(f, blur_mm) * mtf_jitter(f, jitter_um)
         * mtf_alignment(f, alignment_error_um, frames))
    if np.any(np.asarray(denoise_sigma_px) != 0.0):
        m = m * mtf_denoise(f, denoise_sigma_px, pixel_pitch_um * np.asarray(binning))
    if demosaic_table is not None:  # a Bayer sensor's demosaicker, at f p_out
        m = m * mtf_demosaic(f, pixel_pitch_um * np.asarray(binning), demosaic_table)
    return m


# --- The cut-off frequency (docs/model.md, "The cut-off frequency f50") ----------------------


def f50_bracket(f_number, shortest_wavelength_nm, pixel_pitch_um, fill_factor, blur_mm,
                jitter_um, mtf_threshold, binning=1.0, alignment_error_um=0.0, frames=1.0,
                lens_end_cyc_per_mm=None):
    """cycles/mm: f_hi, the end of the bracket [0, f_hi] holding the unique f50.

    The smallest first zero of the factors (diffraction 1/(lambda_min F), or with a lens table
    ``lens_end_cyc_per_mm``, the table's end: :func:`epc_fast.reference.lens.lens_bracket`; the
    pixel
    1/(sqrt(a) p), binned 1/(k p) for k >= 2, which is min(1/(sqrt(a) p), 1/(k p)) there;
    motion 1/b) and, with jitter or a burst's alignment residual, the frequency where their
    Gaussian (:func:`gaussian_blur_mm`) alone falls to the threshold.
    """
    blur_mm = np.asarray(blur_mm, dtype=np.float64)
    gaussian_mm = gaussian_blur_mm(jitter_um, alignment_error_um, frames)
    with np.errstate(divide="ignore"):
        diffraction_zero = (1.0 / (shortest_wavelength_nm * 1e-6 * f_number)
                            if lens_end_cyc_per_mm is None else lens_end_cyc_per_mm)
        pixel_zero = np.where(np.asarray(binning) > 1.0,
                              1.0 / (binning * (pixel_pitch_um * 1e-3)),
                              1.0 / (np.sqrt(fill_factor) * pixel_pitch_um * 1e-3))
        motion_zero = np.where(blur_mm > 0, 1.0 / blur_mm, np.inf)
        jitter_crossing = np.where(
            gaussian_mm > 0,
            np.sqrt(np.log(1.0 / mtf_threshold) / (2.0 * np.pi**2)) / gaussian_mm,
            np.inf)
    return np.minimum(np.minimum(diffraction_zero, pixel_zero),
                      np.minimum(motion_zero, jitter_crossing))


def f50_bisection(mtf, f_hi, mtf_threshold):
    """cycles/mm: the first f with mtf(f) = threshold, by bisection on [0, f_hi].

    ``mtf`` maps an array of frequencies (shaped like ``f_hi``) to MTF values. The bracket
    keeps mtf(lo) > threshold >= mtf(hi) and halves until lo and hi are adjacent floats;
    the midpoint is returned.
    """
    lo = np.zeros_like(f_hi)
    hi = np.array(f_hi, dtype=np.float64)
    while True:
        mid = lo + 0.5 * (hi - lo)
        active = (mid > lo) & (mid < hi)
        if not active.any():
            return lo + 0.5 * (hi - lo)
        above = mtf(mid) > mtf_threshold
        lo = np.where(active & above, mid, lo)
        hi = np.where(active & ~above, mid, hi)


# --- EPC (docs/model.md, "EPC") --------------------------------------------------------------


def effective_pixel_count(sensor_area_mm2, f50_cyc_per_mm):
    """pixels: EPC = 4 S f50^2, S in mm^2 (not capped at the pixel count)."""
    return 4.0 * sensor_area_mm2 * f50_cyc_per_mm**2


# --- All of it, per point --------------------------------------------------------------------


def evaluate_points(p, size_is_pixel_count, wavelengths_nm, weights, valid,
                    lens_tables=None, demosaic_table=None):
    """Evaluate the model on 1-D arrays of equal length.

    Parameters
    ----------
    p : dict of str to ndarray
        Every name of :data:`epc_fast.params.PARAMETER_NAMES` mapped to a 1-D float64 array.
        ``p["size"]`` is a pixel count or a sensor area in mm^2, as ``size_is_pixel_count`` says.
    size_is_pixel_count : bool
    wavelengths_nm, weights : ndarray or None
        A spectrum shared by every point (weights sum to 1), or None for ``p["wavelength_nm"]``.
    valid : ndarray of bool
        Which points have every input inside its domain (:func:`epc_fast.params.in_domain`).
    lens_tables : list of MtfTable, optional
        The call's lens tables (``lens_mtf``): point i's optics MTF is table ``p["lens"][i]``'s
        in place of diffraction (:func:`mtf_system`).
    demosaic_table : MtfTable, optional
        A Bayer sensor's demosaicker's luminance MTF in cycles per output pixel
        (:func:`epc_fast.cfa.demosaic_mtf_table`); the CFA's transmittance and noise gain are
        the columns ``cfa_transmittance`` and ``color_noise_gain``.

    Returns
    -------
    dict of str to ndarray
        ``electron_rate_e_per_s``, ``electrons``, ``t_mpe_s``, ``blur_mm``, ``f50_cyc_per_mm``,
        ``epc``, ``status`` (uint8, :class:`Status`) and ``cause`` (uint8, :class:`Cause`).
        The rate and the electrons are those of one output pixel (k x k pixels) of the whole
        burst.
    """
    # Invalid points are evaluated on harmless stand-in values and masked at the end.
    q = {name: np.where(valid, v, 1.0 if name != "mtf_threshold" else 0.5)
         for name, v in p.items()}
    with np.errstate(all="ignore"):  # extreme but valid points may overflow; statuses tell
        return _evaluate_valid(q, size_is_pixel_count, wavelengths_nm, weights, valid,
                               lens_tables, demosaic_table)


def _evaluate_valid(q, size_is_pixel_count, wavelengths_nm, weights, valid, lens_tables=None,
                    demosaic_table=None):
    k, n = q["binning"], q["frames"]
    pixels = binned_pixels(k)
    rate = electron_rate(q["illuminance_lux"], q["reflectance"], q["lens_transmittance"],
                         q["field_angle_deg"], q["f_number"], q["electrons_per_lux_s_m2"],
                         q["fill_factor"], q["pixel_pitch_um"]) * q["cfa_transmittance"] * pixels
    read_noise = burst_read_noise_e(q["read_noise_e"], k, n, q["binning_readout"])
    prnu = q["prnu"] / k
    # denoising, and a colour sensor's colour correction and demosaicking: every noise
    # variance times g, met after them
    gain = noise_gain_denoise(q["denoise_sigma_px"]) * q["color_noise_gain"]
    electrons = signal_electrons(rate, q["snr_db"], read_noise,
                                 q["dark_current_e_per_s"] * pixels, prnu, gain)
    t_mpe = electrons / rate

    # No light: a rate of 0 (or flushed to 0 by electron_rate), or a T_MPE beyond float64.
    prnu_cap = (rate > 0) & prnu_capped(prnu, q["snr_db"], gain)
    no_light = ~prnu_cap & ~np.isfinite(t_mpe)
    # the full well holds k^2 W a frame: n k^2 W over the burst
    full_well = ~no_light & ~prnu_cap & (electrons > q["full_well_e"] * (pixels * n))
    unreachable = no_light | prnu_cap | full_well

    t_mpe = np.where(unreachable, np.inf, t_mpe)
    # each frame moves by its own T/n of shake
    blur = blur_length_mm(q["focal_length_mm"], q["shake_deg_per_s"], q["stabilization"] * n,
                          np.where(unreachable, 0.0, t_mpe))
    unbounded = ~unreachable & np.isinf(blur)
    solve = ~unreachable & ~unbounded

    if wavelengths_nm is None:
        wavelengths, spectral_weights = [q["wavelength_nm"]], [1.0]
        shortest = q["wavelength_nm"]
    else:
        wavelengths, spectral_weights = list(wavelengths_nm), list(weights)
        shortest = np.min(np.asarray(wavelengths_nm)[np.asarray(weights) > 0])

    blur_solved = np.where(solve, blur, 0.0)
    f_hi = f50_bracket(q["f_number"], shortest, q["pixel_pitch_um"], q["fill_factor"],
                       blur_solved, q["jitter_um"], q["mtf_threshold"], k,
                       q["alignment_error_um"], n,
                       None if lens_tables is None else lens_bracket(q["lens"], lens_tables))

    def mtf(f):
        return mtf_system(f, q["f_number"], q["pixel_pitch_um"], q["fill_factor"], blur_solved,
                          q["jitter_um"], wavelengths, spectral_weights, k,
                          q["alignment_error_um"], n, q["wavefront_rms_waves"],
                          q["denoise_sigma_px"], q["lens"], lens_tables, demosaic_table)

    # a lens table that ends above the threshold holds no f50: a status, not a number
    beyond = solve & (mtf(f_hi) > q["mtf_threshold"]) if lens_tables is not None else False
    f50 = np.where(solve, f50_bisection(mtf, f_hi, q["mtf_threshold"]), 0.0)
    f50 = np.where(beyond, np.nan, f50)
    area_mm2 = q["size"] * (q["pixel_pitch_um"] * 1e-3) ** 2 if size_is_pixel_count else q["size"]
    epc = effective_pixel_count(area_mm2, f50)

    status = np.select([~valid, unreachable, unbounded, beyond],
                       [Status.INVALID, Status.UNREACHABLE, Status.BLUR_UNBOUNDED,
                        Status.BEYOND_TABLE],
                       Status.OK).astype(np.uint8)
    cause = np.select([~valid, no_light, prnu_cap, full_well],
                      [Cause.NONE, Cause.NO_LIGHT, Cause.PRNU, Cause.FULL_WELL],
                      Cause.NONE).astype(np.uint8)
    solved = valid & ~unreachable
    return {
        "electron_rate_e_per_s": np.where(valid, rate, np.nan),
        "electrons": np.where(valid & ~no_light & ~prnu_cap, electrons, np.nan),
        "t_mpe_s": np.where(valid, t_mpe, np.nan),
        "blur_mm": np.where(solved, blur, np.nan),
        "f50_cyc_per_mm": np.where(solved, f50, np.nan),
        "epc": np.where(solved, epc, np.nan),
        "status": status,
        "cause": cause,
    }
