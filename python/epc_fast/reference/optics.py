"""The NumPy reference of the lens's wavefront error and of denoising (docs/model.md, "System
MTF" and "Exposure: T_MPE"; issue #40): Shannon's aberration transfer function and a Gaussian
filter on the output image, its noise gain and its transfer.

Each function carries the same name as the formula in docs/model.md and, once the core has
them, in ``cpp/include/epc_fast/mtf.h``. Both terms are off at 0 and then change nothing, bit
for bit (:func:`epc_fast.reference.mtf_system` leaves them out where no point has them).
"""

from __future__ import annotations

import numpy as np

__all__ = ["SHANNON_W0", "mtf_aberration", "denoise_kernel", "noise_gain_denoise", "mtf_denoise",
           "denoise_log_factor", "noise_gain_log_slope"]


#: waves: the rms wavefront error at which Shannon's ATF reaches 0 at nu = 1/2.
SHANNON_W0 = 0.18


def mtf_aberration(f_cyc_per_mm, wavelength_nm, f_number, wavefront_rms_waves):
    """1: Shannon's empirical aberration transfer function at nu = f lambda F,
    ATF(nu) = 1 - (W/0.18)^2 (1 - 4 (nu - 1/2)^2), W the rms wavefront error in waves
    (R. R. Shannon, "The Art and Science of Optical Design", Cambridge University Press, 1997).

    It multiplies the diffraction MTF of the same wavelength: W is taken in waves at every
    wavelength of a spectrum. nu is held at 1 past the cut-off (where D is 0). On [0, 1/2] it
    falls from 1 to 1 - (W/0.18)^2, symmetric about 1/2; 1 at W = 0, bit for bit.
    """
    nu = np.minimum(f_cyc_per_mm * (wavelength_nm * 1e-6) * f_number, 1.0)
    a = (np.asarray(wavefront_rms_waves, dtype=np.float64) / SHANNON_W0) ** 2
    return 1.0 - a * (1.0 - 4.0 * (nu - 0.5) ** 2)


def denoise_kernel(denoise_sigma_px):
    """(i, h): the denoising filter's taps i = 0 .. n (n = max ceil(4 sigma) over the points,
    shape (n + 1, 1)) and its weights h_i (shape (n + 1, points)): the sampled Gaussian
    exp(-i^2 / (2 sigma^2)) on the integers |i| <= ceil(4 sigma), normalised to sum 1 over
    -ceil(4 sigma) .. ceil(4 sigma) (h_-i = h_i; 0 past a point's own ceil(4 sigma)). It is
    applied along the rows and then the columns of the output image (separable). sigma = 0 is
    the identity, h = (1)."""
    sigma = np.atleast_1d(np.asarray(denoise_sigma_px, dtype=np.float64))
    reach = np.ceil(4.0 * sigma)
    i = np.arange(int(reach.max(initial=0.0)) + 1, dtype=np.float64)[:, None]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # e_0 = 1 (its exponent 0 / (2 sigma^2) would be NaN where sigma^2 underflows)
        e = np.where(i == 0, 1.0, np.where(i <= reach, np.exp(-(i * i) / (2.0 * sigma * sigma)),
                                           0.0))
    return i, e / (e[0] + 2.0 * e[1:].sum(axis=0))


def noise_gain_denoise(denoise_sigma_px):
    """1: g = (sum_i h_i^2)^2, the factor by which the separable denoising filter
    (:func:`denoise_kernel`, in x and in y) multiplies the variance of white pixel noise; below
    1 for sigma > 0, 1 at sigma = 0."""
    _, h = denoise_kernel(denoise_sigma_px)
    one_d = h[0] ** 2 + 2.0 * (h[1:] ** 2).sum(axis=0)
    return np.reshape(one_d * one_d, np.shape(denoise_sigma_px))


def mtf_denoise(f_cyc_per_mm, denoise_sigma_px, output_pitch_um):
    """1: the denoising filter's transfer along the rows, H(f) = sum_i h_i cos(2 pi f p i) =
    h_0 + 2 sum_{i >= 1} h_i cos(2 pi f p i), p the output pitch in mm (the pitch times the
    binning), at min(f, 1/(2 p)).

    H is periodic in f with period 1/p and falls on [0, 1/(2 p)] (the output's Nyquist
    frequency) to its minimum; past it the sampled filter's transfer rises again, onto the
    aliases of frequencies below it. The model holds H at its Nyquist value there, so that the
    system MTF keeps falling and f50 is its first crossing (docs/model.md, "System MTF").
    For large sigma H tends to exp(-2 pi^2 sigma^2 p^2 f^2). 1 at sigma = 0.
    """
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    p_mm = np.asarray(output_pitch_um, dtype=np.float64) * 1e-3
    shape = np.broadcast_shapes(f.shape, np.shape(denoise_sigma_px), p_mm.shape)
    i, h = denoise_kernel(np.broadcast_to(denoise_sigma_px, shape).ravel())
    x = np.broadcast_to(np.minimum(f * p_mm, 0.5), shape).ravel()  # f p, held at 1/2
    transfer = h[0] + 2.0 * (h[1:] * np.cos(2.0 * np.pi * i[1:] * x)).sum(axis=0)
    return transfer.reshape(shape)


# --- What the shares and the elasticities need (epc_fast.reference.sensitivity) ------------------


def denoise_log_factor(f_cyc_per_mm, denoise_sigma_px, output_pitch_um):
    """1: (ln H, f d ln H / df, sigma d ln H / d sigma) at f (:func:`mtf_denoise`): with
    x = min(f p, 1/2) and the kernel's weights h_i over every i (both signs),

        f dH/df       = -sum_i h_i 2 pi x i sin(2 pi x i)   (0 past the output's Nyquist
                                                              frequency, where H is held)
        sigma dH/dsigma = sum_i h_i (i/sigma)^2 (cos(2 pi x i) - H)

    (sigma de_i/dsigma = e_i (i/sigma)^2 for e_i = exp(-i^2 / (2 sigma^2)), normalised). All
    three are 0 at sigma = 0."""
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    p_mm = np.asarray(output_pitch_um, dtype=np.float64) * 1e-3
    shape = np.broadcast_shapes(f.shape, np.shape(denoise_sigma_px), p_mm.shape)
    sigma = np.broadcast_to(denoise_sigma_px, shape).ravel()
    i, h = denoise_kernel(sigma)
    x = np.broadcast_to(f * p_mm, shape).ravel()
    held = x >= 0.5
    x = np.minimum(x, 0.5)
    phase = 2.0 * np.pi * i[1:] * x
    transfer = h[0] + 2.0 * (h[1:] * np.cos(phase)).sum(axis=0)
    f_slope = np.where(held, 0.0, -2.0 * (h[1:] * phase * np.sin(phase)).sum(axis=0))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        weight = np.where(h[1:] > 0.0, (i[1:] / sigma) ** 2, 0.0)  # a tap of weight 0: none
    sigma_slope = 2.0 * (h[1:] * weight * (np.cos(phase) - transfer)).sum(axis=0)  # i = 0: 0
    return tuple(np.reshape(v, shape) for v in
                 (np.log(transfer), f_slope / transfer, sigma_slope / transfer))


def noise_gain_log_slope(denoise_sigma_px):
    """1: d ln g / d ln sigma, g = (sum_i h_i^2)^2 (:func:`noise_gain_denoise`): 2 sigma dG /
    dsigma / G with G = sum_i h_i^2 and sigma dG/dsigma = 2 sum_i h_i^2 ((i/sigma)^2 - m),
    m = sum_j h_j (j/sigma)^2; 0 at sigma = 0."""
    sigma = np.atleast_1d(np.asarray(denoise_sigma_px, dtype=np.float64))
    i, h = denoise_kernel(sigma)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        weight = np.where((h > 0.0) & (i > 0), (i / sigma) ** 2, 0.0)  # i = 0, taps of 0: none
    both = np.where(i > 0, 2.0, 1.0)  # h_-i = h_i
    mean = (both * h * weight).sum(axis=0)
    gain = (both * h * h).sum(axis=0)
    slope = 2.0 * (2.0 * (both * h * h * (weight - mean)).sum(axis=0)) / gain
    return np.reshape(slope, np.shape(denoise_sigma_px))
