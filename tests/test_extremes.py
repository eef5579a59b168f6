"""The engine at the extremes of its domain, on both backends, against mpmath (docs/numerics.md).

Each group below holds one numerical hazard of the model: sinc and the diffraction MTF near
their zeros, the quadratic root for T_MPE for every sign pattern, the PRNU cap, tan near a
right angle, rates that underflow and exposures that overflow, subnormal inputs, f50 at the
end of its bracket, the full well at the electrons needed, grazing field angles. The last
test measures the worst error over the extreme region and prints the table that
docs/numerics.md quotes:

    python -m pytest tests/test_extremes.py -k worst_case -s -q

Accuracy is judged against the conditioning of each point: an answer is right when it is
within C (kappa + 1) u of the exact value, u = 2^-53 the unit roundoff and kappa the sum over
the inputs of |d ln output / d ln input| (:func:`condition_numbers`), i.e. as close as a
rounding of every input would allow, plus the bisection tolerance for f50 and EPC.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath as mp
import numpy as np
import pytest

import epc_fast
from epc_fast import Cause, Status, _core, params, reference
from helpers.conditioning import OUTPUTS, condition_numbers, evaluate_quietly
from helpers.designs import box_corners, parameter_defaults
from helpers.mp_model import (LARGEST, MP_DPS, SMALLEST_NORMAL, expected_status, mp_diffraction,
                              mp_model, mp_signal_electrons, relative_error)

U = 2.0**-53  # unit roundoff
#: C in C (kappa + 1) u: the measured worst is 1.4 (reference and f50_rtol=0 core, table below);
#: 8 leaves room for the few roundings a formula may add without letting a lost digit through.
C_ROUNDINGS = 8.0
#: The core's default f50 bisection tolerance: its midpoint is within half of it.
F50_RTOL = 1e-14

BACKENDS = [pytest.param(dict(backend="core"), id="core"),
            pytest.param(dict(backend="core", t_mpe_solver="brent"), id="core-brent"),
            pytest.param(dict(backend="reference"), id="reference")]

#: An OK design with every term on (the paper's 1.4 um design at 1000 lux, on axis).
DESIGN = dict(illuminance_lux=1000.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
              sensor_area_mm2=15.6751, electrons_per_lux_s_m2=2.5577e15)
DEFAULTS = parameter_defaults()

# The model of docs/model.md in mpmath, statuses included, is helpers/mp_model.py (50 digits);
# the condition numbers kappa are helpers/conditioning.py's.
mp.mp.dps = MP_DPS  # every mpf below, errors included, at 50 digits (as in the reference tests)


def allowed_error(output, kappa, f50_rtol):
    """Relative error owed at condition number kappa: C (kappa + 1) u, plus half the bisection
    tolerance for f50 (the midpoint of a bracket of relative width f50_rtol), twice that for
    EPC (f50 squared)."""
    bisection = {"t_mpe_s": 0.0, "f50_cyc_per_mm": 0.5, "epc": 1.0}[output] * f50_rtol
    return C_ROUNDINGS * (kappa + 1.0) * U + bisection


def points_of(designs):
    """A list of keyword dicts (same keys) as one dict of arrays."""
    return {k: np.array([d[k] for d in designs], dtype=np.float64) for k in designs[0]}


def full(**changes):
    """DESIGN with every default spelled out (so that points_of sees every key) and changes."""
    return {**DEFAULTS, "full_well_e": math.inf, **DESIGN, **changes}


def assert_within_conditioning(designs, options, label):
    """Every OK point of `designs` within allowed_error of mpmath, for T_MPE, f50 and EPC."""
    points = points_of(designs)
    result = evaluate_quietly(**points, **options)
    kappa = condition_numbers(points)
    f50_rtol = options.get("f50_rtol", F50_RTOL) if options.get("backend") == "core" else 0.0
    checked = 0
    for i, design in enumerate(designs):
        model = mp_model(design)
        assert (Status(result.status[i]), Cause(result.cause[i])) == expected_status(model), (
            label, design)
        if model["status"] != "ok":
            continue
        for out in OUTPUTS:
            err = relative_error(getattr(result, out)[i], model[out])
            bound = allowed_error(out, kappa[out][i], f50_rtol)
            assert err <= bound, (f"{label}: {out} off by {err:.3g} (allowed {bound:.3g}, "
                                  f"kappa {kappa[out][i]:.3g}) at {design}")
        checked += 1
    return checked


# --- sinc and the diffraction MTF near their zeros -----------------------------------------------


def test_reference_sinc_keeps_relative_accuracy_next_to_its_zeros():
    # sin(pi x) is formed from x - round(x), which is exact: no digit of the distance to the
    # zero is lost (np.sin(np.pi * x) would keep only ~1e-16 / distance of them).
    x = np.array([n + d for n in (1.0, 2.0, 7.0) for d in (2.0**-40, -(2.0**-30), 1e-9, -1e-6)])
    exact = [mp.sincpi(mp.mpf(v)) for v in x]
    err = max(relative_error(a, b) for a, b in zip(reference.sinc(x), exact))
    # 4 u: pi r, sin and pi x each round once, and the quotient once more.
    assert err <= 4 * U


DIFFRACTION = [pytest.param(_core.testing.mtf_diffraction, id="core"),
               pytest.param(lambda nu: reference.mtf_diffraction(nu, 1e6, 1.0), id="reference")]


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_keeps_its_relative_precision_down_to_the_cut_off(mtf):
    # Before: acos(nu) - nu sqrt(1 - nu^2) cancelled, leaving ~1e-16 absolute (at 1 - nu = 1e-12
    # a relative error of 1e-1). Now both backends write D near nu = 1 in sin(phi/2).
    nu = np.concatenate([1.0 - np.logspace(-16, -1, 61), np.linspace(0.5, 0.999, 50)])
    err = max(relative_error(v, mp_diffraction(n)) for v, n in zip(mtf(nu), nu))
    # 8 u: tools/fit_polynomials.py measures the core at <= 6 ulp; the reference's arcsin, sqrt
    # and series add about as many roundings. D's own conditioning in nu (1.5 nu / (1 - nu))
    # does not enter: nu is taken exactly.
    assert err <= 8 * U


@pytest.mark.parametrize("mtf", DIFFRACTION)
def test_diffraction_mtf_is_continuous_and_decreasing_where_its_two_forms_meet(mtf):
    # nu = 1/2 switches between the textbook form and the sin(phi/2) form: the bisection needs
    # D strictly decreasing across it.
    nu = 0.5 + np.arange(-64, 65) * 2.0**-53
    d = mtf(nu)
    assert np.all(np.diff(d) <= 0)
    assert d[0] - d[-1] <= 4 * 128 * 2.0**-53  # |D'| = 1.1 at 1/2: no jump, just the slope


# --- T_MPE: the quadratic root for every sign pattern --------------------------------------------


def mp_electrons_condition(args):
    """sum_x |d ln E / d ln x| over the five inputs, by exact central differences."""
    base, h, total = mp_signal_electrons(*args), mp.mpf(10) ** -25, mp.mpf(0)
    for k, value in enumerate(args):
        if value == 0:
            continue
        up = list(args)
        down = list(args)
        up[k] = mp.mpf(value) * (1 + h)
        down[k] = mp.mpf(value) * (1 - h)
        total += abs((mp_signal_electrons(*up) - mp_signal_electrons(*down)) / (2 * h * base))
    return float(total)


SIGN_PATTERNS = [(read, dark, prnu_fraction)
                 for read in (0.0, 3.0, 1e29) for dark in (0.0, 50.0, 1e29)
                 for prnu_fraction in (0.0, 0.5, 0.999999)]


@pytest.mark.parametrize("read, dark, prnu_fraction", SIGN_PATTERNS)
def test_electrons_needed_match_the_mpmath_root_for_every_sign_pattern(read, dark,
                                                                        prnu_fraction):
    # Read noise, dark current and PRNU each on or off (and huge), over targets from -3000 to
    # +1000 dB and rates from the smallest normal double to 1e160 e-/s: the closed form of both
    # backends and the core's Brent against the exact root.
    cases = [(rate, snr, read, dark, prnu_fraction * 10.0 ** (-snr / 20))
             for rate in (SMALLEST_NORMAL, 1e-200, 1.0, 1e100, 1e160)
             for snr in (-3000.0, -300.0, 0.0, 30.0, 33.0, 300.0, 1000.0)]
    args = [np.array(column) for column in zip(*cases)]
    with mp.workdps(60):
        exact = [mp_signal_electrons(*case) for case in cases]
        kappa = [mp_electrons_condition(case) for case in cases]
    for name, values in [("core", _core.testing.signal_electrons(*args)),
                         ("core-brent", _core.testing.signal_electrons_brent(*args, 0.0)),
                         ("reference", reference.signal_electrons(*args))]:
        for value, e, k, case in zip(values, exact, kappa, cases):
            if e > LARGEST:  # e.g. D/r = 2e309: the answer itself overflows
                assert value == math.inf, (name, case, value)
                continue
            err = relative_error(value, e)
            assert err <= C_ROUNDINGS * (k + 1) * U, (name, case, err, k)


@pytest.mark.parametrize("options", BACKENDS)
def test_the_prnu_cap_is_decided_exactly_where_sqrt_s_is_a_double(options):
    # At 20 k dB, sqrt(s) = 10^k is a double (k <= 22), so u sqrt(s) >= 1 is decided on the
    # exact product: the double next below fl(10^-k) is reachable even where u * 10^k rounds
    # to 1.0 (e.g. PRNU 1e-6 at 120 dB is 4.5e-23 short of the cap, so not PRNU-capped).
    designs, capped = [], []
    for k in range(23):
        threshold = 10.0 ** -k
        for step in range(-3, 4):
            u = threshold + step * float(np.spacing(threshold))
            designs.append(full(prnu=u, snr_db=20.0 * k, illuminance_lux=1e5,
                                shake_deg_per_s=0.0))
            capped.append(Fraction(u) * 10**k >= 1)
    r = evaluate_quietly(**points_of(designs), **options)
    np.testing.assert_array_equal((r.status == Status.UNREACHABLE) & (r.cause == Cause.PRNU),
                                  np.array(capped))
    assert not np.any(r.status == Status.INVALID)


@pytest.mark.parametrize("options", BACKENDS)
def test_t_mpe_near_the_prnu_cap_is_within_its_conditioning(options):
    # u sqrt(s) = 1 - delta: T_MPE grows as 1/delta and so does its sensitivity to the inputs
    # (kappa ~ 1/delta). w = 1 - s u^2 is formed from the exact product u sqrt(s), so only the
    # rounding of 10^(snr_db/20) itself is amplified.
    designs = [full(snr_db=snr, prnu=float((1 - mp.mpf(10) ** -k) / mp.mpf(10) ** (snr / 20)),
                    illuminance_lux=1e5, shake_deg_per_s=0.0)
               for snr in (30.0, 40.0, 60.0) for k in range(1, 16)]
    assert assert_within_conditioning(designs, options, "PRNU cap") == len(designs)


# --- tan near a right angle ---------------------------------------------------------------------


def test_an_angle_of_exactly_fl_pi_over_2_is_unbounded_and_the_double_below_it_is_not():
    # fl(pi/2) is 6.1e-17 below pi/2, but "reaches pi/2" compares with fl(pi/2): documented.
    # 90 deg/s for 1 s is exactly fl(pi/2) (reference/test_model.py); the double below gives tan
    # of an angle 2.8e-16 short of pi/2: 3.6e15, times f_L.
    below = float(np.nextafter(1.0, 0.0))
    blur = reference.blur_length_mm(5.6, 90.0, 1.0, np.array([1.0, below]))
    assert blur[0] == math.inf
    with mp.workdps(40):
        exact = 5.6 * mp.tan(mp.mpf(90) * mp.pi / 180 * mp.mpf(below))
    # The condition of tan there is 1/(pi/2 - x) x ~ 6e15: the angle's two roundings (pi/180,
    # the product) move it by ~2e-16 / 2.8e-16 of the distance: a few tens of percent.
    assert 0.5 < blur[1] / float(exact) < 2.0


@pytest.mark.parametrize("options", BACKENDS)
def test_angles_far_past_a_right_angle_stay_unbounded_and_never_wrap(options):
    # tan has period pi: an angle of 1e300 rad must not come back as a finite blur.
    t = evaluate_quietly(**DESIGN, **options).t_mpe_s
    shake = np.rad2deg(np.pi / 2 / t) * np.array([1.0 + 1e-12, 2.0, 3.0, 4.0, 1e6, 1e20])
    r = evaluate_quietly(**{**DESIGN, "shake_deg_per_s": shake}, **options)
    assert np.all(r.status == Status.BLUR_UNBOUNDED)
    assert np.all(r.blur_mm == math.inf) and np.all(r.f50_cyc_per_mm == 0) and np.all(r.epc == 0)


@pytest.mark.parametrize("options", BACKENDS)
def test_blur_near_a_right_angle_is_within_its_conditioning(options):
    t = evaluate_quietly(**DESIGN, **options).t_mpe_s
    designs = [full(shake_deg_per_s=float(mp.mpf(90) / mp.mpf(t) * (1 - mp.mpf(10) ** -k)))
               for k in range(1, 14)]
    assert assert_within_conditioning(designs, options, "right angle") == len(designs)


# --- Rates that underflow, exposures that overflow, the largest rate ----------------------------


@pytest.mark.parametrize("options", BACKENDS)
def test_a_rate_below_the_smallest_normal_double_is_no_light(options):
    # The rate is proportional to the illuminance: scale it around 2.2e-308 e-/s. Below, the
    # rate would carry too few digits to divide by; it is reported 0 (no light).
    unit = evaluate_quietly(**{**DESIGN, "illuminance_lux": 1.0}, **options).electron_rate_e_per_s
    lux = SMALLEST_NORMAL / unit * np.array([0.25, 0.999, 1.001, 4.0])
    r = evaluate_quietly(**{**DESIGN, "illuminance_lux": lux}, snr_db=-3000.0,
                         shake_deg_per_s=0.0, **options)
    np.testing.assert_array_equal(r.electron_rate_e_per_s[:2], [0.0, 0.0])
    assert np.all(r.electron_rate_e_per_s[2:] >= SMALLEST_NORMAL)
    assert r.status.tolist() == [Status.UNREACHABLE] * 2 + [Status.OK] * 2
    assert r.cause.tolist() == [Cause.NO_LIGHT] * 2 + [Cause.NONE] * 2
    assert np.all(np.isfinite(r.t_mpe_s[2:]))


@pytest.mark.parametrize("options", BACKENDS)
def test_an_exposure_beyond_the_largest_double_is_no_light_and_the_one_below_is_finite(options):
    # Shot noise only at 1000 dB needs 1e100 electrons; at a rate of 1e-208 e-/s that is 1e308 s,
    # just under the largest double (1.8e308); at 1e-209 e-/s it is beyond.
    unit = evaluate_quietly(**{**DESIGN, "illuminance_lux": 1.0}, **options).electron_rate_e_per_s
    lux = np.array([1e-208, 1e-209]) / unit
    r = evaluate_quietly(**{**DESIGN, "illuminance_lux": lux}, snr_db=1000.0,
                         shake_deg_per_s=0.0, **options)
    assert (r.status[0], r.cause[0]) == (Status.OK, Cause.NONE)
    assert 1e307 < r.t_mpe_s[0] < LARGEST and r.electrons[0] == pytest.approx(1e100, rel=1e-13)
    assert (r.status[1], r.cause[1]) == (Status.UNREACHABLE, Cause.NO_LIGHT)
    assert r.t_mpe_s[1] == math.inf and math.isnan(r.electrons[1])


def _next_inside(param, end):
    value, closed = (param.lo, param.lo_closed) if end == "lo" else (param.hi, param.hi_closed)
    if closed:
        return value
    return float(np.nextafter(value, math.inf if end == "lo" else -math.inf))


@pytest.mark.parametrize("options", BACKENDS)
def test_the_brightest_corner_of_the_domain_has_a_finite_rate_and_exposure(options):
    # Illuminance, K and pitch just under 1e30, F just over 1e-30: the rate is 2.5e167 e-/s
    # (the bound params.py promises), computed without an intermediate overflow.
    table = {p.name: p for p in params.PARAMETERS}
    design = full(illuminance_lux=_next_inside(table["illuminance_lux"], "hi"),
                  electrons_per_lux_s_m2=_next_inside(table["electrons_per_lux_s_m2"], "hi"),
                  pixel_pitch_um=_next_inside(table["pixel_pitch_um"], "hi"),
                  f_number=_next_inside(table["f_number"], "lo"), reflectance=1.0)
    r = evaluate_quietly(**design, **options)
    model = mp_model(design)
    assert 1e167 < r.electron_rate_e_per_s < 3e167
    assert relative_error(r.electron_rate_e_per_s, model["electron_rate_e_per_s"]) <= 16 * U  # 13 roundings
    assert (r.status, r.cause) == expected_status(model)
    assert math.isfinite(r.t_mpe_s)


# --- Subnormal inputs ---------------------------------------------------------------------------

# (the lens index, a whole number, has no subnormal in its domain)
SUBNORMAL_CASES = [(p.name, value) for p in params.PARAMETERS if p.lo == 0.0 and p.name != "size"
                   and not p.integer
                   for value in (5e-324, 2.2e-310)]


@pytest.mark.parametrize("options", BACKENDS)
def test_a_subnormal_input_gives_the_status_and_values_mpmath_gives(options):
    # Every parameter whose domain reaches 0, at the smallest subnormal and a mid one: a rate
    # that underflows is no light; otherwise the outputs are finite and as accurate as the
    # point's conditioning allows (the products are scaled_products, so a subnormal factor
    # loses no digit of the others).
    designs = [full(**{name: value}) for name, value in SUBNORMAL_CASES]
    assert len(designs) == 36  # the 18 parameters whose domain reaches 0, two values each
    points = points_of(designs)
    r = evaluate_quietly(**points, **options)
    kappa = condition_numbers(points)
    f50_rtol = F50_RTOL if options["backend"] == "core" else 0.0
    for i, (case, design) in enumerate(zip(SUBNORMAL_CASES, designs)):
        model = mp_model(design)
        assert (Status(r.status[i]), Cause(r.cause[i])) == expected_status(model), case
        if r.status[i] != Status.OK:
            continue
        for out in ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm",
                    "f50_cyc_per_mm", "epc"):
            assert math.isfinite(getattr(r, out)[i]), (case, out)
        for out in OUTPUTS:
            err = relative_error(getattr(r, out)[i], model[out])
            assert err <= allowed_error(out, kappa[out][i], f50_rtol), (case, out, err)


# --- f50 at the end of its bracket --------------------------------------------------------------

#: Scenes where one factor alone sets the end of the bracket: the others are made negligible.
LIMITED_BY = {
    "diffraction": dict(pixel_pitch_um=1e-9, shake_deg_per_s=0.0),
    "pixel": dict(wavelength_nm=1e-9, shake_deg_per_s=0.0),
    "motion": dict(wavelength_nm=1e-9, pixel_pitch_um=1e-9, illuminance_lux=1e7,
                   shake_deg_per_s=50.0),
    "jitter": dict(wavelength_nm=1e-9, pixel_pitch_um=1e-9, shake_deg_per_s=0.0,
                   jitter_um=1.0),
}


@pytest.mark.parametrize("options", BACKENDS)
@pytest.mark.parametrize("factor", sorted(LIMITED_BY))
def test_f50_at_the_end_of_its_bracket_matches_mpmath(factor, options):
    # Thresholds down to 1e-300: f50 closes on the factor's first zero (or jitter's crossing).
    # The tiny-pixel scenes get their light from a 1e30 K, so that T_MPE stays finite.
    designs = [full(mtf_threshold=c, electrons_per_lux_s_m2=1e29, **LIMITED_BY[factor])
               for c in 10.0 ** -np.arange(1.0, 301.0, 23.0)]
    assert assert_within_conditioning(designs, options, factor) == len(designs)
    r = evaluate_quietly(**points_of(designs), **options)
    p = points_of(designs)
    f_hi = reference.f50_bracket(p["f_number"], p["wavelength_nm"], p["pixel_pitch_um"],
                                 p["fill_factor"], r.blur_mm, p["jitter_um"], p["mtf_threshold"])
    assert np.all(r.f50_cyc_per_mm <= f_hi * (1 + 4 * U))  # the backends' f_hi round alike


# --- The full well at the electrons needed ------------------------------------------------------


@pytest.mark.parametrize("options", BACKENDS)
@pytest.mark.parametrize("snr_db", [-3000.0, 30.0, 1000.0])
def test_a_full_well_of_exactly_the_electrons_needed_is_enough_at_any_scale(snr_db, options):
    # "r T_MPE > W" is strict: W equal to the electrons needed (1e-300 to 1e100 of them) is
    # reachable, the double below it is not; each solver compared with its own electrons.
    design = full(snr_db=snr_db, read_noise_e=3.0, dark_current_e_per_s=50.0, prnu=1e-60,
                  shake_deg_per_s=0.0, illuminance_lux=1e5)
    needed = evaluate_quietly(**design, **options).electrons
    walls = np.array([needed, float(np.nextafter(needed, 0.0)), float(np.nextafter(needed,
                                                                                    math.inf))])
    r = evaluate_quietly(**{**design, "full_well_e": walls}, **options)
    assert r.status.tolist() == [Status.OK, Status.UNREACHABLE, Status.OK]
    assert r.cause[1] == Cause.FULL_WELL and r.electrons[1] == needed


# --- Grazing field angles -----------------------------------------------------------------------


@pytest.mark.parametrize("options", BACKENDS)
def test_the_rate_keeps_its_digits_at_grazing_field_angles(options):
    # cos(theta) is formed as sin(90 deg - |theta|): exact argument. Before, cos(theta pi/180)
    # lost the digits of the distance to 90 deg: a relative error of 0.2 at 90 - 1e-13 deg.
    angles = 90.0 - 10.0 ** -np.arange(0.0, 14.0)
    designs = [full(field_angle_deg=sign * a, illuminance_lux=1e7, shake_deg_per_s=0.0)
               for a in angles for sign in (1.0, -1.0)]
    r = evaluate_quietly(**points_of(designs), **options)
    for i, design in enumerate(designs):
        # 16 u: a dozen roundings in the product and sin's own.
        assert relative_error(r.electron_rate_e_per_s[i], mp_model(design)["electron_rate_e_per_s"]) <= 16 * U


# --- The measurement quoted in docs/numerics.md -------------------------------------------------


def monte_carlo_corners(n, seed):
    """The corners a Monte Carlo scan samples: each parameter at an end of the physical box
    with probability 0.7 (1e-3 / 1e7 lux, 0.3 / 20 um, F/0.7 / F/64, 0 / 60 deg/s, 5 / 60 dB,
    ...: helpers.designs.box_corners)."""
    return box_corners(n, seed)


def whole_domain(n, seed):
    """Points spread over every parameter's whole domain (log-uniform over its float range up to
    the caps of params.py, subnormals, exact ends), each parameter drawn from that spread or
    from the physical box with equal odds."""
    rng = np.random.default_rng(seed)
    box = box_corners(n, seed + 1)

    def spread(lo, hi):
        return np.exp(rng.uniform(np.log(lo), np.log(hi), n))

    wide = {
        "illuminance_lux": spread(1e-300, 1e30), "pixel_pitch_um": spread(1e-300, 1e30),
        "f_number": spread(1e-30, 1e300), "focal_length_mm": spread(1e-300, 1e30),
        "sensor_area_mm2": spread(1e-300, 1e30), "reflectance": spread(1e-300, 1.0),
        "lens_transmittance": spread(1e-300, 1.0),
        "field_angle_deg": rng.choice([-1.0, 1.0], n) * (90.0 - spread(1e-13, 90.0)),
        "fill_factor": spread(1e-300, 1.0), "electrons_per_lux_s_m2": spread(1e-300, 1e30),
        "read_noise_e": spread(1e-300, 1e30), "dark_current_e_per_s": spread(1e-300, 1e30),
        "prnu": spread(1e-300, 1e3), "full_well_e": spread(1e-300, 1e300),
        "snr_db": rng.uniform(-3000.0, 1000.0, n), "shake_deg_per_s": spread(1e-300, 1e30),
        "stabilization": spread(1e-30, 1e300), "jitter_um": spread(1e-300, 1e300),
        "wavelength_nm": spread(1e-30, 1e300),
        "mtf_threshold": np.where(rng.random(n) < 0.5, spread(1e-300, 1.0),
                                  1.0 - spread(1e-4, 1.0)),
    }
    return {k: np.where(rng.random(n) < 0.5, wide[k], box[k]) for k in box}


REGIONS = {"Monte Carlo corners": (monte_carlo_corners, 1000, 4390),
           "whole domain": (whole_domain, 8000, 2009)}
MEASURED = [("core", dict(backend="core")),
            ("core, f50_rtol=0", dict(backend="core", f50_rtol=0.0)),
            ("core, Brent", dict(backend="core", t_mpe_solver="brent")),
            ("reference", dict(backend="reference"))]


def _measure(points, max_ok):
    """Per engine and output: the largest relative error against mpmath and the largest
    error / ((kappa + 1) u), over at most max_ok OK points; also the number of points used."""
    results = {label: evaluate_quietly(**points, **options) for label, options in MEASURED}
    ok = np.flatnonzero(results["reference"].status == Status.OK)[:max_ok]
    sub = {k: v[ok] for k, v in points.items()}
    kappa = condition_numbers(sub)
    worst = {(label, out): [0.0, 0.0] for label, _ in MEASURED for out in OUTPUTS}
    used = 0
    for j, i in enumerate(ok):
        if not all(np.isfinite(kappa[out][j]) for out in OUTPUTS):
            continue  # a status boundary within 1e-7: no error is meaningful
        model = mp_model({k: float(v[i]) for k, v in points.items()})
        assert model["status"] == "ok", {k: float(v[i]) for k, v in points.items()}
        used += 1
        for label, options in MEASURED:
            f50_rtol = options.get("f50_rtol", F50_RTOL) if label.startswith("core") else 0.0
            for out in OUTPUTS:
                exact = model[out]
                if abs(exact) < 1e-290:  # absolute accuracy only (docs/numerics.md)
                    continue
                err = relative_error(getattr(results[label], out)[i], exact)
                assert err <= allowed_error(out, kappa[out][j], f50_rtol), (label, out, err)
                w = worst[(label, out)]
                w[0] = max(w[0], err)
                w[1] = max(w[1], err / ((kappa[out][j] + 1.0) * U))
    return worst, used


def test_worst_case_relative_error_at_the_extremes_is_within_the_documented_bound():
    rows = []
    for region, (generator, n, seed) in REGIONS.items():
        worst, used = _measure(generator(n, seed), max_ok=300)
        assert used >= 150, (region, used)
        for label, _ in MEASURED:
            rows.append(f"| {region} ({used} OK points) | {label} | "
                        + " | ".join(f"{worst[(label, out)][0]:.1e} ({worst[(label, out)][1]:.1f})"
                                     for out in OUTPUTS) + " |")
    print("\n| region | engine | T_MPE | f50 | EPC |\n|---|---|---|---|---|\n" + "\n".join(rows))


#: Two-wavelength spectra (equal weights) at the ends of double's range:
#: - wavelengths from 1e160 nm on, whose f50 lies below 1e-154 cycles/mm: R^2 and the squared
#:   lengths of the curvature overflow there, and Halley's step from an infinite denominator is
#:   0, which must not pass for convergence (f50 would be the bracket's midpoint, 20-36% off);
#: - subnormal wavelengths, for which no start can be fitted (the fit's matrix is rank-deficient),
#:   so the call must go on without one rather than raise "least_squares: rank-deficient
#:   matrix";
#: - wavelengths 10^17.4 and 10^628 apart: past the long one's cut-off the short one's D rounds to
#:   1, so the MTF is exactly c = 1/2 over a stretch, and f50 is the stretch's first point (the
#:   first frequency where MTF <= c, as the reference bisects to). Brent, Halley and Newton must
#:   not take another point of it, where h = 0 too, for the root: at 400 nm and 1e20 nm such a
#:   point lies up to 26x f50, at 1e-320 nm and 1e308 nm up to 3e296x (a 12-decade stretch).
#: (At 400 nm and 1e15 nm the MTF is not flat but nearly so, and f50's condition number with
#: respect to the MTF's roundings is ~1e4: core and reference differ by 6e-13 there, within it.)
EXTREME_SPECTRA = [(1e160, 1.2e160), (1e300, 3e300), (1e-310, 2e-310), (5e-324, 500.0),
                   (400.0, 1e20), (1e-320, 1e308)]


@pytest.mark.parametrize("solver", ["halley", "newton", "brent", "bisection"])
@pytest.mark.parametrize("wavelengths_nm", EXTREME_SPECTRA, ids=str)
def test_spectra_at_the_ends_of_the_double_range_give_the_references_f50(wavelengths_nm, solver):
    spectrum = epc_fast.Spectrum(wavelengths_nm, [1.0, 1.0])
    core = epc_fast.evaluate(**DESIGN, spectrum=spectrum, f50_solver=solver)
    ref = epc_fast.evaluate(**DESIGN, spectrum=spectrum, backend="reference")
    assert core.status == ref.status == Status.OK
    # the reference bisects to adjacent doubles; the core's f50_rtol is 1e-14 and these points'
    # f50 is at the long wavelength's cut-off or the short one's D = 1/2, condition O(1): 1e-13
    # allows the MTF sum's roundings and still fails every error listed above
    assert relative_error(float(core.f50_cyc_per_mm), float(ref.f50_cyc_per_mm)) <= 1e-13


def test_a_spectrum_whose_start_cannot_be_fitted_has_none_and_is_solved_from_the_cubic_one():
    subnormal = np.array([1e-310, 2e-310])
    assert _core.testing.spectrum_start(subnormal, np.array([0.5, 0.5])) is None
    start = _core.testing.f50_spectrum_start(subnormal, np.array([0.5, 0.5]), 1e-3, 1e-3, 0.0, 0.5)
    assert start == _core.testing.f50_cubic_start(1e-3, 1e-3, 0.0, 0.0, 0.5)


# --- Binning and bursts at their extremes -------------------------------------------------------

#: Huge binning and bursts (inside their domains, below 1e30): the output pixel's rate k^2 r,
#: its read noise sigma_r k sqrt(n) and full well n k^2 W grow past anything physical, and f50
#: shrinks as 1/(k p) or as the alignment residual's Gaussian, but nothing overflows.
HUGE_SENSOR = {
    "binning 1e29": dict(binning=1e29),
    "binning 1e15, fill 0.3": dict(binning=1e15, fill_factor=0.3),
    "frames 1e29": dict(frames=1e29),
    "2^60 x 2^60 binned, 2^70 frames, 1e20 um misaligned": dict(
        binning=2.0**60, frames=2.0**70, alignment_error_um=1e20),
    "frames 1e29, charge binning 2": dict(frames=1e29, binning=2.0),
}


@pytest.mark.parametrize("options", BACKENDS)
@pytest.mark.parametrize("case", HUGE_SENSOR)
def test_huge_binning_and_bursts_give_what_mpmath_gives(case, options):
    design = full(read_noise_e=3.0, dark_current_e_per_s=10.0, prnu=0.005, full_well_e=6000.0,
                  jitter_um=0.5, **HUGE_SENSOR[case])
    design["binning_readout"] = 1.0 if "charge" in case else 0.0  # its codes
    r = evaluate_quietly(**points_of([design]), **options)
    model = mp_model(design)
    assert (Status(r.status[0]), Cause(r.cause[0])) == expected_status(model)
    assert r.status[0] == Status.OK
    for out in ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc"):
        value = getattr(r, out)[0]
        assert math.isfinite(value), out
        # a few roundings in each of k^2, sqrt(n k^2) and the quadratic's root, and f50 to the
        # core's tolerance: well-conditioned points, 1e-13
        assert relative_error(value, model[out]) <= 1e-13, (out, value, model[out])
