"""Known values of each formula of docs/model.md, for the NumPy reference (epc_fast.reference) and
for the C++ formulas exposed in epc_fast._core (sinc, mtf_diffraction, signal_electrons,
signal_electrons_brent).

Expected values are closed forms or mpmath at 50 digits; every tolerance says why it is that size.
"""

import math

import mpmath
import numpy as np
import pytest

import epc_fast
from epc_fast import Cause, Status, _core, reference
from helpers.mp_model import mp_diffraction, mp_signal_electrons

ULP = 2.0**-52  # spacing of float64 just above 1; 2**-53 is the unit roundoff

# --- Helpers ------------------------------------------------------------------------------------

# Every mpf of this module at 50 digits, the model's formulas (mp_diffraction, the textbook root
# r T_MPE of mp_signal_electrons) included: helpers/mp_model.py works at the caller's precision.
mpmath.mp.dps = 50


def mp_sinc(x):
    return mpmath.sincpi(x)  # sin(pi x) / (pi x), 1 at 0


#: The x with sinc(x) = 1/2 (0.6034...): f50 of a pixel aperture of side 1 is X50 / side.
X50 = mpmath.findroot(lambda x: mp_sinc(x) - mpmath.mpf(1) / 2, 0.6)
#: The normalised frequency nu with D(nu) = 1/2 (0.4040...).
NU50 = mpmath.findroot(lambda nu: mp_diffraction(nu) - mpmath.mpf(1) / 2, 0.4)


def reference_diffraction_at_nu(nu):
    """reference.mtf_diffraction as a function of nu alone: lambda = 1e6 nm = 1 mm and F = 1,
    so nu = f lambda F = f (1e6 * 1e-6 is exactly 1.0 in float64)."""
    return reference.mtf_diffraction(np.asarray(nu, dtype=np.float64), 1e6, 1.0)


DIFFRACTION = [pytest.param(_core.testing.mtf_diffraction, id="core"),
               pytest.param(reference_diffraction_at_nu, id="reference")]
SINC = [pytest.param(_core.testing.sinc, id="core"), pytest.param(reference.sinc, id="reference")]
SIGNAL_ELECTRONS = [pytest.param(_core.testing.signal_electrons, id="core"),
                    pytest.param(reference.signal_electrons, id="reference")]
BACKENDS = [pytest.param(dict(backend="core"), id="core"),
            pytest.param(dict(backend="core", t_mpe_solver="brent"), id="core-brent"),
            pytest.param(dict(backend="reference"), id="reference")]


def exposure_sample(n, seed):
    """n random sensor/target combinations with read noise, dark current and PRNU: log-uniform
    rate 1e-3..1e9 e-/s, read noise 0..50 e-, dark 0..1e4 e-/s, snr 5..60 dB and PRNU up to 0.9
    of its cap 10^(-snr/20) (above that, w = 1 - s u^2 < 0.19 and the target is near-unreachable).
    Returns (rate, snr_db, read, dark, prnu) as arrays."""
    rng = np.random.default_rng(seed)
    rate = 10.0 ** rng.uniform(-3, 9, n)
    read = rng.uniform(0, 50, n)
    dark = rng.uniform(0, 1e4, n)
    snr_db = rng.uniform(5, 60, n)
    prnu = rng.uniform(0, 0.9, n) * 10.0 ** (-snr_db / 20)
    return rate, snr_db, read, dark, prnu


def root_s_amplification(electrons, snr_db, dark_per_signal, prnu):
    """|d ln E / d ln sqrt(s)| at the root E: how much a last-bit difference in 10^(snr/20)
    moves E. Differentiating w E^2 - s (1 + D/r) E - s sigma^2 = 0 (w = 1 - s u^2) gives
    d ln E / d ln s = E / (2 w E - s (1 + D/r)); sqrt(s) doubles it. 2 without PRNU."""
    s = 10.0 ** (snr_db / 10)
    w = 1.0 - s * prnu**2
    return 2.0 * electrons / (2.0 * w * electrons - s * (1.0 + dark_per_signal))


# --- Diffraction MTF (docs/model.md, "System MTF") ------------------------------------------------


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_at_half_cutoff_is_0_3910(mtf):
    # 4 digits: the value as quoted, 0.3910 +- half a unit in the 4th decimal.
    assert abs(float(mtf(0.5)) - 0.3910) < 0.5e-4


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_at_half_cutoff_is_the_exact_closed_form(mtf):
    exact = float(2 / mpmath.pi * (mpmath.acos(0.5) - 0.5 * mpmath.sqrt(0.75)))
    # 1e-15 relative: acos, sqrt and three products each round once (about 4 ulp in all).
    assert float(mtf(0.5)) == pytest.approx(exact, rel=1e-15, abs=0)


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_is_one_at_zero_frequency(mtf):
    # (2/pi) acos(0): fl(2/pi) times fl(pi/2), one rounding each: within one ulp of 1.
    assert float(mtf(0.0)) == pytest.approx(1.0, rel=0, abs=ULP)


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_is_exactly_zero_at_the_cutoff(mtf):
    # acos(1) = 0 and sqrt((1 - 1)(1 + 1)) = 0 are exact in float64.
    assert float(mtf(1.0)) == 0.0


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_is_exactly_zero_beyond_the_cutoff(mtf):
    nu = np.array([1.0 + ULP, 1.001, 1.5, 2.0, 10.0, 1e300, np.inf])
    np.testing.assert_array_equal(mtf(nu), np.zeros_like(nu))


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_decreases_strictly_from_zero_to_the_cutoff(mtf):
    nu = np.linspace(0.0, 1.0, 10001)
    assert np.all(np.diff(mtf(nu)) < 0)


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_matches_mpmath_on_a_grid(mtf):
    nu = np.concatenate([np.linspace(0.0, 1.0, 401), 1.0 - np.logspace(-12, -2, 21)])
    expected = np.array([float(mp_diffraction(v)) for v in nu])
    # 1e-15 absolute: D is O(1) with about 4 roundings; near nu = 1, acos(nu) and
    # nu sqrt(1 - nu^2) cancel (D ~ eps^1.5), so only an absolute bound is meaningful there.
    np.testing.assert_allclose(mtf(nu), expected, rtol=0, atol=1e-15)


# --- sinc (docs/model.md, "System MTF") -----------------------------------------------------------


@pytest.mark.parametrize("sinc", SINC)
def test_sinc_crosses_one_half_at_0_6034_to_four_digits(sinc):
    # sinc decreases on (0, 1): the crossing lies in [0.60335, 0.60345), i.e. rounds to 0.6034.
    assert float(sinc(0.60335)) > 0.5 > float(sinc(0.60345))


@pytest.mark.parametrize("sinc", SINC)
def test_sinc_is_one_half_at_its_mpmath_crossing_0_6034(sinc):
    # 1e-15 absolute: X50 rounds to float64 within 5.6e-17, |sinc'| there is 1.1, and sin and
    # the division add about 2 ulp of 0.5.
    assert float(sinc(float(X50))) == pytest.approx(0.5, rel=0, abs=1e-15)


@pytest.mark.parametrize("sinc", SINC)
def test_sinc_is_exactly_one_at_zero(sinc):
    assert float(sinc(0.0)) == 1.0


@pytest.mark.parametrize("sinc", SINC)
def test_sinc_vanishes_at_small_integers_to_1e_16(sinc):
    n = np.concatenate([-np.arange(1.0, 11.0), np.arange(1.0, 11.0)])
    # sin(fl(pi) n) = +-n (pi - fl(pi)) = +-n 1.22e-16, over pi n: 3.9e-17; for |n| <= 10 the
    # rounding of fl(pi) n adds less than 6.1e-17.
    assert np.max(np.abs(sinc(n))) < 1e-16


@pytest.mark.parametrize("sinc", SINC)
def test_sinc_vanishes_at_every_integer_up_to_1e4_within_the_rounding_of_pi_n(sinc):
    n = np.concatenate([-np.arange(1.0, 10001.0), np.arange(1.0, 10001.0)])
    # |fl(fl(pi) n) - pi n| <= 2^-53 pi n + n |pi - fl(pi)|, over pi n: 2^-53 + 3.9e-17 = 1.5e-16.
    assert np.max(np.abs(sinc(n))) <= 2.0**-53 + 3.9e-17 + 1e-18  # 1e-18: slack for sin itself


@pytest.mark.parametrize("sinc", SINC)
@pytest.mark.parametrize("x", [1e-300, 1e-20, -1e-20, 5e-324])
def test_sinc_is_exactly_one_for_tiny_arguments(sinc, x):
    # sin(y) rounds to y for |y| < 1e-8, so the quotient is exactly 1 (no 0/0, no underflow).
    assert float(sinc(x)) == 1.0


@pytest.mark.parametrize("sinc", SINC)
def test_sinc_matches_mpmath_on_a_grid(sinc):
    x = np.linspace(-3.0, 3.0, 601)
    expected = np.array([float(mp_sinc(mpmath.mpf(v))) for v in x])
    # 1e-15 absolute: |sinc| <= 1 and pi x, sin and the division round once each; at integers
    # sinc is only known to ~1.5e-16 absolute (see above).
    np.testing.assert_allclose(sinc(x), expected, rtol=0, atol=1e-15)


# --- T_MPE: electrons needed (docs/model.md, "Exposure: T_MPE") -----------------------------------


@pytest.mark.parametrize("signal_electrons", SIGNAL_ELECTRONS)
@pytest.mark.parametrize("rate", [1e-3, 1.0, 4025.8, 1e9])
def test_30_db_shot_noise_only_needs_1000_electrons(signal_electrons, rate):
    # 1e-15 relative: s = fl(10^1.5)^2 is 1000 within 2 roundings (4.4e-16); the rest is exact.
    assert float(signal_electrons(rate, 30.0, 0.0, 0.0, 0.0)) == pytest.approx(1000.0, rel=1e-15)


@pytest.mark.parametrize("signal_electrons", SIGNAL_ELECTRONS)
def test_33_db_shot_noise_only_needs_1995_26_electrons(signal_electrons):
    electrons = float(signal_electrons(1.0, 33.0, 0.0, 0.0, 0.0))
    assert round(electrons, 2) == 1995.26
    # 1e-15 relative: as for 30 dB, against 10^3.3 at 50 digits.
    assert electrons == pytest.approx(float(mpmath.mpf(10) ** mpmath.mpf(3.3)), rel=1e-15)


def test_t_mpe_with_shot_noise_only_is_1000_electrons_over_the_rate():
    rate = np.array([1e-3, 0.37, 4025.825471213014, 1e9])
    # 1e-15 relative: 1000 e- within 4.4e-16 (above), and one division.
    np.testing.assert_allclose(reference.t_mpe_closed_form(rate, 30.0, 0.0, 0.0, 0.0),
                               1000.0 / rate, rtol=1e-15, atol=0)


def test_closed_form_t_mpe_reaches_the_target_snr():
    rate, snr_db, read, dark, prnu = exposure_sample(500, seed=1)
    t = reference.t_mpe_closed_form(rate, snr_db, read, dark, prnu)
    # 1e-12 dB: SNR_dB = 20 log10(S/sigma) is evaluated in float64 from ~1e14-sized terms; a
    # 1e-15 relative error in S/sigma is 1e-14 dB (seen: 7e-15 dB).
    np.testing.assert_allclose(reference.snr_db_at(t, rate, read, dark, prnu), snr_db,
                               rtol=0, atol=1e-12)


def test_closed_form_t_mpe_matches_the_mpmath_quadratic_root():
    rate, snr_db, read, dark, prnu = exposure_sample(50, seed=2)
    t = reference.t_mpe_closed_form(rate, snr_db, read, dark, prnu)
    expected = np.array([float(mp_signal_electrons(*args) / mpmath.mpf(float(args[0])))
                         for args in zip(rate, snr_db, read, dark, prnu)])
    # 1e-14 relative: 10^(snr/20) is within 1 ulp, amplified up to ~10x near the PRNU cap
    # (root_s_amplification at w = 0.19), plus ~8 roundings (seen: 4.5e-15).
    np.testing.assert_allclose(t, expected, rtol=1e-14, atol=0)


def test_core_signal_electrons_matches_the_mpmath_quadratic_root():
    rate, snr_db, read, dark, prnu = exposure_sample(50, seed=3)
    expected = np.array([float(mp_signal_electrons(*args))
                         for args in zip(rate, snr_db, read, dark, prnu)])
    # 1e-14 relative: as for the reference's closed form, the same formula.
    np.testing.assert_allclose(_core.testing.signal_electrons(rate, snr_db, read, dark, prnu),
                               expected, rtol=1e-14, atol=0)


def test_core_signal_electrons_equals_the_reference_without_prnu():
    rate, snr_db, read, dark, _ = exposure_sample(2000, seed=4)
    prnu = np.zeros_like(rate)
    core = _core.testing.signal_electrons(rate, snr_db, read, dark, prnu)
    ref = reference.signal_electrons(rate, snr_db, read, dark, prnu)
    # 1e-15 relative: the same operations in the same order, but NumPy's vectorised 10**x and
    # libm's pow differ in the last bit of 10^(snr/20) for ~6% of inputs; without PRNU that bit
    # is amplified at most 2x (E ~ s), and the later roundings can then fall differently
    # (seen: 8.9e-16 over 2e5 points).
    np.testing.assert_allclose(core, ref, rtol=1e-15, atol=0)


def test_core_signal_electrons_equals_the_reference_with_prnu_up_to_its_amplification():
    rate, snr_db, read, dark, prnu = exposure_sample(2000, seed=5)
    core = _core.testing.signal_electrons(rate, snr_db, read, dark, prnu)
    ref = reference.signal_electrons(rate, snr_db, read, dark, prnu)
    amplification = root_s_amplification(ref, snr_db, dark / rate, prnu)
    # The 1e-15 of the case without PRNU (amplification 2) scaled by the amplification of the
    # last bit of 10^(snr/20), which reaches ~10 at 0.9 of the PRNU cap (seen: 2.9e-15 there).
    tolerance = 1e-15 * np.maximum(1.0, amplification / 2.0)
    assert np.all(np.abs(core / ref - 1.0) <= tolerance)


def test_brent_t_mpe_matches_the_closed_form():
    rate, snr_db, read, dark, prnu = exposure_sample(2000, seed=6)
    brent = _core.testing.signal_electrons_brent(rate, snr_db, read, dark, prnu, 1e-15)
    closed = _core.testing.signal_electrons(rate, snr_db, read, dark, prnu)
    # 1e-13 relative: Brent stops at 1e-15, but it finds the zero of g(E) = ln E - ln(variance)/2
    # - ln sqrt(s), whose logs (up to ~30) carry ~1e-15 absolute rounding, over a slope E g'(E)
    # that falls to ~w/2 = 0.1 near the PRNU cap: ~3e-14 (seen: 3.5e-14 over 1e6 points).
    np.testing.assert_allclose(brent, closed, rtol=1e-13, atol=0)


@pytest.mark.parametrize("signal_electrons", SIGNAL_ELECTRONS)
def test_closed_form_depends_on_rate_and_dark_only_through_their_ratio(signal_electrons):
    rate, snr_db, read, dark, prnu = exposure_sample(200, seed=7)
    # Scaling r and D by a power of 2 leaves D/r exactly unchanged: so must E be.
    np.testing.assert_array_equal(signal_electrons(8.0 * rate, snr_db, read, 8.0 * dark, prnu),
                                  signal_electrons(rate, snr_db, read, dark, prnu))


def test_prnu_cap_is_inclusive():
    # u 10^(snr/20) = 0.1 * 10 rounds to exactly 1.0: the cap, which docs/model.md says is reached.
    assert 0.1 * 10.0 ** (20.0 / 20.0) == 1.0
    assert reference.t_mpe_closed_form(1000.0, 20.0, 0.0, 0.0, 0.1) == math.inf


@pytest.mark.parametrize("options", BACKENDS)
def test_evaluate_reports_prnu_at_exactly_its_cap_as_unreachable(options):
    r = epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, sensor_area_mm2=15.6751, snr_db=20.0, prnu=0.1,
                          **options)
    assert (r.status, r.cause, r.t_mpe_s) == (Status.UNREACHABLE, Cause.PRNU, math.inf)


# --- Rayleigh blur: the units of lambda and F (docs/model.md, "The paper's systems") --------------


def diffraction_cutoff(f_number, wavelength_nm):
    """cycles/mm: 1/(lambda F) from the reference's bracket, with every other factor's zero far
    beyond it (pitch 1e-12 um, no motion, no jitter)."""
    a = np.asarray
    return float(reference.f50_bracket(a(f_number), a(wavelength_nm), a(1e-12), a(1.0), a(0.0),
                                       a(0.0), a(0.5)))


@pytest.mark.parametrize("f_number, digits, rayleigh_um",
                         [(2.8, 3, 1.879), (4.9, 2, 3.29)])
def test_rayleigh_blur_at_550_nm_is_as_the_paper_says(f_number, digits, rayleigh_um):
    # 1.22 lambda F = 1.22 / cutoff, in um (1e3 um per mm), to the digits the paper gives.
    assert round(1.22 / diffraction_cutoff(f_number, 550.0) * 1e3, digits) == rayleigh_um


def test_reference_diffraction_mtf_vanishes_at_the_rayleigh_cutoff_and_not_before():
    cutoff = diffraction_cutoff(2.8, 550.0)
    # 1e-9 below the cutoff nu = 1 - 1e-9: D ~ (8 sqrt 2 / 3 pi) 1e-13.5 > 0.
    assert reference.mtf_diffraction(cutoff * (1 - 1e-9), 550.0, 2.8) > 0
    assert reference.mtf_diffraction(cutoff, 550.0, 2.8) == 0


# --- Blur (docs/model.md, "Blur during the exposure") ---------------------------------------------


@pytest.mark.parametrize("t_s", [1e-4, 0.0248, 0.25, 2.0])
def test_blur_length_is_f_omega_t_up_to_the_tan_correction(t_s):
    focal_mm, shake, k = 5.6, 4.39, 1.0
    angle = shake * math.pi / 180 / k * t_s
    ratio = float(reference.blur_length_mm(focal_mm, shake, k, t_s)) / (focal_mm * angle)
    # tan(x)/x - 1 = x^2/3 + 2 x^4/15 + ...: the next term bounds the series' rest, 4 ulp the
    # float64 evaluation of the two sides.
    assert abs(ratio - 1 - angle**2 / 3) <= 2 * angle**4 / 15 * 1.01 + 4 * ULP


def test_blur_length_divides_the_angle_by_the_stabilization():
    # tan(x) = tan(4x / 4): k = 4 with 4x the shake is exactly the blur of x with k = 1.
    assert (reference.blur_length_mm(5.6, 4 * 4.39, 4.0, 0.3)
            == reference.blur_length_mm(5.6, 4.39, 1.0, 0.3))


@pytest.mark.parametrize("t_s", [1.0, 1.5, 2.0, 4.0, 1e9])
def test_blur_is_infinite_once_the_angle_reaches_a_quarter_turn(t_s):
    # 90 deg/s for 1 s is exactly pi/2 in float64 (deg2rad(90) == pi/2); beyond it tan would
    # wrap to finite or negative values, which docs/model.md forbids.
    assert np.deg2rad(90.0) == np.pi / 2
    assert reference.blur_length_mm(5.6, 90.0, 1.0, t_s) == math.inf


def test_blur_is_finite_just_below_a_quarter_turn():
    blur = float(reference.blur_length_mm(5.6, 90.0, 1.0, 1.0 - 1e-9))
    # 5.6 tan(pi/2 - 1.57e-9) = 5.6 / 1.57e-9 = 3.565e9 mm; 1e-6: the angle's own rounding.
    assert blur == pytest.approx(5.6 / (math.pi / 2 * 1e-9), rel=1e-6)


@pytest.mark.parametrize("options", BACKENDS)
def test_evaluate_reports_an_unbounded_blur_with_zero_f50_and_epc(options):
    # 0.01 lux at the 1.4 um corner: T_MPE ~ 2500 s, shake angle ~ 190 rad >> pi/2.
    r = epc_fast.evaluate(0.01, 1.4, 2.8, 5.6, sensor_area_mm2=15.6751, **options)
    assert (r.status, r.blur_mm, r.f50_cyc_per_mm, r.epc) == (Status.BLUR_UNBOUNDED, math.inf,
                                                               0.0, 0.0)


# --- f50 (docs/model.md, "The cut-off frequency f50") ---------------------------------------------


def bracket(f_number=2.8, wavelength_nm=550.0, pitch_um=1.4, fill_factor=1.0, blur_mm=0.0,
            jitter_um=0.0, threshold=0.5):
    a = np.asarray
    return float(reference.f50_bracket(a(f_number), a(wavelength_nm), a(pitch_um), a(fill_factor),
                                       a(blur_mm), a(jitter_um), a(threshold)))


@pytest.mark.parametrize("kwargs, expected", [
    (dict(), 1 / (550e-6 * 2.8)),  # diffraction 649.35 < pixel 714.29
    (dict(pitch_um=2.0, fill_factor=0.81), 1 / (0.9 * 2.0e-3)),  # pixel 555.6
    (dict(blur_mm=0.01), 1 / 0.01),  # motion 100
    (dict(jitter_um=1.5), math.sqrt(math.log(2) / (2 * math.pi**2)) / 1.5e-3),  # jitter 124.9
])
def test_f50_bracket_ends_at_the_smallest_first_zero(kwargs, expected):
    # 1e-15 relative: each candidate is a product or quotient of a few rounded factors.
    assert bracket(**kwargs) == pytest.approx(expected, rel=1e-15)


@pytest.mark.parametrize("pitch_um", [1.4, 1.75, 2.8])
def test_pixel_only_f50_is_0_6034_over_the_pitch(pitch_um):
    pitch_mm = pitch_um * 1e-3
    f50 = reference.f50_bisection(lambda f: np.abs(reference.sinc(pitch_mm * f)),
                                  np.array(1.0 / pitch_mm), 0.5)
    # 1e-15 relative: bisection ends on adjacent floats; sinc rounds within ~2e-16 there and
    # its log slope at the crossing is -1.3, and pitch_mm carries one rounding.
    assert float(f50) == pytest.approx(float(X50 / (mpmath.mpf(pitch_um) / 1000)), rel=1e-15)


@pytest.mark.parametrize("f_number, wavelength_nm", [(2.8, 550.0), (4.9, 550.0), (16.0, 480.0)])
def test_diffraction_only_f50_is_nu50_over_lambda_f(f_number, wavelength_nm):
    f_hi = bracket(f_number=f_number, wavelength_nm=wavelength_nm, pitch_um=1e-12)
    f50 = reference.f50_bisection(
        lambda f: reference.mtf_diffraction(f, wavelength_nm, f_number), np.array(f_hi), 0.5)
    expected = NU50 / (mpmath.mpf(wavelength_nm) / 10**6 * mpmath.mpf(f_number))
    # 1e-15 relative: as for the pixel; D's log slope at nu50 is -1.5.
    assert float(f50) == pytest.approx(float(expected), rel=1e-15)


@pytest.mark.parametrize("threshold", [0.5, 0.1, 0.9])
def test_jitter_only_f50_is_the_gaussian_closed_form(threshold):
    sigma_um = 1.5
    expected = mpmath.sqrt(mpmath.log(1 / mpmath.mpf(threshold))
                           / (2 * mpmath.pi**2 * (mpmath.mpf(sigma_um) / 1000) ** 2))
    # A bracket three times wider than the answer, so that bisection has work to do.
    f50 = reference.f50_bisection(lambda f: reference.mtf_jitter(f, sigma_um),
                                  np.array(3 * float(expected)), threshold)
    # 2e-15 relative: bisection ends on adjacent floats, where exp and its argument leave ~3e-16
    # relative error in J; J's log slope is -2 ln(1/c), only -0.21 at c = 0.9, which turns that
    # into ~1.4e-15 in f50 (seen: 3.3e-16).
    assert float(f50) == pytest.approx(float(expected), rel=2e-15)


@pytest.mark.parametrize("options", BACKENDS)
@pytest.mark.parametrize("fill_factor", [1.0, 0.3])
def test_evaluate_without_diffraction_or_motion_gives_the_pixel_f50(options, fill_factor):
    # lambda = 1e-20 nm: nu ~ 1e-24 at f50, so D = 1 to the last bit; no shake, no jitter.
    r = epc_fast.evaluate(1000.0, 1.75, 2.8, 5.6, pixel_count=1e6, fill_factor=fill_factor,
                          shake_deg_per_s=0.0, wavelength_nm=1e-20, **options)
    expected = X50 / (mpmath.sqrt(mpmath.mpf(fill_factor)) * mpmath.mpf(1.75) / 1000)
    # 1e-14 relative: the core bisects until hi - lo <= 1e-14 lo (f50_rtol), so its midpoint is
    # within 5e-15; the reference goes to adjacent floats.
    assert r.f50_cyc_per_mm == pytest.approx(float(expected), rel=1e-14)


@pytest.mark.parametrize("options", BACKENDS)
def test_evaluate_with_a_vanishing_pixel_gives_the_diffraction_f50(options):
    # Pitch 1e-12 um: sinc(1e-15 * 260) = 1 to the last bit; no shake, no jitter.
    r = epc_fast.evaluate(1000.0, 1e-12, 2.8, 5.6, pixel_count=1e6, shake_deg_per_s=0.0,
                          **options)
    expected = NU50 / (mpmath.mpf(550) / 10**6 * mpmath.mpf(2.8))
    # 1e-14 relative: as above.
    assert r.f50_cyc_per_mm == pytest.approx(float(expected), rel=1e-14)


# --- EPC (docs/model.md, "EPC") -------------------------------------------------------------------


def test_epc_of_a_sensor_of_n_pixels_is_n_times_f50_over_nyquist_squared():
    n_pixels, pitch_mm = 5038848.0, 1.75e-3
    f50 = np.array([1.0, 63.57, 285.7, 400.0])  # 285.7 = Nyquist 1/(2p): EPC = N
    nyquist = 1 / (2 * pitch_mm)
    # 1e-15 relative: two products of a few rounded factors each side.
    np.testing.assert_allclose(reference.effective_pixel_count(n_pixels * pitch_mm**2, f50),
                               n_pixels * (f50 / nyquist) ** 2, rtol=1e-15, atol=0)


@pytest.mark.parametrize("options", BACKENDS)
def test_evaluate_epc_is_n_times_f50_over_nyquist_squared(options):
    n_pixels, pitch_um = 7680000.0, 1.4
    r = epc_fast.evaluate(3000.0, pitch_um, 2.8, 5.6, pixel_count=n_pixels, **options)
    nyquist = 1 / (2 * pitch_um * 1e-3)
    # 1e-15 relative: S = N p^2 and 4 S f50^2 against N (f50 / f_Nyq)^2, ~4 roundings a side.
    assert r.epc == pytest.approx(n_pixels * (r.f50_cyc_per_mm / nyquist) ** 2, rel=1e-15)


@pytest.mark.parametrize("options", BACKENDS)
def test_evaluate_gives_the_same_epc_for_pixel_count_and_its_area(options):
    n_pixels, pitch_um = 7680000.0, 1.4
    by_count = epc_fast.evaluate(3000.0, pitch_um, 2.8, 5.6, pixel_count=n_pixels, **options)
    by_area = epc_fast.evaluate(3000.0, pitch_um, 2.8, 5.6,
                                sensor_area_mm2=n_pixels * (pitch_um * 1e-3) ** 2, **options)
    # 1e-15 relative: the two areas are N p^2 rounded in different orders.
    assert by_count.epc == pytest.approx(by_area.epc, rel=1e-15)


# --- Binning and bursts (docs/model.md, "Exposure: T_MPE", "Blur during the exposure", "System MTF")

#: The paper's 1.4 um design with every sensor term on, over a range of light.
SENSOR = dict(illuminance_lux=np.geomspace(1.0, 1e5, 41), pixel_pitch_um=1.4, f_number=2.8,
              focal_length_mm=5.6, sensor_area_mm2=15.6751, read_noise_e=2.5,
              dark_current_e_per_s=20.0, prnu=0.01, full_well_e=6000.0, jitter_um=0.3,
              fill_factor=0.8)
DEFAULT_OUTPUTS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                   "epc", "status", "cause")
PRECISIONS = [pytest.param(dict(backend="core"), id="core"),
              pytest.param(dict(backend="core", precision="float32"), id="core-float32"),
              pytest.param(dict(backend="reference"), id="reference")]


@pytest.mark.parametrize("options", PRECISIONS)
@pytest.mark.parametrize("off", [dict(binning=1.0, frames=1.0),
                                 dict(binning=np.ones(41), frames=np.ones(41)),
                                 dict(frames=1.0, alignment_error_um=3.0)],
                         ids=["broadcast", "per point", "one frame, misaligned"])
def test_one_pixel_and_one_frame_are_todays_model_bit_for_bit(off, options):
    # k = n = 1, broadcast or per point (a block that then takes the binning and burst path),
    # and an alignment error with one frame (never blurred by its alignment): the same bits
    today = epc_fast.evaluate(**SENSOR, **options)
    same = epc_fast.evaluate(**SENSOR, **off, **options)
    for name in DEFAULT_OUTPUTS:
        np.testing.assert_array_equal(getattr(same, name), getattr(today, name), err_msg=name)


@pytest.mark.parametrize("k", [2.0, 3.0, 4.0, 7.0])
def test_the_binned_pixel_at_full_fill_is_sinc_of_k_pitches(k):
    f = np.linspace(0.0, 1.0 / (k * 1.4e-3), 1001)  # up to its first zero 1/(k p)
    got = reference.mtf_binned_pixel(f, 1.4, 1.0, k)
    expected = np.abs(reference.sinc(k * 1.4e-3 * f))
    # sinc(p f) sin(k pi p f) / (k sin(pi p f)): a few roundings from the one sinc, and near
    # the zero the rounding of k p f (an absolute 1e-16 there)
    np.testing.assert_allclose(got, expected, rtol=1e-14, atol=4e-16)


def test_the_binned_pixel_takes_its_limit_where_sin_pi_p_f_vanishes():
    # p f = 1, 2: sin(k pi p f) / (k sin(pi p f)) -> cos(k pi p f) / cos(pi p f) = +-1
    f = np.array([1.0, 2.0]) / 1.4e-3
    for k in (2.0, 3.0):
        ratio = reference.mtf_binned_pixel(f, 1.4, 0.36, k) / reference.mtf_pixel(f, 1.4, 0.36)
        np.testing.assert_allclose(ratio, 1.0, rtol=1e-15)
    assert reference.mtf_binned_pixel(0.0, 1.4, 0.6, 4.0) == 1.0


@pytest.mark.parametrize("options", BACKENDS)
@pytest.mark.parametrize("k", [2.0, 4.0])
def test_binning_at_full_fill_gives_the_pixel_f50_of_k_pitches(options, k):
    # no diffraction (1e-20 nm), no motion, no jitter: f50 = X50 / (k p)
    r = epc_fast.evaluate(1000.0, 1.75, 2.8, 5.6, pixel_count=1e6, binning=k,
                          shake_deg_per_s=0.0, wavelength_nm=1e-20, **options)
    expected = X50 / (k * mpmath.mpf(1.75) / 1000)
    assert r.f50_cyc_per_mm == pytest.approx(float(expected), rel=1e-14)  # as for one pixel


@pytest.mark.parametrize("options", BACKENDS)
def test_binning_below_full_fill_gives_the_f50_of_the_binned_aperture(options):
    k, a, p_mm = 3.0, 0.5, mpmath.mpf(1.75) / 1000
    r = epc_fast.evaluate(1000.0, 1.75, 2.8, 5.6, pixel_count=1e6, binning=k, fill_factor=a,
                          shake_deg_per_s=0.0, wavelength_nm=1e-20, **options)

    def binned(f):
        return (mpmath.sincpi(mpmath.sqrt(a) * p_mm * f) * mpmath.sinpi(k * p_mm * f)
                / (k * mpmath.sinpi(p_mm * f)))

    expected = mpmath.findroot(lambda f: binned(f) - mpmath.mpf(1) / 2, 0.5 / (k * p_mm))
    assert r.f50_cyc_per_mm == pytest.approx(float(expected), rel=1e-13)


@pytest.mark.parametrize("options", BACKENDS)
def test_charge_binning_reads_once_where_digital_binning_reads_k_squared_times(options):
    # read noise alone: digital binning's k^2 reads of sigma_r are one read of k sigma_r
    k, read = 3.0, 2.0
    base = dict(illuminance_lux=np.geomspace(1.0, 1e4, 9), pixel_pitch_um=1.4, f_number=2.8,
                focal_length_mm=5.6, pixel_count=8e6, binning=k, **options)
    digital = epc_fast.evaluate(**base, read_noise_e=read)
    charge = epc_fast.evaluate(**base, read_noise_e=read, binning_readout="charge")
    charge_of_k_sigma = epc_fast.evaluate(**base, read_noise_e=k * read,
                                          binning_readout="charge")
    np.testing.assert_allclose(digital.electrons, charge_of_k_sigma.electrons, rtol=4e-16)
    assert np.all(charge.electrons < digital.electrons)
    # without read noise the read-out does not matter, bit for bit
    quiet = epc_fast.evaluate(**base)
    quiet_charge = epc_fast.evaluate(**base, binning_readout="charge")
    np.testing.assert_array_equal(quiet.t_mpe_s, quiet_charge.t_mpe_s)


@pytest.mark.parametrize("options", BACKENDS)
def test_binning_sums_the_rate_and_dark_current_and_divides_the_prnu(options):
    k = 2.0
    one = epc_fast.evaluate(**SENSOR, **options)
    binned = epc_fast.evaluate(**SENSOR, binning=k, **options)
    np.testing.assert_array_equal(binned.electron_rate_e_per_s,
                                  one.electron_rate_e_per_s * (k * k))
    # PRNU 0.04 caps 30 dB (0.04 sqrt(1000) = 1.26 > 1); binned 2 x 2 it is 0.02: reachable
    capped = epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, pixel_count=8e6, prnu=0.04, **options)
    freed = epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, pixel_count=8e6, prnu=0.04, binning=k,
                              **options)
    assert (capped.status, capped.cause) == (Status.UNREACHABLE, Cause.PRNU)
    assert freed.status == Status.OK
    # the electrons the binned pixel needs: the quadratic with k^2 r, k^2 D, u / k, k^2 sigma^2
    rate = binned.electron_rate_e_per_s
    expected = [mp_signal_electrons(r, 30.0, 2.5 * k, 20.0 * k * k, 0.01 / k) for r in rate]
    np.testing.assert_allclose(binned.electrons, [float(e) for e in expected], rtol=1e-14)


@pytest.mark.parametrize("options", BACKENDS)
@pytest.mark.parametrize("n", [2.0, 8.0, 1e6])
def test_a_burst_without_read_noise_or_motion_needs_the_time_of_one_frame(options, n):
    # shot, dark and PRNU noise are those of the total time: only the reads depend on n
    base = dict(SENSOR, read_noise_e=0.0, shake_deg_per_s=0.0, full_well_e=math.inf)
    one = epc_fast.evaluate(**base, **options)
    burst = epc_fast.evaluate(**base, frames=n, **options)
    np.testing.assert_array_equal(burst.t_mpe_s, one.t_mpe_s)
    np.testing.assert_array_equal(burst.electrons, one.electrons)


@pytest.mark.parametrize("options", BACKENDS)
def test_a_burst_reads_n_times_and_fills_each_frame_with_its_share(options):
    n, read = 4.0, 3.0
    base = dict(illuminance_lux=100.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
                pixel_count=8e6, **options)
    burst = epc_fast.evaluate(**base, read_noise_e=read, frames=n)
    one_read_of_2_sigma = epc_fast.evaluate(**base, read_noise_e=read * math.sqrt(n))
    assert burst.electrons == pytest.approx(one_read_of_2_sigma.electrons, rel=4e-16)
    # 1000 e- at 30 dB: a full well of 999 e- is too small for one frame, not for two
    assert epc_fast.evaluate(**base, full_well_e=999.0).cause == Cause.FULL_WELL
    assert epc_fast.evaluate(**base, full_well_e=999.0, frames=2.0).status == Status.OK
    assert epc_fast.evaluate(**base, full_well_e=499.0, frames=2.0).cause == Cause.FULL_WELL


@pytest.mark.parametrize("options", BACKENDS)
def test_each_frame_is_blurred_by_its_own_share_of_the_exposure(options):
    # b = f_L tan(omega / k_IS T / n): n frames blur as a stabilisation n times stronger
    base = dict(illuminance_lux=np.geomspace(1.0, 1e4, 9), pixel_pitch_um=1.4, f_number=2.8,
                focal_length_mm=5.6, pixel_count=8e6, **options)
    burst = epc_fast.evaluate(**base, frames=8.0, stabilization=2.0)
    stabilised = epc_fast.evaluate(**base, stabilization=16.0)
    np.testing.assert_array_equal(burst.blur_mm, stabilised.blur_mm)
    np.testing.assert_array_equal(burst.f50_cyc_per_mm, stabilised.f50_cyc_per_mm)


def test_the_alignment_factor_is_the_gaussian_of_the_frames_offsets_about_their_mean():
    f = np.linspace(0.0, 400.0, 81)
    sigma_um, n = 1.5, 8.0
    expected = np.exp(-2.0 * np.pi**2 * (sigma_um * 1e-3) ** 2 * (1.0 - 1.0 / n) * f**2)
    np.testing.assert_allclose(reference.mtf_alignment(f, sigma_um, n), expected, rtol=1e-15)
    # one frame is never blurred by its alignment
    np.testing.assert_array_equal(reference.mtf_alignment(f, sigma_um, 1.0), 1.0)


@pytest.mark.parametrize("n", [2, 4, 8])
def test_the_alignment_residuals_variance_under_each_description_of_the_error(n):
    # docs/model.md, "System MTF": the summed burst is blurred by its frames' spread about their
    # mean. Each frame's own error iid of rms s (alignment_error_um): s^2 (1 - 1/n), registered
    # to frame 1 or not (e_i - e_1 is a common shift away); independent registration errors
    # of rms s against an exact reference frame (positions 0, eps_2, ..., eps_n):
    # s^2 (1 - 1/n)^2. Monte Carlo over 4e5 bursts: a spread's relative standard error is at
    # most sqrt(2 / (n - 1)) / sqrt(4e5) = 0.22 %, so 1 % is 4.5 of them.
    rng = np.random.default_rng(54)
    e = rng.normal(0.0, 1.0, (400_000, n))
    spread = lambda x: np.mean(np.var(x, axis=1))  # noqa: E731  E[(1/n) sum (x_i - mean)^2]
    assert spread(e) == pytest.approx(1.0 - 1.0 / n, rel=0.01)
    assert spread(e - e[:, :1]) == pytest.approx(1.0 - 1.0 / n, rel=0.01)
    to_reference = np.concatenate([np.zeros((e.shape[0], 1)), e[:, 1:]], axis=1)
    assert spread(to_reference) == pytest.approx((1.0 - 1.0 / n) ** 2, rel=0.01)


@pytest.mark.parametrize("options", BACKENDS)
def test_a_bursts_alignment_blurs_as_jitter_of_its_residual_rms(options):
    # no diffraction, a vanishing pixel, no motion: f50 of the Gaussian of rms
    # sigma_a sqrt(1 - 1/n) alone, sqrt(ln 2 / (2 pi^2)) / sigma
    sigma_um, n = 1.5, 4.0
    r = epc_fast.evaluate(1000.0, 1e-9, 2.8, 5.6, pixel_count=1e6, frames=n,
                          alignment_error_um=sigma_um, shake_deg_per_s=0.0, wavelength_nm=1e-20,
                          **options)
    residual_mm = mpmath.mpf(sigma_um) / 1000 * mpmath.sqrt(1 - 1 / mpmath.mpf(n))
    expected = mpmath.sqrt(mpmath.log(2) / (2 * mpmath.pi**2)) / residual_mm
    assert r.f50_cyc_per_mm == pytest.approx(float(expected), rel=1e-14)


def test_the_cores_binned_pixel_alignment_and_gaussian_are_the_references():
    f = np.linspace(0.0, 1.0 / (3 * 1.4e-3), 201)
    for fill, k in ((1.0, 3.0), (0.5, 3.0), (0.5, 1.0)):
        aperture_mm = math.sqrt(fill) * 1.4e-3
        pitch_mm = 1.4e-3 if k > 1 else 0.0  # the core's array factor: none at k = 1
        # the core's sinc(k p f) / sinc(p f) against sin(k pi p f) / (k sin(pi p f)): 1e-14
        np.testing.assert_allclose(_core.testing.mtf_binned_pixel(f, aperture_mm, pitch_mm, k),
                                   reference.mtf_binned_pixel(f, 1.4, fill, k), rtol=1e-14,
                                   atol=1e-15)
    # exp_poly against NumPy's exp: a few ulp
    np.testing.assert_allclose(_core.testing.mtf_alignment(f, 2e-3, 8.0),
                               reference.mtf_alignment(f, 2.0, 8.0), rtol=1e-15)
    jitter, residual, frames = np.array([0.0, 0.3, 5.0, 1e300]), 1.0, 4.0
    np.testing.assert_allclose(_core.testing.gaussian_blur_mm(jitter, residual, frames),
                               reference.gaussian_blur_mm(jitter, residual, frames), rtol=4e-16)
    # without a residual, the jitter itself
    np.testing.assert_array_equal(_core.testing.gaussian_blur_mm(jitter, 0.0, frames),
                                  jitter * 1e-3)
