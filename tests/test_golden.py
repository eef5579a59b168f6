"""The golden set (tests/data/golden_public.json, mpmath at 50 digits) and a few more cases from an
independent mpmath model of MODEL.md written below, each run through epc_fast.evaluate on the core
(closed-form and Brent T_MPE) and on the NumPy reference."""

import functools
import json
import math
from pathlib import Path

import mpmath
import pytest

import epc_fast
from epc_fast import Cause, Status

# --- Helpers ------------------------------------------------------------------------------------

GOLDEN = json.loads((Path(__file__).parent / "data" / "golden_public.json").read_text())
POINTS = {p["id"]: p for p in GOLDEN["points"]}

BACKENDS = {
    "core": dict(backend="core"),
    "core-brent": dict(backend="core", t_mpe_solver="brent"),
    "reference": dict(backend="reference"),
}

STATUS = {"ok": Status.OK, "unreachable": Status.UNREACHABLE,
          "blur_unbounded": Status.BLUR_UNBOUNDED, "invalid": Status.INVALID}
CAUSE = {None: Cause.NONE, "no_light": Cause.NO_LIGHT, "prnu": Cause.PRNU,
         "full_well": Cause.FULL_WELL}

#: Golden output name -> epc_fast.Result attribute.
QUANTITIES = {"electron_rate_e_per_s": "electron_rate_e_per_s", "signal_e": "electrons",
              "t_mpe_s": "t_mpe_s", "blur_mm": "blur_mm", "f50_cyc_per_mm": "f50_cyc_per_mm",
              "epc": "epc"}
#: The outputs a T_MPE error reaches amplified by the point's `conditioning` (d ln f50/d ln T).
AMPLIFIED_BY_T_MPE = {"f50_cyc_per_mm", "epc"}

#: The target: both backends are float64-accurate, orders of magnitude below it.
RTOL = 1e-12


def golden_rtol(outputs, quantity):
    """Relative tolerance for one golden output.

    The golden values are exact for the decimal inputs; rounding those inputs to float64 alone
    moves an output by up to `float64_floor_rel` (2^-53 times the sum of the output's
    |d ln out / d ln x|), and a backend adds a few roundings of its own: a point whose inputs
    are that ill-conditioned gets 8 floors where 8 floors exceed RTOL. An error in T_MPE reaches
    f50 (and EPC) multiplied by `conditioning` = |d ln f50 / d ln T_MPE|: when that exceeds 1,
    the budget of the T_MPE-induced part, which is the whole budget here, is scaled by it.
    With the current golden set every floor is < 8e-15 and every conditioning < 1: all RTOL.
    """
    rtol = max(RTOL, 8 * float(outputs.get("float64_floor_rel", 0.0)))
    conditioning = float(outputs.get("conditioning", "nan"))
    if quantity in AMPLIFIED_BY_T_MPE and math.isfinite(conditioning):
        rtol *= max(1.0, conditioning)
    return rtol


def assert_matches(actual, expected, rtol):
    """`expected` as the golden writes it: nan and inf must be matched exactly, as must 0 (no
    light, no shake: these zeros are exact products, not roundings); anything else to rtol."""
    if math.isnan(expected):
        assert math.isnan(actual)
    elif math.isinf(expected) or expected == 0.0:
        assert actual == expected
    else:
        assert actual == pytest.approx(expected, rel=rtol, abs=0)


@functools.lru_cache(maxsize=None)
def run_golden(point_id, backend):
    """epc_fast.evaluate on one golden point's inputs, every input under its own keyword."""
    inputs = dict(POINTS[point_id]["inputs"])
    spectrum = None
    if "wavelengths_nm" in inputs:
        spectrum = ([float(v) for v in inputs.pop("wavelengths_nm")],
                    [float(v) for v in inputs.pop("weights")])
    kwargs = {name: float(value) for name, value in inputs.items()}
    return epc_fast.evaluate(spectrum=spectrum, **kwargs, **BACKENDS[backend])


GOLDEN_CASES = [pytest.param(point_id, backend, id=f"{point_id}-{backend}")
                for point_id in POINTS for backend in BACKENDS]


# --- An independent mpmath model of MODEL.md (40 digits) ----------------------------------------

MP_DPS = 40

#: MODEL.md section 1's defaults, restated here so that the model does not lean on the package.
MODEL_DEFAULTS = dict(reflectance=0.4, lens_transmittance=1.0, field_angle_deg=0.0,
                      fill_factor=1.0, read_noise_e=0.0, dark_current_e_per_s=0.0, prnu=0.0,
                      snr_db=30.0, shake_deg_per_s=4.39, stabilization=1.0, jitter_um=0.0,
                      wavelength_nm=550.0, mtf_threshold=0.5)


def mp_model(inputs, spectrum=None):
    """Every output of MODEL.md sections 3-7 at MP_DPS digits, from the float64 inputs taken
    exactly; `spectrum` is (wavelengths_nm, weights) or None for inputs["wavelength_nm"]."""
    with mpmath.workdps(MP_DPS):
        x = {name: mpmath.mpf(value) for name, value in {**MODEL_DEFAULTS, **inputs}.items()
             if name != "full_well_e"}
        pi = mpmath.pi
        um, nm = mpmath.mpf(10) ** -3, mpmath.mpf(10) ** -6  # in mm

        # Section 3: the electron rate and the positive root of a T^2 - b T - c = 0.
        focal_plane_lux = (x["illuminance_lux"] * x["reflectance"] * x["lens_transmittance"]
                           * mpmath.cos(x["field_angle_deg"] * pi / 180) ** 4
                           / (4 * x["f_number"] ** 2))
        rate = (focal_plane_lux * x["electrons_per_lux_s_m2"] * x["fill_factor"]
                * (x["pixel_pitch_um"] * mpmath.mpf(10) ** -6) ** 2)
        s = mpmath.mpf(10) ** (x["snr_db"] / 10)
        a = rate**2 * (1 - s * x["prnu"] ** 2)
        b = s * (rate + x["dark_current_e_per_s"])
        c = s * x["read_noise_e"] ** 2
        t_mpe = (b + mpmath.sqrt(b * b + 4 * a * c)) / (2 * a)

        # Section 4: blur with tan (the cases below stay far below a quarter turn).
        angle = x["shake_deg_per_s"] * pi / 180 / x["stabilization"] * t_mpe
        assert angle < pi / 2
        blur = x["focal_length_mm"] * mpmath.tan(angle)

        # Section 5: the system MTF.
        if spectrum is None:
            lines = [(x["wavelength_nm"], mpmath.mpf(1))]
        else:
            total = sum(mpmath.mpf(w) for w in spectrum[1])
            lines = [(mpmath.mpf(lam), mpmath.mpf(w) / total) for lam, w in zip(*spectrum)]
        aperture = mpmath.sqrt(x["fill_factor"]) * x["pixel_pitch_um"] * um
        sigma = x["jitter_um"] * um

        def diffraction(f, lam):
            nu = f * lam * nm * x["f_number"]
            return 2 / pi * (mpmath.acos(nu) - nu * mpmath.sqrt(1 - nu * nu)) if nu < 1 else 0

        def mtf(f):
            return (sum(w * diffraction(f, lam) for lam, w in lines)
                    * abs(mpmath.sincpi(aperture * f)) * abs(mpmath.sincpi(blur * f))
                    * mpmath.exp(-2 * pi**2 * sigma**2 * f**2))

        # Section 6: the first crossing, in (0, f_hi], f_hi the smallest first zero.
        threshold = x["mtf_threshold"]
        zeros = [1 / (min(lam for lam, w in lines if w > 0) * nm * x["f_number"]), 1 / aperture]
        if blur > 0:
            zeros.append(1 / blur)
        if sigma > 0:
            zeros.append(mpmath.sqrt(mpmath.log(1 / threshold) / (2 * pi**2)) / sigma)
        f_hi = min(zeros)
        f50 = mpmath.findroot(lambda f: mtf(f) - threshold, (f_hi * mpmath.mpf(10) ** -9, f_hi),
                              solver="anderson")
        # The root is the crossing: MTF - c changes sign across f50 (1 -+ 1e-30).
        assert mtf(f50 * (1 - mpmath.mpf(10) ** -30)) > threshold > mtf(
            f50 * (1 + mpmath.mpf(10) ** -30))

        # Section 7.
        if "pixel_count" in x:
            area = x["pixel_count"] * (x["pixel_pitch_um"] * um) ** 2
        else:
            area = x["sensor_area_mm2"]
        epc = 4 * area * f50**2
        return {"electron_rate_e_per_s": rate, "electrons": rate * t_mpe, "t_mpe_s": t_mpe,
                "blur_mm": blur, "f50_cyc_per_mm": f50, "epc": epc}


K = 2557705539053827.5  # e-/(lux s m^2): the golden set's K, passed explicitly
CORNER_DEG = 27.02970193087426  # half diagonal of the 1/3.2" format at f = 5.6 mm

#: name -> (evaluate inputs, spectrum or None). Each exercises terms the golden set keeps apart.
OWN_CASES = {
    "read_dark_prnu_combined": (dict(
        illuminance_lux=300.0, pixel_pitch_um=1.75, f_number=2.8, focal_length_mm=5.6,
        sensor_area_mm2=15.6751, field_angle_deg=20.0, electrons_per_lux_s_m2=K,
        read_noise_e=5.0, dark_current_e_per_s=200.0, prnu=0.02), None),
    "fill_factor_0_3_with_jitter_and_motion": (dict(
        illuminance_lux=2000.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
        pixel_count=7680000.0, fill_factor=0.3, jitter_um=0.8, field_angle_deg=CORNER_DEG,
        electrons_per_lux_s_m2=K), None),
    "f_16_diffraction_dominated": (dict(
        illuminance_lux=100000.0, pixel_pitch_um=2.2, f_number=16.0, focal_length_mm=20.0,
        sensor_area_mm2=15.6751, electrons_per_lux_s_m2=K), None),
    "mtf_threshold_0_1": (dict(
        illuminance_lux=5000.0, pixel_pitch_um=1.75, f_number=2.8, focal_length_mm=5.6,
        sensor_area_mm2=15.6751, field_angle_deg=CORNER_DEG, mtf_threshold=0.1,
        electrons_per_lux_s_m2=K), None),
    "stabilization_4_at_33_db": (dict(
        illuminance_lux=50.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
        sensor_area_mm2=15.6751, stabilization=4.0, snr_db=33.0,
        electrons_per_lux_s_m2=K), None),
    "polychromatic_unequal_weights_dim_lens": (dict(
        illuminance_lux=800.0, pixel_pitch_um=1.75, f_number=4.9, focal_length_mm=16.8,
        sensor_area_mm2=15.6751, reflectance=0.18, lens_transmittance=0.9,
        field_angle_deg=9.651360532708715, electrons_per_lux_s_m2=K),
        ([450.0, 530.0, 610.0], [1.0, 3.0, 2.0])),
}

OWN_PARAMS = [pytest.param(case, backend, quantity, id=f"{case}-{backend}-{quantity}")
              for case in OWN_CASES for backend in BACKENDS
              for quantity in ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm",
                               "f50_cyc_per_mm", "epc")]


@functools.lru_cache(maxsize=None)
def own_expected(case):
    inputs, spectrum = OWN_CASES[case]
    return mp_model(inputs, spectrum)


@functools.lru_cache(maxsize=None)
def run_own(case, backend):
    inputs, spectrum = OWN_CASES[case]
    return epc_fast.evaluate(spectrum=spectrum, **inputs, **BACKENDS[backend])


# --- The golden set -----------------------------------------------------------------------------


def test_golden_file_holds_the_24_public_points():
    assert GOLDEN["n_points"] == len(POINTS) == 24


@pytest.mark.parametrize("point_id, backend", GOLDEN_CASES)
def test_status_matches_the_golden_point(point_id, backend):
    outputs = POINTS[point_id]["outputs"]
    assert run_golden(point_id, backend).status == STATUS[outputs["status"]]


@pytest.mark.parametrize("point_id, backend", GOLDEN_CASES)
def test_cause_matches_the_golden_point(point_id, backend):
    outputs = POINTS[point_id]["outputs"]
    assert run_golden(point_id, backend).cause == CAUSE[outputs["unreachable_cause"]]


# Result field -> the golden output it is held against.
GOLDEN_OUTPUTS = {
    "t_mpe_s": "t_mpe_s",
    "f50_cyc_per_mm": "f50_cyc_per_mm",
    "epc": "epc",
    "electron_rate_e_per_s": "electron_rate_e_per_s",
    "electrons": "signal_e",
    "blur_mm": "blur_mm",
}


@pytest.mark.parametrize("field", list(GOLDEN_OUTPUTS))
@pytest.mark.parametrize("point_id, backend", GOLDEN_CASES)
def test_output_matches_the_golden_point(point_id, backend, field):
    outputs = POINTS[point_id]["outputs"]
    golden_name = GOLDEN_OUTPUTS[field]
    assert_matches(getattr(run_golden(point_id, backend), field), float(outputs[golden_name]),
                   golden_rtol(outputs, golden_name))


# --- Own cases against the mpmath model ---------------------------------------------------------


@pytest.mark.parametrize("case", OWN_CASES)
@pytest.mark.parametrize("backend", BACKENDS)
def test_own_case_is_ok(case, backend):
    assert run_own(case, backend).status == Status.OK


@pytest.mark.parametrize("case, backend, quantity", OWN_PARAMS)
def test_own_case_matches_the_mpmath_model(case, backend, quantity):
    # RTOL: the model takes the float64 inputs exactly, so no input-rounding floor applies;
    # these cases are well conditioned (f50 moves less than T_MPE), so the plain 1e-12 target.
    assert getattr(run_own(case, backend), quantity) == pytest.approx(
        float(own_expected(case)[quantity]), rel=RTOL, abs=0)


@pytest.mark.parametrize("point_id", [p for p in POINTS if POINTS[p]["outputs"]["status"] == "ok"])
def test_mpmath_model_reproduces_the_golden_point(point_id):
    # The model is checked against the golden set before it is trusted as a reference. The
    # golden is exact for the decimal inputs and the model for their float64 roundings: they
    # differ by at most float64_floor_rel to first order (twice it, for the 8-digit
    # finite-difference sensitivities that floor is built from).
    point = POINTS[point_id]
    outputs = point["outputs"]
    inputs = {name: float(v) for name, v in point["inputs"].items()
              if name not in ("wavelengths_nm", "weights")}
    spectrum = None
    if "wavelengths_nm" in point["inputs"]:
        spectrum = ([float(v) for v in point["inputs"]["wavelengths_nm"]],
                    [float(v) for v in point["inputs"]["weights"]])
    model = mp_model(inputs, spectrum)
    worst = max(float(abs(model[name] / mpmath.mpf(outputs[golden_name]) - 1))
                for golden_name, name in QUANTITIES.items()
                if mpmath.mpf(outputs[golden_name]) != 0)
    assert worst <= 2 * float(outputs["float64_floor_rel"])
