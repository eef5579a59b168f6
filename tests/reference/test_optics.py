"""The wavefront error and denoising terms of the NumPy reference (epc_fast.reference.optics and
their place in epc_fast.reference.model): closed forms, Shannon's ATF against a pupil-based MTF
(our own FFT of a pupil with a Zernike phase, and prysm's where it is installed), the denoising
filter's kernel, noise gain and transfer, the exposure it buys and f50 as the first crossing.

Every tolerance says why it is that size.
"""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, _core, reference
from epc_fast.params import DENOISE_SIGMA_PX_MAX, WAVEFRONT_RMS_WAVES_MAX
from epc_fast.reference import optics

DESIGN = dict(pixel_pitch_um=1.4, f_number=2.4, focal_length_mm=4.0, pixel_count=8e6,
              read_noise_e=2.0, backend="reference")

# --- Shannon's aberration transfer function ----------------------------------------------------


def atf_at_nu(nu, w):
    """optics.mtf_aberration as a function of nu: lambda = 1e6 nm = 1 mm and F = 1."""
    return optics.mtf_aberration(np.asarray(nu, dtype=np.float64), 1e6, 1.0, w)


def diffraction_at_nu(nu):
    return reference.mtf_diffraction(np.asarray(nu, dtype=np.float64), 1e6, 1.0)


def test_the_atf_is_one_at_zero_and_at_the_cut_off_and_its_least_at_half():
    w = np.array([0.0, 0.05, 0.1, 0.16])
    assert np.all(atf_at_nu(0.0, w) == 1.0)
    assert np.all(atf_at_nu(1.0, w) == 1.0)
    np.testing.assert_allclose(atf_at_nu(0.5, w), 1.0 - (w / 0.18) ** 2, rtol=1e-15)


def test_the_atf_is_one_bit_for_bit_without_a_wavefront_error():
    nu = np.linspace(0.0, 1.5, 1001)
    assert np.all(atf_at_nu(nu, 0.0) == 1.0)


def test_the_atf_is_symmetric_about_one_half():
    nu = np.linspace(0.0, 0.5, 101)
    np.testing.assert_allclose(atf_at_nu(nu, 0.1), atf_at_nu(1.0 - nu, 0.1), rtol=0, atol=1e-15)


def test_the_aberrated_diffraction_mtf_falls_up_to_the_domains_end_and_not_beyond_0_1642():
    # the f50 bracket needs D(nu) ATF(nu) to fall on [0, 1]; it does for W <= 0.1642 waves
    # (bisected on this grid) and the domain stops at 0.16
    nu = np.linspace(0.0, 1.0, 200_001)[:-1]
    falls = lambda w: np.all(np.diff(diffraction_at_nu(nu) * atf_at_nu(nu, w)) <= 0.0)  # noqa: E731
    assert WAVEFRONT_RMS_WAVES_MAX == 0.16
    assert all(falls(w) for w in (0.01, 0.05, 0.1, 0.14, 0.16, 0.164))
    assert not falls(0.165) and not falls(0.18)


ZERNIKE = {  # Noll-normalised (unit rms over the unit disk), rho^2 = r2
    "defocus": lambda r2: math.sqrt(3.0) * (2.0 * r2 - 1.0),
    "spherical": lambda r2: math.sqrt(5.0) * (6.0 * r2 * r2 - 6.0 * r2 + 1.0),
}


def pupil_mtf(w, kind, radius=128):
    """(nu, MTF) along a radius of a circular pupil with a Zernike phase of rms w waves: the
    OTF as the pupil's autocorrelation, by FFT on a grid twice the pupil's diameter (no wrap)."""
    n = 4 * radius
    y, x = (np.mgrid[:n, :n] - n / 2 + 0.5) / radius
    r2 = x * x + y * y
    pupil = (r2 <= 1.0) * np.exp(2j * np.pi * w * ZERNIKE[kind](r2))
    otf = np.fft.ifft2(np.abs(np.fft.fft2(pupil)) ** 2)
    mtf = np.abs(otf[0, :2 * radius + 1])
    return np.arange(2 * radius + 1) / (2 * radius), mtf / mtf[0]


def first_crossing(nu, m, c=0.5):
    i = int(np.argmax(m <= c))
    return nu[i - 1] + (m[i - 1] - c) / (m[i - 1] - m[i]) * (nu[i] - nu[i - 1])


def model_mtf50(w):
    nu = np.linspace(0.0, 1.0, 400_001)
    return first_crossing(nu, diffraction_at_nu(nu) * atf_at_nu(nu, w))


# The measured relative difference of Shannon's MTF50 from the pupil's (ATF MTF50 / pupil MTF50
# - 1, radius 128: the aberration-free pupil is within 0.03% of D's MTF50), and the bound each
# case is held to (measured + 0.5 percentage points, for the grid). Shannon's ATF is an average
# over mixed aberrations: for pure defocus or spherical aberration it is optimistic, within a few
# percent only to 0.02 waves.
ATF_MTF50_ERROR = {
    ("defocus", 0.02): 0.0100, ("defocus", 0.05): 0.0607, ("defocus", 0.07): 0.1041,
    ("defocus", 0.1): 0.1130, ("defocus", 0.14): -0.0187,
    ("spherical", 0.02): 0.0103, ("spherical", 0.05): 0.0857, ("spherical", 0.07): 0.1979,
    ("spherical", 0.1): 0.3832, ("spherical", 0.14): 0.4018,
}


@pytest.mark.parametrize("kind, w", sorted(ATF_MTF50_ERROR))
def test_shannons_mtf50_against_a_pupil_with_a_zernike_phase(kind, w):
    nu, m = pupil_mtf(w, kind)
    error = model_mtf50(w) / first_crossing(nu, m) - 1.0
    assert error == pytest.approx(ATF_MTF50_ERROR[kind, w], abs=0.005)


def test_shannons_mtf_is_within_0_075_of_defocus_and_0_15_of_spherical_aberration_everywhere():
    for kind, bound in (("defocus", 0.075), ("spherical", 0.15)):
        for w in (0.02, 0.05, 0.07, 0.1, 0.14):
            nu, m = pupil_mtf(w, kind)
            assert np.max(np.abs(m - diffraction_at_nu(nu) * atf_at_nu(nu, w))) < bound


def test_our_pupil_mtf_agrees_with_prysms_to_0_2_percent_at_mtf50():
    prysm = pytest.importorskip("prysm")  # noqa: F841  (a test peer, not a dependency)
    from prysm.coordinates import cart_to_polar, make_xy_grid
    from prysm.geometry import circle
    from prysm.otf import mtf_from_psf
    from prysm.polynomials import zernike_nm
    from prysm.propagation import Wavefront

    n, diameter_mm, wavelength_um, efl_mm = 256, 10.0, 0.55, 20.0
    x, y = make_xy_grid(n, diameter=diameter_mm)
    r, t = cart_to_polar(x, y)
    rho = r / (diameter_mm / 2)
    amplitude = circle(1, rho).astype(float)
    for (radial, kind) in ((2, "defocus"), (4, "spherical")):
        zernike = zernike_nm(radial, 0, rho, t, norm=True)
        for w in (0.05, 0.1):
            wf = Wavefront.from_amp_and_phase(amplitude, w * wavelength_um * 1e3 * zernike,
                                              wavelength_um, diameter_mm / n)
            mtf = mtf_from_psf(wf.focus(efl_mm, Q=2).intensity)
            cy, cx = np.array(mtf.data.shape) // 2
            fx = mtf.x[cy, cx:] if mtf.x.ndim == 2 else mtf.x[cx:]
            prysm_nu = fx * wavelength_um * 1e-3 * efl_mm / diameter_mm
            ours = first_crossing(*pupil_mtf(w, kind))
            assert first_crossing(prysm_nu, mtf.data[cy, cx:]) == pytest.approx(ours, rel=2e-3)


# --- Denoising ----------------------------------------------------------------------------------


def test_the_denoising_kernel_sums_to_one_and_reaches_ceil_4_sigma():
    sigma = np.array([0.0, 0.3, 1.0, 2.5, 10.0])
    i, h = optics.denoise_kernel(sigma)
    np.testing.assert_allclose(h[0] + 2.0 * h[1:].sum(axis=0), 1.0, rtol=1e-15)
    reach = (h > 0).sum(axis=0) - 1
    assert reach.tolist() == [0, 2, 4, 10, 40]
    assert h[:, 0].tolist() == [1.0] + [0.0] * (len(i) - 1)


def test_the_noise_gain_is_one_without_denoising_and_below_one_with():
    # below sigma = 0.14, h_1 = exp(-1/(2 sigma^2)) < 1e-11 and g rounds to within 1e-21 of 1
    g = optics.noise_gain_denoise(np.array([0.0, 0.2, 0.5, 1.0, 3.0]))
    assert g[0] == 1.0 and optics.noise_gain_denoise(0.1) == pytest.approx(1.0, abs=1e-20)
    assert np.all(np.diff(g) < 0.0) and g[1] < 1.0


def test_the_noise_gain_tends_to_the_continuous_gaussians():
    # sum h_i^2 -> 1 / (2 sqrt(pi) sigma) as sigma grows (the sampled Gaussian's sum of squares
    # differs by its aliases, exp(-pi^2 sigma^2), and the truncation at 4 sigma, 6e-5)
    for sigma in (3.0, 10.0, 30.0):
        assert optics.noise_gain_denoise(sigma) == pytest.approx(
            (1.0 / (2.0 * math.sqrt(math.pi) * sigma)) ** 2, rel=3e-4)


def test_the_transfer_is_one_at_zero_and_tends_to_the_continuous_gaussians():
    pitch_um = 1.4
    f = np.linspace(0.0, 0.5 / (pitch_um * 1e-3), 201)
    for sigma in (3.0, 10.0):
        h = optics.mtf_denoise(f, sigma, pitch_um)
        assert h[0] == pytest.approx(1.0, abs=1e-15)
        gaussian = np.exp(-2.0 * np.pi**2 * (sigma * pitch_um * 1e-3 * f) ** 2)
        # the kernel's truncation at 4 sigma leaves ripples of its tails' mass, 6.3e-5 each side
        assert np.max(np.abs(h - gaussian)) < 1.5e-4


def test_the_transfer_falls_to_the_outputs_nyquist_frequency_and_is_held_beyond():
    pitch_um = 2.0
    nyquist = 0.5 / (pitch_um * 1e-3)
    f = np.linspace(0.0, nyquist, 4001)
    for sigma in (0.2, 0.5, 1.0, 1.7):  # below 1.75 no truncation ripple reaches H > 0
        assert np.all(np.diff(optics.mtf_denoise(f, sigma, pitch_um)) <= 0.0)
    for sigma in (2.0, 5.0, 20.0):  # above, H falls wherever it is above the ripples (1e-4)
        h = optics.mtf_denoise(f, sigma, pitch_um)
        assert np.all(np.diff(h)[h[1:] > 1e-4] <= 0.0)
    beyond = optics.mtf_denoise(np.array([1.2, 2.0, 7.5]) * nyquist, 0.5, pitch_um)
    assert np.all(beyond == optics.mtf_denoise(nyquist, 0.5, pitch_um))


def test_denoising_meets_the_target_after_the_filter():
    # T_MPE with noise gain g is T_MPE without it at a target 10 log10(g) dB higher, and the SNR
    # after the filter at that T_MPE is the target
    rate, snr_db, read, dark, prnu = 3e3, 30.0, 2.0, 5.0, 0.01
    g = float(optics.noise_gain_denoise(1.0))
    t = reference.t_mpe_closed_form(rate, snr_db, read, dark, prnu, g)
    assert t == pytest.approx(
        reference.t_mpe_closed_form(rate, snr_db + 10.0 * math.log10(g), read, dark, prnu),
        rel=1e-13)
    assert reference.snr_db_at(t, rate, read, dark, prnu, g) == pytest.approx(snr_db, abs=1e-12)


def test_denoising_buys_a_shorter_exposure_and_more_epc_at_low_light():
    plain = epc_fast.evaluate(illuminance_lux=10.0, **DESIGN)
    denoised = epc_fast.evaluate(illuminance_lux=10.0, denoise_sigma_px=1.0, **DESIGN)
    assert denoised.t_mpe_s < 0.1 * plain.t_mpe_s
    assert denoised.epc > 10.0 * plain.epc
    bright_plain = epc_fast.evaluate(illuminance_lux=1e4, **DESIGN)
    bright_denoised = epc_fast.evaluate(illuminance_lux=1e4, denoise_sigma_px=3.0, **DESIGN)
    assert bright_denoised.epc < 0.2 * bright_plain.epc  # in bright light it only blurs


# --- f50 with both terms ------------------------------------------------------------------------


def test_f50_is_the_first_crossing_of_the_sampled_filters_periodic_transfer():
    # the MTF on a fine grid with the filter's own periodic H (not held past Nyquist): where its
    # first crossing lies below the output's Nyquist frequency, f50 is it to the grid's step
    rng = np.random.default_rng(40)
    n = 40
    p = dict(illuminance_lux=10.0 ** rng.uniform(0, 4, n), pixel_pitch_um=rng.uniform(0.8, 3, n),
             f_number=rng.uniform(1.6, 4, n), focal_length_mm=4.0, pixel_count=8e6,
             read_noise_e=2.0, wavefront_rms_waves=rng.uniform(0, 0.16, n),
             denoise_sigma_px=rng.choice([0.3, 0.7, 1.0, 2.0, 3.0], n),
             mtf_threshold=rng.choice([0.5, 0.3, 0.1], n), binning=rng.choice([1.0, 2.0], n))
    r = epc_fast.evaluate(backend="reference", **p)
    assert np.all(r.status == Status.OK)
    checked = 0
    for j in range(n):
        pitch_out_mm = p["pixel_pitch_um"][j] * p["binning"][j] * 1e-3
        f = np.linspace(0.0, 2.0 * r.f50_cyc_per_mm[j], 200_001)
        m = reference.mtf_system(
            f, p["f_number"][j], p["pixel_pitch_um"][j], 1.0, r.blur_mm[j], 0.0, [550.0], [1.0],
            p["binning"][j], wavefront_rms_waves=p["wavefront_rms_waves"][j])
        _, h = optics.denoise_kernel(p["denoise_sigma_px"][j])
        i = np.arange(len(h))[:, None]
        periodic = h[0, 0] + 2.0 * (h[1:, 0:1] * np.cos(2 * np.pi * i[1:] * f * pitch_out_mm)).sum(0)
        crossing = f[np.argmax(m * periodic <= p["mtf_threshold"][j])]
        if crossing < 0.5 / pitch_out_mm:
            checked += 1
            assert r.f50_cyc_per_mm[j] == pytest.approx(crossing, abs=2.0 * (f[1] - f[0]))
    assert checked >= 30


def test_without_either_term_the_reference_gives_the_same_bits():
    p = dict(illuminance_lux=np.geomspace(0.1, 1e5, 50), **DESIGN)
    plain = epc_fast.evaluate(**p)
    zeros = epc_fast.evaluate(**p, wavefront_rms_waves=np.zeros(50), denoise_sigma_px=np.zeros(50))
    for name in ("t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc", "status"):
        assert np.array_equal(getattr(plain, name), getattr(zeros, name), equal_nan=True)


# --- Domains and bad input ----------------------------------------------------------------------


@pytest.mark.parametrize("name, bad", [
    ("wavefront_rms_waves", [-0.01, np.nan, np.inf, 0.1601, 0.18]),
    ("denoise_sigma_px", [-1.0, np.nan, np.inf, DENOISE_SIGMA_PX_MAX * 1.01]),
])
def test_values_outside_the_domain_are_invalid_or_raise(name, bad):
    r = epc_fast.evaluate(illuminance_lux=100.0, **DESIGN, **{name: bad})
    assert np.all(r.status == Status.INVALID) and np.all(np.isnan(r.epc))
    with pytest.raises(ValueError, match=name):
        epc_fast.evaluate(illuminance_lux=100.0, invalid="raise", **DESIGN, **{name: bad[0]})


def test_the_domains_ends_are_valid_and_finite():
    r = epc_fast.evaluate(illuminance_lux=[0.1, 1e5], wavefront_rms_waves=WAVEFRONT_RMS_WAVES_MAX,
                          denoise_sigma_px=DENOISE_SIGMA_PX_MAX, **DESIGN)
    assert np.all(r.status == Status.OK) and np.all(np.isfinite(r.epc)) and np.all(r.epc > 0)


def test_subnormal_values_are_the_terms_off():
    # (W / 0.18)^2 underflows to 0 and exp(-1 / (2 sigma^2)) to 0: ATF = 1 and the kernel (1)
    plain = epc_fast.evaluate(illuminance_lux=100.0, **DESIGN)
    for name in ("wavefront_rms_waves", "denoise_sigma_px"):
        for value in (5e-324, 2.2e-310):
            r = epc_fast.evaluate(illuminance_lux=100.0, **DESIGN, **{name: value})
            assert (r.status, r.epc, r.t_mpe_s) == (plain.status, plain.epc, plain.t_mpe_s)


# --- Shares and elasticities --------------------------------------------------------------------

SENSITIVITY_POINT = dict(illuminance_lux=np.array([10.0, 300.0, 5000.0]), pixel_pitch_um=1.4,
                         f_number=2.4, focal_length_mm=4.0, pixel_count=8e6, read_noise_e=2.0,
                         dark_current_e_per_s=5.0, prnu=0.005, binning=np.array([1.0, 2.0, 1.0]),
                         backend="reference")


@pytest.mark.parametrize("w, sigma", [(0.07, 1.3), (0.12, 0.6), (0.0, 2.1), (0.1, 0.0)])
def test_the_elasticities_with_either_term_are_the_central_differences_of_ln_epc(w, sigma):
    # central differences at h = 1e-5: truncation h^2 ~ 1e-10 and rounding 1e-16 / h ~ 1e-11 of
    # an elasticity of order 1, well inside 1e-6 (the analytic ones agree to 1e-8 measured).
    # Not at 4 sigma whole: the kernel gains a tap there (ceil(4 sigma)), a jump of its weight
    # exp(-8), and the elasticity is the derivative between the jumps.
    p = dict(SENSITIVITY_POINT, wavefront_rms_waves=w, denoise_sigma_px=sigma)
    r = epc_fast.evaluate(**p, outputs=("epc", "status", "elasticities"))
    values = dict(wavelength_nm=550.0, snr_db=30.0, **p)
    h = 1e-5
    for name in ("wavefront_rms_waves", "denoise_sigma_px", "f_number", "pixel_pitch_um",
                 "wavelength_nm", "snr_db", "illuminance_lux", "read_noise_e"):
        v = np.broadcast_to(np.asarray(values[name], dtype=np.float64), (3,))
        if np.all(v == 0.0):  # a term that is off: elasticity 0
            assert np.all(r.elasticities[name] == 0.0)
            continue
        up = epc_fast.evaluate(**{**p, name: v * (1 + h)}).epc
        down = epc_fast.evaluate(**{**p, name: v * (1 - h)}).epc
        central = (np.log(up) - np.log(down)) / (2 * h)
        np.testing.assert_allclose(r.elasticities[name], central, rtol=1e-6, atol=1e-9,
                                   err_msg=name)


def test_the_seven_shares_sum_to_one_and_the_terms_that_are_off_have_none():
    names = [f"share_{n}" for n in ("diffraction", "pixel", "motion", "jitter", "alignment",
                                    "aberration", "denoise")]
    on = epc_fast.evaluate(**SENSITIVITY_POINT, wavefront_rms_waves=0.07, denoise_sigma_px=1.3,
                           outputs=("epc", "status", *names))
    np.testing.assert_allclose(sum(getattr(on, n) for n in names), 1.0, rtol=1e-13)
    assert np.all(on.share_aberration > 0.0) and np.all(on.share_denoise > 0.0)
    off = epc_fast.evaluate(**SENSITIVITY_POINT, outputs=("epc", "status", *names))
    assert np.all(off.share_aberration == 0.0) and np.all(off.share_denoise == 0.0)
