"""Properties of the model that must hold at every point of the domain, on both backends,
checked with hypothesis.

Each design draws every parameter either from the physical box a Monte Carlo scan samples
(1e-3..1e7 lux, 0.3..20 um, F/0.7..F/64, ...), from the parameter's whole domain (log-uniform
up to the caps of params.py), or from its edges (0, subnormals, the last double inside a
cap). Budget (settings below; derandomize=True, so CI always runs the same examples): 300
examples for each of the 4 general tests and 100 for each of the 10 monotonicity tests, 2200
examples in all.

Tolerances: two answers that should be equal or ordered may differ by the f50 bisection
tolerance (1e-14 in the core) plus a few roundings amplified by the point's conditioning;
where a plain 1e-12 check fails, the conditioning is computed (test_extremes.
condition_numbers) and the check is repeated at 1e-12 (kappa + 1).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

import epc_fast
from epc_fast import Cause, Status, params, reference
from helpers.conditioning import condition_numbers

EXAMPLES = 300
#: Per parameter of the ten monotonicity tests.
MONOTONE_EXAMPLES = 100
SETTINGS = settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])
#: Relative agreement asked of two evaluations of the same quantity, before conditioning:
#: 100 times the core's f50 bisection tolerance of 1e-14.
RTOL = 1e-12
FLOAT_FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc")
TABLE = {p.name: p for p in params.PARAMETERS}


# --- Designs ------------------------------------------------------------------------------------


def last_inside(name, end):
    p = TABLE[name]
    value, closed = (p.lo, p.lo_closed) if end == "lo" else (p.hi, p.hi_closed)
    return value if closed else float(np.nextafter(value, math.inf if end == "lo" else -math.inf))


def _linear(lo, hi):
    return lambda f: lo + f * (hi - lo)


def _log(lo, hi):
    """Log-uniform on the open interval (lo, hi) (10**e may round onto an end: kept inside)."""
    a, b = math.log10(lo), math.log10(hi)
    inner_lo, inner_hi = float(np.nextafter(lo, math.inf)), float(np.nextafter(hi, 0.0))
    return lambda f: min(max(10.0 ** (a + f * (b - a)), inner_lo), inner_hi)


def _near_one(f):
    return 1.0 - _log(1.2e-16, 0.9)(f)


#: name -> (physical box, whole domain, edges), the first two as maps from [0, 1].
SPACE = {
    "illuminance_lux": (_log(1e-3, 1e7), _log(1e-300, 1e30),
                        [0.0, 5e-324, last_inside("illuminance_lux", "hi")]),
    "pixel_pitch_um": (_linear(0.3, 20.0), _log(1e-300, 1e30),
                       [5e-324, last_inside("pixel_pitch_um", "hi")]),
    "f_number": (_linear(0.7, 64.0), _log(1e-30, 1e300), [last_inside("f_number", "lo"), 1.7e308]),
    "focal_length_mm": (_linear(1.0, 100.0), _log(1e-300, 1e30),
                        [5e-324, last_inside("focal_length_mm", "hi")]),
    "sensor_area_mm2": (_log(0.1, 1e3), _log(1e-300, 1e30), [5e-324, last_inside("size", "hi")]),
    "reflectance": (_linear(0.01, 1.0), _log(1e-300, 1.0), [0.0, 5e-324, 1.0]),
    "lens_transmittance": (_linear(0.01, 1.0), _log(1e-300, 1.0), [0.0, 5e-324, 1.0]),
    "field_angle_deg": (_linear(-80.0, 80.0),
                        lambda f: math.copysign(90.0 - _log(1e-13, 90.0)(abs(2 * f - 1)), f - 0.5),
                        [last_inside("field_angle_deg", "lo"),
                         last_inside("field_angle_deg", "hi"), -0.0]),
    "fill_factor": (_linear(0.05, 1.0), _log(1e-300, 1.0), [5e-324, 1.0]),
    "electrons_per_lux_s_m2": (_log(1.25e15, 5e15), _log(1e-300, 1e30),
                               [5e-324, last_inside("electrons_per_lux_s_m2", "hi")]),
    "read_noise_e": (_linear(0.0, 50.0), _log(1e-300, 1e30),
                     [0.0, 5e-324, last_inside("read_noise_e", "hi")]),
    "dark_current_e_per_s": (_linear(0.0, 1e4), _log(1e-300, 1e30),
                             [0.0, 5e-324, last_inside("dark_current_e_per_s", "hi")]),
    "prnu": (_linear(0.0, 0.05), _log(1e-300, 1e3), [0.0, 5e-324, 1.0]),
    "full_well_e": (lambda f: math.inf if f < 0.5 else _log(1e2, 1e6)(2 * f - 1),
                    _log(1e-300, 1e300), [math.inf, 5e-324, 1.7e308]),
    "snr_db": (_linear(5.0, 60.0), _linear(-3000.0, 1000.0), [-3000.0, 0.0, 1000.0]),
    "shake_deg_per_s": (_linear(0.0, 60.0), _log(1e-300, 1e30),
                        [0.0, 5e-324, last_inside("shake_deg_per_s", "hi")]),
    "stabilization": (_linear(1.0, 8.0), _log(1e-30, 1e300),
                      [last_inside("stabilization", "lo"), 1.7e308]),
    "jitter_um": (_linear(0.0, 5.0), _log(1e-300, 1e300), [0.0, 5e-324, 1.7e308]),
    "wavelength_nm": (_linear(400.0, 700.0), _log(1e-30, 1e300),
                      [last_inside("wavelength_nm", "lo"), 1.7e308]),
    "mtf_threshold": (_linear(0.1, 0.9),
                      lambda f: _log(1e-300, 0.9)(2 * f) if f < 0.5 else _near_one(2 * f - 1),
                      [5e-324, last_inside("mtf_threshold", "hi")]),
}


def _table_name(keyword):
    return "size" if keyword in params.SIZE_PARAMETERS else keyword


def _value(name, mode, fraction):
    """mode "box": the physical box; "around": x or / 1e6 of it, clipped to the domain;
    "domain": the whole domain; "edge": one of the edges."""
    box, domain, edges = SPACE[name]
    if mode == "box":
        return box(fraction)
    if mode == "around":
        return _around(name, box, fraction)
    if mode == "domain":
        return domain(fraction)
    return edges[min(int(fraction * len(edges)), len(edges) - 1)]


def _around(name, box, fraction):
    p = TABLE[_table_name(name)]
    lo, hi = (1e2, 1e6) if name == "full_well_e" else (box(0.0), box(1.0))
    if name in ("snr_db", "field_angle_deg"):  # signed: widen by an offset
        value = lo - 100.0 + fraction * (hi - lo + 200.0)
    else:
        value = _log(max(lo, 1e-6 * hi), 1e6 * hi)(fraction)  # lo may be 0
    bottom = p.lo if p.lo_closed else float(np.nextafter(p.lo, math.inf))
    top = p.hi if p.hi_closed else float(np.nextafter(p.hi, -math.inf))
    return min(max(value, bottom), top)


#: A fraction for every parameter; up to four parameters moved out of the physical box, each
#: in its own way; whether the size is a pixel count. Most designs keep all but one or two
#: parameters physical, so that an extreme value meets ordinary others (and a status other
#: than "no light" is likely); hypothesis shrinks a failure towards fewer extremes and the
#: bottom of each range.
_DRAWS = st.tuples(
    st.lists(st.floats(0.0, 1.0), min_size=len(SPACE), max_size=len(SPACE)),
    st.lists(st.tuples(st.integers(0, len(SPACE) - 1),
                       st.sampled_from(["around", "domain", "edge"])), max_size=4),
    st.booleans())


def _design(draws):
    fractions, extremes, pixel_count = draws
    modes = dict.fromkeys(SPACE, "box")
    names = list(SPACE)
    for index, mode in extremes:
        modes[names[index]] = mode
    design = {name: _value(name, modes[name], f) for name, f in zip(SPACE, fractions)}
    if pixel_count:
        design["pixel_count"] = min(design.pop("sensor_area_mm2") * 1e6,
                                    last_inside("size", "hi"))
    for name, value in design.items():  # every value stays inside the domain
        assert params.in_domain(TABLE[_table_name(name)], value), (name, value)
    return design


def designs():
    """One design over the whole domain; the size given as a sensor area or a pixel count."""
    return _DRAWS.map(_design)


def evaluate(points, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the reference's overflow warnings
        return epc_fast.evaluate(**points, **options)


def stacked(*designs_):
    return {k: np.array([d[k] for d in designs_], dtype=np.float64) for k in designs_[0]}


def effective_epc(result):
    """EPC, with 0 where the target is unreachable or the blur unbounded (no usable image)."""
    return np.where(result.status == Status.OK, result.epc,
                    np.where(result.status == Status.INVALID, np.nan, 0.0))


#: threads=1: one-point calls need no team (a team's fork and join costs milliseconds on a
#: busy machine); test_api.py and test_concurrency.py hold results to every thread count.
ENGINES = [dict(backend="core", threads=1), dict(backend="core", t_mpe_solver="brent", threads=1),
           dict(backend="reference")]


# --- Monotonicity -------------------------------------------------------------------------------


def grown(name, value, step):
    """The value of `name` made larger by `step` (a factor, or dB for snr_db), kept inside the
    domain; 0 grows to `step` times the smallest normal double."""
    p = TABLE[name]
    if name == "snr_db":
        new = value + 10.0 * math.log10(step)
    elif value == 0.0:
        new = step * 2.2250738585072014e-308
    else:
        new = value * step
    top = p.hi if p.hi_closed else float(np.nextafter(p.hi, -math.inf))
    return min(new, top)


def assert_ordered(lower, higher, design, pair, label):
    """higher >= lower up to RTOL, or up to RTOL (kappa + 1) at this design's conditioning."""
    if not higher < lower * (1.0 - RTOL):
        return
    kappa = condition_numbers(pair)["epc"]
    slack = RTOL * (float(np.max(kappa)) + 1.0)
    note(f"EPC {lower!r} -> {higher!r}, kappa {kappa}")
    assert higher >= lower * (1.0 - slack), (label, design)


INCREASING = ["illuminance_lux", "reflectance", "lens_transmittance", "stabilization"]
DECREASING = ["shake_deg_per_s", "read_noise_e", "dark_current_e_per_s", "prnu", "jitter_um",
              "snr_db"]


@pytest.mark.parametrize("name", INCREASING + DECREASING)
@settings(SETTINGS, max_examples=MONOTONE_EXAMPLES)
@given(design=designs(), step=st.floats(0.0, 3.0).map(lambda e: 10.0**e))
def test_epc_moves_the_way_the_physics_says_when_a_parameter_grows(name, design, step):
    # More light or more stabilisation never lowers EPC; more shake, noise, PRNU, jitter or a
    # higher target never raises it. An unreachable target or an unbounded blur counts as EPC 0.
    bigger = dict(design, **{name: grown(name, design[name], step)})
    pair = stacked(design, bigger)
    for options in ENGINES:
        before, after = effective_epc(evaluate(pair, **options))
        low, high = (before, after) if name in INCREASING else (after, before)
        assert_ordered(low, high, design, pair, (name, options))


# --- f50 and its bracket ------------------------------------------------------------------------


def _f50_without(result, design, factor):
    """f50 of the same point with one MTF factor left out, by the reference's bisection."""
    p = {k: np.asarray(v, dtype=np.float64) for k, v in design.items()}
    blur = np.asarray(result.blur_mm)
    keep = {"diffraction": factor != "diffraction", "pixel": factor != "pixel",
            "motion": factor != "motion", "jitter": factor != "jitter"}
    lam, f_number, threshold = p["wavelength_nm"], p["f_number"], p["mtf_threshold"]

    def mtf(f):
        m = np.ones_like(f)
        if keep["diffraction"]:
            m = m * reference.mtf_diffraction(f, lam, f_number)
        if keep["pixel"]:
            m = m * reference.mtf_pixel(f, p["pixel_pitch_um"], p["fill_factor"])
        if keep["motion"]:
            m = m * reference.mtf_motion(f, blur)
        if keep["jitter"]:
            m = m * reference.mtf_jitter(f, p["jitter_um"])
        return m

    zeros = []
    with np.errstate(divide="ignore", over="ignore"):
        if keep["diffraction"]:
            zeros.append(1.0 / (lam * 1e-6 * f_number))
        if keep["pixel"]:
            zeros.append(1.0 / (np.sqrt(p["fill_factor"]) * p["pixel_pitch_um"] * 1e-3))
        if keep["motion"] and blur > 0:
            zeros.append(1.0 / blur)
        if keep["jitter"] and p["jitter_um"] > 0:
            zeros.append(np.sqrt(np.log(1 / threshold) / (2 * np.pi**2)) / (p["jitter_um"] * 1e-3))
    f_hi = np.array(min(zeros))
    if not np.isfinite(f_hi):
        return math.inf  # no factor left to fall below the threshold
    return float(reference.f50_bisection(mtf, f_hi, threshold))


@SETTINGS
@given(design=designs())
def test_f50_stays_in_its_bracket_and_below_the_f50_with_any_factor_left_out(design):
    # docs/model.md, "The cut-off frequency f50": f50 <= f_hi, the smallest first zero (or jitter's own crossing); and
    # every factor is <= 1, so leaving one out can only raise the crossing.
    point = {k: np.array([v]) for k, v in design.items()}
    for options in ENGINES:
        r = evaluate(design, **options)
        if r.status is not Status.OK:
            continue
        with np.errstate(all="ignore"):  # 1/blur of a subnormal blur: inf, as it should
            f_hi = float(reference.f50_bracket(design["f_number"], design["wavelength_nm"],
                                               design["pixel_pitch_um"], design["fill_factor"],
                                               r.blur_mm, design["jitter_um"],
                                               design["mtf_threshold"]))
        assert r.f50_cyc_per_mm <= f_hi * (1 + 4 * 2.0**-53), (options, design)  # f_hi rounds
        for factor in ("diffraction", "pixel", "motion", "jitter"):
            without = _f50_without(r, design, factor)
            if r.f50_cyc_per_mm > without * (1 + RTOL):
                kappa = condition_numbers(point)["f50_cyc_per_mm"][0]
                assert r.f50_cyc_per_mm <= without * (1 + RTOL * (kappa + 1)), (factor, options,
                                                                              design)


# --- What each status promises ------------------------------------------------------------------


def invalid_value(name):
    p = TABLE[name]
    outside = [math.nan, -math.inf]
    if math.isfinite(p.hi):
        outside.append(p.hi if not p.hi_closed else float(np.nextafter(p.hi, math.inf)))
    if math.isfinite(p.lo):
        outside.append(p.lo if not p.lo_closed else float(np.nextafter(p.lo, -math.inf)))
    return st.sampled_from(outside)


@st.composite
def designs_sometimes_invalid(draw):
    design = draw(designs())
    if draw(st.integers(0, 3)) == 0:
        name = draw(st.sampled_from(sorted(design)))
        design[name] = draw(invalid_value(_table_name(name)))
    return design


@SETTINGS
@given(design=designs_sometimes_invalid())
def test_every_status_keeps_its_promise(design):
    # OK: every output finite. INVALID: every output NaN, no cause. UNREACHABLE: T_MPE = +inf,
    # a cause, blur/f50/EPC NaN. BLUR_UNBOUNDED: blur +inf, f50 = EPC = 0, T_MPE finite.
    for options in ENGINES:
        r = evaluate(design, **options)
        values = {name: getattr(r, name) for name in FLOAT_FIELDS}
        if r.status is Status.OK:
            assert all(math.isfinite(v) for v in values.values()), (options, values)
            assert r.cause is Cause.NONE and r.epc >= 0 and r.f50_cyc_per_mm > 0
        elif r.status is Status.INVALID:
            assert all(math.isnan(v) for v in values.values()) and r.cause is Cause.NONE
        elif r.status is Status.UNREACHABLE:
            assert r.cause is not Cause.NONE and r.t_mpe_s == math.inf
            assert all(math.isnan(values[n]) for n in ("blur_mm", "f50_cyc_per_mm", "epc"))
        else:
            assert r.status is Status.BLUR_UNBOUNDED and r.cause is Cause.NONE
            assert (r.blur_mm, r.f50_cyc_per_mm, r.epc) == (math.inf, 0.0, 0.0)
            assert 0 < r.t_mpe_s < math.inf


# --- The backends agree ---------------------------------------------------------------------------


@pytest.mark.parametrize("other", ENGINES[:2], ids=["core", "core-brent"])
@SETTINGS
@given(design=designs())
def test_the_core_equals_the_reference_within_the_tolerance_scaled_by_conditioning(other,
                                                                                   design):
    core = evaluate(design, **other)
    ref = evaluate(design, backend="reference")
    assert (core.status, core.cause) == (ref.status, ref.cause), design
    kappa = None
    for name in FLOAT_FIELDS:
        a, b = getattr(core, name), getattr(ref, name)
        if a == b or (math.isnan(a) and math.isnan(b)):
            continue
        err = abs(a / b - 1.0)
        if err <= RTOL:
            continue
        if kappa is None:
            kappa = condition_numbers({k: np.array([v]) for k, v in design.items()})
        k = max(float(kappa[out][0]) for out in kappa)  # rate, E, T, blur: within T's kappa
        note(f"{name}: core {a!r} vs reference {b!r}, kappa {k}")
        assert err <= RTOL * (k + 1.0), (name, design)
