"""The golden set (tests/data/golden_public.json, mpmath at 50 digits) and a few more cases from an
independent mpmath model of docs/model.md (tests/helpers/mp_model.py), each run through
epc_fast.evaluate on the core (closed-form and Brent T_MPE) and on the NumPy reference."""

import functools
import json
import math
from pathlib import Path

import mpmath
import pytest

import epc_fast
from epc_fast import Cause, Status
from helpers.mp_model import OWN_CASES, mp_model

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


# --- Cases of the independent mpmath model (helpers/mp_model.py) ------------------------------

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
