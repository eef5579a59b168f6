"""Bad input, for every parameter and option: a clear error naming the argument and value, or a
per-point status under the invalid= policy; never a crash or a silent answer.

test_api.py already holds each parameter's out-of-domain values to status INVALID with NaN
outputs, a few parameters to TypeError for non-numbers, bad thread counts, and layouts
(strided, read-only, big-endian) for all parameters at once. Here: the same questions for every
remaining parameter and value kind, invalid="raise" for every parameter, -inf and -0.0, empty
and mismatched shapes per parameter, arrays that went through pickle, out= in all its ways of
being wrong, and requests too large for memory.
"""

from __future__ import annotations

import decimal
import math
import pickle
import re

import numpy as np
import pytest

import epc_fast
from epc_fast import Cause, Result, Status, _core, api, params

BACKENDS = ("core", "reference")
FLOAT_FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc")

#: An OK design, every parameter given (the paper's 1.4 um design with every term on).
DESIGN = dict(illuminance_lux=1000.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
              sensor_area_mm2=15.6751, reflectance=0.4, lens_transmittance=0.9,
              field_angle_deg=20.0, fill_factor=0.8, electrons_per_lux_s_m2=2.5577e15,
              read_noise_e=3.0, dark_current_e_per_s=10.0, prnu=0.005, full_well_e=1e5,
              snr_db=30.0, shake_deg_per_s=4.39, stabilization=2.0, jitter_um=0.5,
              wavelength_nm=550.0, mtf_threshold=0.5, binning=2.0, frames=4.0,
              alignment_error_um=0.5, wavefront_rms_waves=0.0, denoise_sigma_px=0.0, lens=0.0,
              cfa_transmittance=0.6, color_noise_gain=1.2, binning_readout=1.0)
# (the wavefront error, denoising and lens tables are off: the core refuses them until it has them;
# tests/reference/test_optics.py holds their bad input in the reference)
TABLE = {p.name: p for p in params.PARAMETERS}
#: Every keyword that carries a model parameter (the size slot under both of its names).
KEYWORDS = [name for name in DESIGN] + ["pixel_count"]


def _param(keyword):
    return TABLE["size" if keyword in params.SIZE_PARAMETERS else keyword]


def design_with(keyword, value):
    design = dict(DESIGN)
    if keyword == "pixel_count":
        design.pop("sensor_area_mm2")
        design["pixel_count"] = 8e6
    design[keyword] = value
    return design


def test_the_design_is_ok_and_uses_every_keyword():
    assert epc_fast.evaluate(**DESIGN).status is Status.OK
    assert {_param(k).name for k in KEYWORDS} == set(params.PARAMETER_NAMES)


# --- Values outside the domain, under invalid="raise" ------------------------------------------


def _bad_values(param):
    """NaN, both infinities unless the domain holds one, zero and a negative unless it holds
    them, and the first double past each finite end."""
    values = [math.nan]
    values += [v for v in (math.inf, -math.inf, 0.0, -1.0)
               if not params.in_domain(param, v)]
    if math.isfinite(param.lo):
        values.append(float(np.nextafter(param.lo, -math.inf)) if param.lo_closed else param.lo)
    if math.isfinite(param.hi):
        values.append(float(np.nextafter(param.hi, math.inf)) if param.hi_closed else param.hi)
    if param.integer:  # binning and frames: whole numbers only (k = 2.5, n = 0.5)
        values += [param.lo + 1.5, param.lo - 0.5]
    return sorted(set(values), key=repr)


RAISE_CASES = [pytest.param(keyword, value, id=f"{keyword}={value!r}")
               for keyword in KEYWORDS for value in _bad_values(_param(keyword))]


def test_every_keyword_has_at_least_three_bad_values():
    by_keyword = {}
    for case in RAISE_CASES:
        by_keyword.setdefault(case.values[0], []).append(case.values[1])
    assert set(by_keyword) == set(KEYWORDS)
    assert all(len(v) >= 3 for v in by_keyword.values()), by_keyword


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword, value", RAISE_CASES)
def test_raise_policy_names_every_argument_its_bad_value_and_domain(keyword, value, backend):
    column = np.full(3, _valid_value(keyword))
    column[1] = value
    pattern = re.escape(f"{keyword}={value!r} at index (1,) is outside its domain "
                        f"{_param(keyword).domain_text()}")
    with pytest.raises(ValueError, match=pattern):
        epc_fast.evaluate(**design_with(keyword, column), invalid="raise", backend=backend)


def _valid_value(keyword):
    return DESIGN.get(keyword, 8e6)  # 8e6: the pixel count


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword", [k for k in KEYWORDS if not params.in_domain(_param(k),
                                                                              -math.inf)])
def test_minus_infinity_makes_any_point_invalid_with_nan_outputs(keyword, backend):
    r = epc_fast.evaluate(**design_with(keyword, -math.inf), backend=backend)
    assert (r.status, r.cause) == (Status.INVALID, Cause.NONE)
    assert all(math.isnan(getattr(r, name)) for name in FLOAT_FIELDS)


ZERO_KEYWORDS = [k for k in KEYWORDS if params.in_domain(_param(k), 0.0)]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword", ZERO_KEYWORDS)
def test_negative_zero_gives_exactly_the_results_of_zero(keyword, backend):
    # -0.0 == 0.0 is inside every domain that holds 0: it must not become a sign anywhere.
    minus = epc_fast.evaluate(**design_with(keyword, -0.0), backend=backend)
    plus = epc_fast.evaluate(**design_with(keyword, 0.0), backend=backend)
    for name in FLOAT_FIELDS:
        a, b = getattr(minus, name), getattr(plus, name)
        assert a == b or (math.isnan(a) and math.isnan(b)), name
    assert (minus.status, minus.cause) == (plus.status, plus.cause)


# --- Values that are not real numbers -------------------------------------------------------------

NOT_NUMBERS = [
    pytest.param("2.0", id="str"), pytest.param(b"2.0", id="bytes"),
    pytest.param(np.str_("2.0"), id="numpy-str"), pytest.param(2.0 + 0j, id="complex"),
    pytest.param(np.array([2.0 + 1j, 1.0]), id="complex-array"),
    pytest.param(object(), id="object"), pytest.param({"value": 2.0}, id="dict"),
    pytest.param(decimal.Decimal("2.0"), id="decimal"), pytest.param(True, id="bool"),
    pytest.param(np.datetime64("2009-01-19"), id="datetime64"),
    pytest.param(np.timedelta64(2, "s"), id="timedelta64"),
    pytest.param([2.0, None], id="list-with-none"),
    pytest.param(np.ma.masked_array([2.0, 1.0], mask=[False, True]), id="masked"),
]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("value", NOT_NUMBERS)
@pytest.mark.parametrize("keyword", KEYWORDS)
def test_a_value_that_is_not_a_real_number_raises_type_error_naming_the_argument(keyword, value,
                                                                                backend):
    # binning_readout takes names: a string that is none of them is a ValueError naming it
    error = (ValueError if keyword == "binning_readout" and isinstance(value, (str, bytes))
             else TypeError)
    with pytest.raises(error, match=rf"^{keyword}\b"):
        epc_fast.evaluate(**design_with(keyword, value), backend=backend)


@pytest.mark.parametrize("keyword", [k for k in KEYWORDS if k != "electrons_per_lux_s_m2"
                                     and k not in params.SIZE_PARAMETERS
                                     and k not in params.CFA_PARAMETERS])  # None: a default
def test_none_where_a_number_is_needed_raises_type_error_naming_the_argument(keyword):
    # (None means "not given" for the two size keywords and "the D50 default" for K.)
    with pytest.raises(TypeError, match=rf"^{keyword} must be a number"):
        epc_fast.evaluate(**design_with(keyword, None))


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_integer_beyond_float64_raises_value_error_and_a_big_one_inside_is_a_number(backend):
    with pytest.raises(ValueError, match=r"^illuminance_lux=1000.* does not fit a float64"):
        epc_fast.evaluate(**design_with("illuminance_lux", 10**400), backend=backend)
    # 10**25 is beyond int64 (NumPy would make it an object array) but a fine float64.
    big = epc_fast.evaluate(**design_with("illuminance_lux", 10**25), backend=backend)
    assert big == epc_fast.evaluate(**design_with("illuminance_lux", 1e25), backend=backend)


# --- Shapes --------------------------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword", KEYWORDS)
def test_a_shape_that_does_not_broadcast_raises_value_error_naming_it(keyword, backend):
    other = "pixel_pitch_um" if keyword == "illuminance_lux" else "illuminance_lux"
    design = design_with(keyword, np.full(3, _valid_value(keyword)))
    design[other] = np.full(4, design[other])
    with pytest.raises(ValueError, match=rf"do not broadcast:.*{keyword}\(3,\)"):
        epc_fast.evaluate(**design, backend=backend)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword", KEYWORDS)
def test_an_empty_array_in_any_argument_gives_empty_results(keyword, backend):
    r = epc_fast.evaluate(**design_with(keyword, np.empty((2, 0))), backend=backend)
    for name in FLOAT_FIELDS:
        assert getattr(r, name).shape == (2, 0) and getattr(r, name).dtype == np.float64
    assert r.status.shape == r.cause.shape == (2, 0)


# --- Arrays that went through pickle --------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_arrays_that_went_through_pickle_evaluate_like_the_originals(backend):
    # Unpickled float64 arrays carry an equal but distinct dtype object (dask and
    # multiprocessing hand such arrays over); the core's binding checks dtype identity, so
    # evaluate hands it NumPy's own (before: "column 0 must be a contiguous 1-D float64 array").
    points = {k: np.linspace(0.9, 1.1, 5) * v for k, v in DESIGN.items()}
    unpickled = pickle.loads(pickle.dumps(points))
    assert unpickled["illuminance_lux"].dtype is not np.dtype(np.float64)
    expected = epc_fast.evaluate(**points, backend=backend)
    assert_same(epc_fast.evaluate(**unpickled, backend=backend), expected)
    out = pickle.loads(pickle.dumps(empty_out((5,))))
    assert_same(epc_fast.evaluate(**unpickled, out=out, backend=backend), expected)


def assert_same(a: Result, b: Result):
    for name in FLOAT_FIELDS + ("status", "cause"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


# --- out= ----------------------------------------------------------------------------------------


def empty_out(shape):
    return {name: np.empty(shape, dtype=dtype) for name, dtype in api.OUTPUT_DTYPES.items()}


GRID = dict(DESIGN, illuminance_lux=np.geomspace(1.0, 1e5, 6).reshape(2, 3))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("kind", ["dict", "Result"])
def test_out_receives_the_results_and_is_returned(kind, backend):
    out = empty_out((2, 3))
    given = Result(**out) if kind == "Result" else out
    r = epc_fast.evaluate(**GRID, out=given, backend=backend)
    for name, array in out.items():
        assert getattr(r, name) is array, name
    assert_same(r, epc_fast.evaluate(**GRID, backend=backend))


@pytest.mark.parametrize("backend", BACKENDS)
def test_out_for_scalar_input_holds_zero_dimensional_arrays(backend):
    out = empty_out(())
    r = epc_fast.evaluate(**DESIGN, out=out, backend=backend)
    assert r.epc is out["epc"] and r.epc.shape == ()
    assert float(r.epc) == epc_fast.evaluate(**DESIGN, backend=backend).epc


def test_out_may_alias_an_input_and_gets_the_answer_of_a_copy():
    # The illuminance column is also out["epc"]: read fully before any result lands in it.
    lux = np.geomspace(1.0, 1e5, 200)
    expected = epc_fast.evaluate(**dict(DESIGN, illuminance_lux=lux.copy()))
    out = empty_out((200,))
    out["epc"] = lux
    r = epc_fast.evaluate(**dict(DESIGN, illuminance_lux=lux), out=out, threads=2)
    np.testing.assert_array_equal(r.epc, expected.epc)


def _wrong_out(defect):
    out = empty_out((2, 3))
    if defect == "missing":
        del out["cause"]
    elif defect == "unknown":
        out["f50_cyc_per_um"] = np.empty((2, 3))
    elif defect == "list":
        out["epc"] = [[0.0] * 3] * 2
    elif defect == "float32":
        out["epc"] = np.empty((2, 3), dtype=np.float32)
    elif defect == "big-endian":
        out["epc"] = np.empty((2, 3), dtype=">f8")
    elif defect == "status-float":
        out["status"] = np.empty((2, 3))
    elif defect == "shape":
        out["epc"] = np.empty((3, 2))
    elif defect == "flat":
        out["epc"] = np.empty(6)
    elif defect == "fortran":
        out["epc"] = np.empty((2, 3), order="F")
    elif defect == "strided":
        out["epc"] = np.empty((2, 6))[:, ::2]
    elif defect == "read-only":
        out["epc"].flags.writeable = False
    elif defect == "overlap":
        out["blur_mm"] = out["epc"]
    return out


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("defect, error, message", [
    ("missing", ValueError, r"out must have exactly the fields .*missing: \['cause'\]"),
    ("unknown", ValueError, r"unknown: \['f50_cyc_per_um'\]"),
    ("list", TypeError, r"out\['epc'\] must be a NumPy array"),
    ("float32", TypeError, r"out\['epc'\] has dtype <f4, expected <f8"),
    ("big-endian", TypeError, r"out\['epc'\] has dtype >f8, expected <f8"),
    ("status-float", TypeError, r"out\['status'\] has dtype <f8, expected \|u1"),
    ("shape", ValueError, r"out\['epc'\] has shape \(3, 2\), expected the broadcast shape "
                          r"\(2, 3\)"),
    ("flat", ValueError, r"out\['epc'\] has shape \(6,\)"),
    ("fortran", ValueError, r"out\['epc'\] must be C-contiguous"),
    ("strided", ValueError, r"out\['epc'\] must be C-contiguous"),
    ("read-only", ValueError, r"out\['epc'\] is read-only"),
    ("overlap", ValueError, r"out\['blur_mm'\] and out\['epc'\] share memory"),
])
def test_a_wrong_out_raises_naming_the_field_before_anything_is_computed(defect, error, message,
                                                                         backend):
    out = _wrong_out(defect)
    sentinel = {k: v.copy() for k, v in out.items() if isinstance(v, np.ndarray)}
    with pytest.raises(error, match=message):
        epc_fast.evaluate(**GRID, out=out, backend=backend)
    for name, before in sentinel.items():  # nothing was written
        np.testing.assert_array_equal(out[name], before)


@pytest.mark.parametrize("value", [np.empty(6), [np.empty(6)], "epc", 3])
def test_out_that_is_not_a_mapping_raises_type_error(value):
    with pytest.raises(TypeError, match="out must be a Result or a mapping"):
        epc_fast.evaluate(**GRID, out=value)


# --- Requests too large for memory ---------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_grid_too_large_for_memory_raises_memory_error_before_allocating(backend):
    # (10^7, 1) x (1, 10^7) is 10^14 points: 5 PB of outputs. The estimate comes first, so this
    # takes no time and no memory.
    with pytest.raises(MemoryError, match=r"\(10000000, 10000000\).*100,000,000,000,000 points"):
        epc_fast.evaluate(**dict(DESIGN, illuminance_lux=np.ones((10**7, 1)),
                                 pixel_pitch_um=np.ones((1, 10**7))), backend=backend)


def test_the_core_refuses_an_impossible_point_count_without_crashing():
    # Beneath the API: the binding asked for outputs of 10^12 (7 TiB) or 2^62 points.
    columns, domains = [np.zeros(1)] * len(params.PARAMETERS), params.domain_table()
    none = np.empty(0)
    for n, error in [(10**12, MemoryError), (2**62, ValueError)]:
        with pytest.raises(error):
            _core.evaluate(columns, False, domains, none, none, n, "halley", 1e-14,
                           "closed_form", 1e-15, "float64", 1, 1 << 18)


@pytest.mark.parametrize("weights, shown", [([0.5, 0.6], "1.1"), ([1e-300, 1e-300], "2e-300")])
def test_the_core_refuses_spectrum_weights_that_do_not_sum_to_one(weights, shown):
    # Beneath the API (epc_fast.Spectrum divides the weights by their sum): the MTF is the
    # weighted sum itself, so weights summing to 2e-300 would put it below any threshold.
    columns, domains = [np.zeros(1)] * len(params.PARAMETERS), params.domain_table()
    with pytest.raises(ValueError, match=rf"weights must sum to 1 .*got sum {shown}\b"):
        _core.evaluate(columns, False, domains, np.array([500.0, 600.0]),
                       np.array(weights), 1, "halley", 1e-14, "closed_form", 1e-15, "float64",
                       1, 1 << 18)


@pytest.mark.parametrize("value, shown", [
    ("analog", "'analog'"), (b"charge", "b'charge'"), (np.array(["charge", "analog"]), "'analog'"),
    (["digital", "Charge"], "'Charge'"), (np.array([b"charge"]), "b'charge'")])
def test_binning_readout_that_is_not_a_name_raises_value_error_naming_it(value, shown):
    with pytest.raises(ValueError, match=r"^binning_readout must be one of 'digital', 'charge'.*; "
                                         r"got " + re.escape(shown)):
        epc_fast.evaluate(**{**DESIGN, "binning_readout": value})
    unread = {k: v for k, v in DESIGN.items()
              if k not in ("binning", "frames", "alignment_error_um", "binning_readout")}
    with pytest.raises(ValueError, match="binning_readout must be one of"):
        epc_fast.evaluate(**unread, modes=[{"binning": 1}, {"binning_readout": value}])


@pytest.mark.parametrize("code", [0.5, 2.0, -1.0, np.nan])
def test_a_binning_readout_code_outside_0_and_1_makes_the_point_invalid(code):
    result = epc_fast.evaluate(**{**DESIGN, "binning_readout": np.array([code, 1.0])})
    assert list(result.status) == [Status.INVALID, Status.OK]
    with pytest.raises(ValueError, match=r"binning_readout="):
        epc_fast.evaluate(**{**DESIGN, "binning_readout": code}, invalid="raise")


@pytest.mark.parametrize("value", [np.array(["charge"]), ["charge", "digital"]])
def test_a_scan_designs_binning_readout_that_is_not_one_name_is_refused_naming_it(value):
    from epc_fast import scan

    design = {"name": "A", "pixel_pitch_um": 1.4, "f_number": 2.8, "focal_length_mm": 5.6,
              "sensor_area_mm2": 10.0, "binning_readout": value}
    with pytest.raises(ValueError, match=r"design 'A': binning_readout = .*charge.*: expected "
                                         r"one of 'digital', 'charge'"):
        scan.Space(design=[design], illuminance_lux=100.0)


@pytest.mark.parametrize("value", [True, False, 2.0, "4"])
@pytest.mark.parametrize("sampling", ["monte_carlo", "sobol"])
def test_replicates_that_are_not_a_whole_number_are_refused_naming_them(value, sampling):
    # True was taken as 1 replicate.
    from epc_fast import scan
    from epc_fast.presets import HIGH_TIER

    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 1e5))
    with pytest.raises(TypeError, match=r"^replicates must be an integer, got " + re.escape(
            repr(value))):
        scan.run(space, 1 << 18, seed=1, sampling=sampling, replicates=value, progress=False)
