"""The public API, epc_fast.evaluate: shapes, types, errors, statuses and determinism.

The physics is checked against the reference in test_core_vs_reference.py; here the questions
are what goes in, what comes out, and that the answer does not depend on how it was asked for
(thread count, chunking, broadcasting, memory layout, dtype).
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

import epc_fast
from epc_fast import Cause, Result, Status, api
from epc_fast.params import PARAMETERS, SIZE_PARAMETERS
from helpers.designs import random_design_points

BACKENDS = ("core", "reference")
FLOAT_FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc")
ALL_FIELDS = FLOAT_FIELDS + ("status", "cause")

# The 1/3.2" 1.4 um design of the paper (docs/model.md, "The paper's systems"), on axis: an OK
# point.
DESIGN = dict(illuminance_lux=1000.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
              sensor_area_mm2=15.6751)


def _bits(a):
    """Float arrays as their bit patterns, so that NaN == NaN and -0.0 != 0.0."""
    a = np.asarray(a)
    return a.view(np.uint64) if a.dtype == np.float64 else a


def assert_bits_equal(x, y, name=""):
    """Bit-for-bit equality; on failure, the first differing values as floats."""
    x, y = np.asarray(x), np.asarray(y)
    assert x.dtype == y.dtype, name
    assert x.shape == y.shape, name
    differ = np.flatnonzero(_bits(x).ravel() != _bits(y).ravel())
    if differ.size:
        shown = ", ".join(f"[{i}] {x.ravel()[i]!r} vs {y.ravel()[i]!r}" for i in differ[:5])
        with np.errstate(all="ignore"):
            rel = np.nanmax(np.abs(x.ravel()[differ] / y.ravel()[differ] - 1.0))
        raise AssertionError(f"{name}: {differ.size} of {x.size} values differ (largest "
                             f"relative difference {rel:.3g}): {shown}")


def assert_results_identical(a: Result, b: Result):
    """Every field bit for bit equal, with the same dtype and shape."""
    for name in ALL_FIELDS:
        assert_bits_equal(getattr(a, name), getattr(b, name), name)


# --- Determinism: threads and chunking ---------------------------------------------------------


@pytest.fixture(scope="module")
def many_points():
    return random_design_points(200_000, seed=1)


@pytest.fixture(scope="module")
def one_thread(many_points):
    return epc_fast.evaluate(**many_points, threads=1)


def test_two_threads_give_bit_identical_results_to_one(many_points, one_thread):
    assert_results_identical(epc_fast.evaluate(**many_points, threads=2), one_thread)


@pytest.mark.parametrize("binning_readout", ["digital", "charge"])
@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_binning_and_bursts_give_the_same_bits_on_any_thread_count(binning_readout, precision):
    points = random_design_points(50_000, seed=39, sensor_terms=True)
    kwargs = dict(binning_readout=binning_readout, precision=precision)
    one = epc_fast.evaluate(**points, threads=1, **kwargs)
    for threads in (2, 7):
        assert_results_identical(epc_fast.evaluate(**points, threads=threads, **kwargs), one)


def test_a_bad_binning_readout_is_a_value_error_naming_it():
    with pytest.raises(ValueError, match="binning_readout must be one of 'digital', 'charge'; "
                                         "got 'analog'"):
        epc_fast.evaluate(**DESIGN, binning=2.0, binning_readout="analog")


def test_seven_threads_give_bit_identical_results_to_two(many_points, one_thread):
    # 7 threads on fewer cores: oversubscribed, and 200,000 / 64 blocks do not split evenly.
    two = epc_fast.evaluate(**many_points, threads=2)
    assert_results_identical(epc_fast.evaluate(**many_points, threads=7), two)


def test_chunking_between_interrupt_checks_does_not_change_results(many_points, one_thread,
                                                                   monkeypatch):
    # 1000 is not a multiple of the 64-point block, so every chunk boundary cuts a block.
    monkeypatch.setattr(api, "CHUNK_POINTS", 1000)
    assert_results_identical(epc_fast.evaluate(**many_points, threads=2), one_thread)


@pytest.mark.parametrize("n", [3, 64, 130])
def test_copies_of_one_design_in_one_call_give_identical_results(n):
    # Every lane of a block computes the same formulas; a point's result must not depend on its
    # position in the block (the first and last lanes are where vector loops peel and finish).
    design = dict(DESIGN, illuminance_lux=1e4, pixel_pitch_um=1.75, mtf_threshold=0.8)
    r = epc_fast.evaluate(**{k: np.full(n, v) for k, v in design.items()})
    single = epc_fast.evaluate(**design)
    assert single.status is Status.OK
    for name in ALL_FIELDS:
        expected = np.full(n, getattr(single, name), dtype=getattr(r, name).dtype)
        assert_bits_equal(getattr(r, name), expected, name)


def test_a_slice_of_the_points_gives_the_same_values_as_the_whole_call(many_points, one_thread):
    # Offsets not aligned to 64: each point lands in a different block and lane.
    for start, stop in [(0, 1), (3, 70), (1001, 1129), (199_990, 200_000)]:
        part = {k: v[start:stop] for k, v in many_points.items()}
        sliced = epc_fast.evaluate(**part, threads=2)
        whole = Result(**{k: getattr(one_thread, k)[start:stop] for k in ALL_FIELDS})
        assert_results_identical(sliced, whole)


# --- Broadcasting and shapes -------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_column_against_a_row_broadcasts_to_a_grid_equal_to_the_flat_call(backend):
    illuminance = np.geomspace(1.0, 1e5, 50).reshape(50, 1)
    pitch = np.array([[1.4, 1.75, 2.2, 2.8]])
    grid = epc_fast.evaluate(illuminance, pitch, 2.8, 5.6, sensor_area_mm2=15.6751,
                             backend=backend)
    assert grid.epc.shape == (50, 4)
    big_l, big_p = np.broadcast_arrays(illuminance, pitch)
    flat = epc_fast.evaluate(big_l.ravel(), big_p.ravel(), 2.8, 5.6, sensor_area_mm2=15.6751,
                             backend=backend)
    for name in ALL_FIELDS:
        assert getattr(grid, name).shape == (50, 4)
        assert_bits_equal(getattr(grid, name).ravel(), getattr(flat, name), name)
    assert np.all(grid.status == Status.OK)


@pytest.mark.parametrize("backend", BACKENDS)
def test_three_dimensional_broadcasting_equals_the_flat_call(backend):
    inputs = dict(illuminance_lux=np.geomspace(0.1, 1e5, 5).reshape(5, 1, 1),
                  pixel_pitch_um=np.array([1.4, 2.2, 2.8]).reshape(1, 3, 1),
                  f_number=np.array([1.8, 2.8, 4.0, 8.0]),
                  shake_deg_per_s=np.array([[0.0], [4.39], [30.0]]),
                  focal_length_mm=5.6, sensor_area_mm2=15.6751, read_noise_e=2.0)
    grid = epc_fast.evaluate(**inputs, backend=backend)
    shape = (5, 3, 4)
    assert grid.t_mpe_s.shape == shape
    keys = list(inputs)
    broadcast = np.broadcast_arrays(*(np.asarray(inputs[k]) for k in keys))
    flat = epc_fast.evaluate(**{k: v.ravel() for k, v in zip(keys, broadcast)}, backend=backend)
    for name in ALL_FIELDS:
        assert getattr(grid, name).shape == shape
        assert_bits_equal(getattr(grid, name).ravel(), getattr(flat, name), name)


@pytest.mark.parametrize("backend", BACKENDS)
def test_tiled_and_reshaped_input_gives_tiled_and_reshaped_output(backend):
    # The colour-science domain-range check: the same values in any n-d layout.
    p = random_design_points(24, seed=3)
    flat = epc_fast.evaluate(**p, backend=backend)
    for shape in [(2, 12), (2, 3, 4), (4, 3, 1, 2)]:
        shaped = epc_fast.evaluate(**{k: v.reshape(shape) for k, v in p.items()},
                                   backend=backend)
        for name in ALL_FIELDS:
            assert_bits_equal(getattr(shaped, name), getattr(flat, name).reshape(shape), name)
    tiled = epc_fast.evaluate(**{k: np.tile(v, (3, 1)) for k, v in p.items()}, backend=backend)
    for name in ALL_FIELDS:
        assert_bits_equal(getattr(tiled, name), np.tile(getattr(flat, name), (3, 1)), name)


@pytest.mark.parametrize("backend", BACKENDS)
def test_scalar_input_gives_python_floats_and_enum_members(backend):
    r = epc_fast.evaluate(**DESIGN, backend=backend)
    for name in FLOAT_FIELDS:
        assert type(getattr(r, name)) is float, name
    assert type(r.status) is Status and r.status is Status.OK
    assert type(r.cause) is Cause and r.cause is Cause.NONE


@pytest.mark.parametrize("backend", BACKENDS)
def test_zero_dimensional_arrays_count_as_scalars(backend):
    r = epc_fast.evaluate(**{k: np.array(v) for k, v in DESIGN.items()},
                          read_noise_e=np.float32(2.0), backend=backend)
    for name in FLOAT_FIELDS:
        assert type(getattr(r, name)) is float, name
    assert type(r.status) is Status and type(r.cause) is Cause
    expected = epc_fast.evaluate(**DESIGN, read_noise_e=2.0, backend=backend)
    assert r == expected


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_one_element_list_gives_arrays_of_shape_one(backend):
    r = epc_fast.evaluate(**{**DESIGN, "illuminance_lux": [1000.0]}, backend=backend)
    scalar = epc_fast.evaluate(**DESIGN, backend=backend)
    for name in ALL_FIELDS:
        value = getattr(r, name)
        assert isinstance(value, np.ndarray) and value.shape == (1,), name
        assert value[0] == getattr(scalar, name), name


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("illuminance, pitch, shape", [
    (np.empty(0), 1.4, (0,)),
    (np.empty((0, 1)), np.array([1.4, 2.8, 5.6]), (0, 3)),
    (np.empty((2, 0, 3)), 1.4, (2, 0, 3)),
])
def test_empty_input_gives_empty_results_of_the_broadcast_shape(backend, illuminance, pitch,
                                                                 shape):
    r = epc_fast.evaluate(illuminance, pitch, 2.8, 5.6, sensor_area_mm2=15.6751,
                          backend=backend)
    for name in FLOAT_FIELDS:
        assert getattr(r, name).shape == shape and getattr(r, name).dtype == np.float64
    assert r.status.shape == r.cause.shape == shape
    assert r.status.dtype == r.cause.dtype == np.uint8


def test_both_backends_return_the_same_structure():
    for inputs in [DESIGN, {**DESIGN, "illuminance_lux": np.geomspace(1, 1e4, 6).reshape(2, 3)}]:
        core = epc_fast.evaluate(**inputs, backend="core")
        ref = epc_fast.evaluate(**inputs, backend="reference")
        assert type(core) is type(ref) is Result
        assert list(core.as_dict()) == list(ref.as_dict()) == list(ALL_FIELDS)
        for name in ALL_FIELDS:
            x, y = getattr(core, name), getattr(ref, name)
            assert type(x) is type(y), name
            if isinstance(x, np.ndarray):
                assert x.dtype == y.dtype and x.shape == y.shape, name
                assert x.flags.c_contiguous and y.flags.c_contiguous, name


# --- Bad arguments -----------------------------------------------------------------------------

NOT_REAL_NUMBERS = [
    pytest.param(None, id="None"),
    pytest.param("1.4", id="str"),
    pytest.param(1.4 + 0j, id="complex"),
    pytest.param(np.array([1.4, 2.0], dtype=object), id="object-array"),
    pytest.param(True, id="bool"),
    pytest.param(np.array([True, False]), id="bool-array"),
    pytest.param([1.4, "2.0"], id="mixed-list"),
    pytest.param([[1.4, 2.0], [3.0]], id="ragged-list"),
]


@pytest.mark.parametrize("value", NOT_REAL_NUMBERS)
@pytest.mark.parametrize("argument", ["illuminance_lux", "pixel_pitch_um", "sensor_area_mm2",
                                      "prnu", "full_well_e", "mtf_threshold"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_a_non_real_argument_raises_type_error_naming_it(argument, value, backend):
    with pytest.raises(TypeError, match=argument):
        epc_fast.evaluate(**{**DESIGN, argument: value}, backend=backend)


def test_a_non_real_pixel_count_raises_type_error_naming_it():
    design = {k: v for k, v in DESIGN.items() if k != "sensor_area_mm2"}
    with pytest.raises(TypeError, match="pixel_count"):
        epc_fast.evaluate(**design, pixel_count="8e6")


@pytest.mark.parametrize("backend", BACKENDS)
def test_shapes_that_do_not_broadcast_raise_value_error_naming_both(backend):
    with pytest.raises(ValueError, match=r"illuminance_lux.*\(3,\).*f_number.*\(4,\)"):
        epc_fast.evaluate(**{**DESIGN, "illuminance_lux": np.ones(3), "f_number": np.ones(4)},
                          backend=backend)
    with pytest.raises(ValueError, match=r"pixel_pitch_um.*\(2, 3\).*snr_db.*\(2,\)"):
        epc_fast.evaluate(**{**DESIGN, "pixel_pitch_um": np.ones((2, 3))}, snr_db=[30, 33],
                          backend=backend)


def test_giving_both_or_neither_size_raises_type_error():
    design = {k: v for k, v in DESIGN.items() if k != "sensor_area_mm2"}
    with pytest.raises(TypeError, match="pixel_count.*sensor_area_mm2"):
        epc_fast.evaluate(**design)
    with pytest.raises(TypeError, match="pixel_count.*sensor_area_mm2"):
        epc_fast.evaluate(**design, pixel_count=8e6, sensor_area_mm2=15.6751)


@pytest.mark.parametrize("threads, error", [
    (0, ValueError), (-1, ValueError), (10**4, ValueError), (api.MAX_THREADS + 1, ValueError),
    (2.5, TypeError), ("2", TypeError), (True, TypeError), (2.0, TypeError),
])
@pytest.mark.parametrize("backend", BACKENDS)
def test_a_bad_thread_count_raises_naming_threads(threads, error, backend):
    with pytest.raises(error, match="threads"):
        epc_fast.evaluate(**DESIGN, threads=threads, backend=backend)


def test_any_integer_type_from_one_to_the_maximum_is_a_thread_count():
    expected = epc_fast.evaluate(**DESIGN, threads=1)
    for threads in [np.int64(2), np.uint8(3), api.MAX_THREADS]:
        assert epc_fast.evaluate(**DESIGN, threads=threads) == expected


@pytest.mark.parametrize("keyword, value", [
    ("backend", "gpu"), ("backend", "Core"), ("t_mpe_solver", "newton"),
    ("t_mpe_solver", None), ("invalid", "ignore"), ("invalid", "warn"),
])
def test_an_unknown_choice_raises_value_error_naming_it(keyword, value):
    with pytest.raises(ValueError, match=f"{keyword}.*{value!r}"):
        epc_fast.evaluate(**DESIGN, **{keyword: value})


@pytest.mark.parametrize("keyword", ["f50_rtol", "t_mpe_rtol"])
@pytest.mark.parametrize("value", [-1, -1e-300, 1.0, math.nan, math.inf])
def test_a_tolerance_outside_zero_to_one_raises_value_error(keyword, value):
    with pytest.raises(ValueError, match=keyword):
        epc_fast.evaluate(**DESIGN, **{keyword: value})


def test_a_non_numeric_tolerance_raises_type_error():
    with pytest.raises(TypeError, match="f50_rtol"):
        epc_fast.evaluate(**DESIGN, f50_rtol="tight")


# --- Per-point invalid inputs, from the parameter table ---------------------------------------


def _keywords(param):
    return SIZE_PARAMETERS if param.name == "size" else (param.name,)


def _outside_values(param):
    """Values just outside the domain, NaN, and the infinities the domain excludes."""
    values = [math.nan]
    if math.isfinite(param.lo):
        values.append(float(np.nextafter(param.lo, -math.inf)) if param.lo_closed else param.lo)
        values.append(param.lo - 1.0)
    if math.isfinite(param.hi):
        values.append(float(np.nextafter(param.hi, math.inf)) if param.hi_closed else param.hi)
        values.append(param.hi + 1.0)
    if not (param.hi == math.inf and param.hi_closed):
        values.append(math.inf)
    if param.lo == -math.inf:
        values.append(-math.inf)
    if param.integer:  # binning and frames: whole numbers only
        values.append(param.lo + 0.5)
    return values


def _closed_ends(param):
    return ([param.lo] if param.lo_closed else []) + ([param.hi] if param.hi_closed else [])


def _inside_open_ends(param):
    """The nearest floats inside each open finite end (e.g. the smallest positive pitch)."""
    values = []
    if not param.lo_closed and math.isfinite(param.lo):
        values.append(float(np.nextafter(param.lo, math.inf)))
    if not param.hi_closed and math.isfinite(param.hi):
        values.append(float(np.nextafter(param.hi, -math.inf)))
    return values


INVALID_CASES = [pytest.param(keyword, value, id=f"{keyword}={value!r}")
                 for param in PARAMETERS for keyword in _keywords(param)
                 for value in _outside_values(param)]
CLOSED_END_CASES = [pytest.param(keyword, value, id=f"{keyword}={value!r}")
                    for param in PARAMETERS for keyword in _keywords(param)
                    for value in _closed_ends(param) + _inside_open_ends(param)]


# The valid value of every keyword in the base design.
CLEAN = {**{p.name: p.default for p in PARAMETERS if p.default is not None}, **DESIGN,
         "pixel_count": 8e6, "electrons_per_lux_s_m2": epc_fast.DEFAULT_ELECTRONS_PER_LUX_S_M2}


def _design_with(keyword, value):
    design = dict(DESIGN)
    if keyword == "pixel_count":
        design.pop("sensor_area_mm2")
    design[keyword] = value
    return design


def test_every_parameter_has_invalid_cases():
    covered = {case.values[0] for case in INVALID_CASES}
    assert covered == {k for p in PARAMETERS for k in _keywords(p)}
    assert len(INVALID_CASES) >= 3 * len(PARAMETERS)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword, value", INVALID_CASES)
def test_a_value_outside_its_domain_makes_the_point_invalid_with_nan_outputs(keyword, value,
                                                                           backend):
    r = epc_fast.evaluate(**_design_with(keyword, value), backend=backend)
    assert r.status is Status.INVALID
    assert r.cause is Cause.NONE
    for name in FLOAT_FIELDS:
        assert math.isnan(getattr(r, name)), name


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword, value", INVALID_CASES)
def test_an_invalid_point_leaves_its_neighbours_unchanged(keyword, value, backend):
    # Five different designs (dim ones blur, bright ones do not); the middle one is bad.
    design = _design_with(keyword, value)
    illuminance = np.array([0.5, 30.0, 1000.0, 2e4, 1e6])
    column = illuminance.copy() if keyword == "illuminance_lux" else np.full(5, CLEAN[keyword])
    column[2] = value
    design["illuminance_lux"] = illuminance
    design[keyword] = column
    good = [0, 1, 3, 4]
    mixed = epc_fast.evaluate(**design, backend=backend)
    alone = epc_fast.evaluate(**{k: (v[good] if isinstance(v, np.ndarray) else v)
                                 for k, v in design.items()}, backend=backend)
    assert mixed.status[2] == Status.INVALID
    assert np.all(alone.status != Status.INVALID)
    for name in ALL_FIELDS:
        assert_bits_equal(getattr(mixed, name)[good], getattr(alone, name), name)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword, value", CLOSED_END_CASES)
def test_a_value_on_a_closed_end_or_just_inside_an_open_one_is_valid(keyword, value, backend):
    r = epc_fast.evaluate(**_design_with(keyword, value), backend=backend)
    assert r.status is not Status.INVALID
    assert not math.isnan(r.electron_rate_e_per_s)
    assert not math.isnan(r.t_mpe_s)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("keyword, value, status, cause", [
    ("illuminance_lux", 0.0, Status.UNREACHABLE, Cause.NO_LIGHT),
    ("reflectance", 0.0, Status.UNREACHABLE, Cause.NO_LIGHT),
    ("lens_transmittance", 0.0, Status.UNREACHABLE, Cause.NO_LIGHT),
    ("reflectance", 1.0, Status.OK, Cause.NONE),
    ("lens_transmittance", 1.0, Status.OK, Cause.NONE),
    ("fill_factor", 1.0, Status.OK, Cause.NONE),
    ("full_well_e", math.inf, Status.OK, Cause.NONE),
    ("read_noise_e", 0.0, Status.OK, Cause.NONE),
    ("dark_current_e_per_s", 0.0, Status.OK, Cause.NONE),
    ("prnu", 0.0, Status.OK, Cause.NONE),
    ("shake_deg_per_s", 0.0, Status.OK, Cause.NONE),
    ("jitter_um", 0.0, Status.OK, Cause.NONE),
])
def test_closed_ends_give_the_status_the_physics_says(keyword, value, status, cause, backend):
    r = epc_fast.evaluate(**_design_with(keyword, value), backend=backend)
    assert (r.status, r.cause) == (status, cause)


# --- invalid="raise" ---------------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_raise_policy_names_the_argument_value_and_index(backend):
    pitch = np.array([1.4, 1.75, 2.2, -1.0, -2.0])
    with pytest.raises(ValueError, match=re.escape("pixel_pitch_um=-1.0 at index (3,)")):
        epc_fast.evaluate(**{**DESIGN, "pixel_pitch_um": pitch}, invalid="raise",
                          backend=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_raise_policy_reports_the_first_bad_point_in_c_order(backend):
    # (0, 2) has a NaN pitch; (1, 0) has reflectance 1.5; (0, 2) comes first in C order.
    pitch = np.array([[1.4, 1.75, np.nan], [1.4, 1.75, 2.2]])
    reflectance = np.array([[0.4], [1.5]])
    with pytest.raises(ValueError, match=re.escape("pixel_pitch_um=nan at index (0, 2)")):
        epc_fast.evaluate(**{**DESIGN, "pixel_pitch_um": pitch}, reflectance=reflectance,
                          invalid="raise", backend=backend)
    # At one point with two bad inputs, the one earlier in the parameter table is named.
    with pytest.raises(ValueError, match=re.escape("f_number=inf at index (1,)")):
        epc_fast.evaluate(**{**DESIGN, "f_number": [2.8, math.inf]}, reflectance=[0.4, 1.5],
                          invalid="raise", backend=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_raise_policy_uses_the_size_keyword_the_caller_gave(backend):
    with pytest.raises(ValueError, match=re.escape("sensor_area_mm2=0.0 at index (1,)")):
        epc_fast.evaluate(**{**DESIGN, "sensor_area_mm2": [15.0, 0.0]}, invalid="raise",
                          backend=backend)
    design = _design_with("pixel_count", [8e6, -1.0])
    with pytest.raises(ValueError, match=re.escape("pixel_count=-1.0 at index (1,)")):
        epc_fast.evaluate(**design, invalid="raise", backend=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_raise_policy_on_scalar_input_names_argument_and_value(backend):
    with pytest.raises(ValueError, match=re.escape("reflectance=1.5 is outside")):
        epc_fast.evaluate(**DESIGN, reflectance=1.5, invalid="raise", backend=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_raise_policy_does_not_raise_for_unreachable_or_unbounded_points(backend):
    r = epc_fast.evaluate(**{**DESIGN, "illuminance_lux": [0.0, 1e-3, 1000.0]},
                          shake_deg_per_s=1e5, invalid="raise", backend=backend)
    assert r.status.tolist() == [Status.UNREACHABLE, Status.BLUR_UNBOUNDED,
                                 Status.BLUR_UNBOUNDED]


# --- Memory layout and dtype -------------------------------------------------------------------


@pytest.fixture(scope="module")
def layout_points():
    return random_design_points(300, seed=11)


@pytest.mark.parametrize("backend", BACKENDS)
def test_strided_read_only_and_big_endian_inputs_give_the_plain_results(layout_points, backend):
    plain = epc_fast.evaluate(**layout_points, backend=backend)
    strided = {}
    for k, v in layout_points.items():
        holder = np.full(3 * v.size, np.nan)
        holder[1::3] = v
        strided[k] = holder[1::3]
        assert not strided[k].flags.c_contiguous
    assert_results_identical(epc_fast.evaluate(**strided, backend=backend), plain)

    read_only = {k: v.copy() for k, v in layout_points.items()}
    for v in read_only.values():
        v.flags.writeable = False
    assert_results_identical(epc_fast.evaluate(**read_only, backend=backend), plain)

    big_endian = {k: v.astype(">f8") for k, v in layout_points.items()}
    assert_results_identical(epc_fast.evaluate(**big_endian, backend=backend), plain)

    reversed_view = {k: v[::-1] for k, v in layout_points.items()}  # negative strides
    backwards = epc_fast.evaluate(**reversed_view, backend=backend)
    assert_results_identical(Result(**{k: getattr(backwards, k)[::-1] for k in ALL_FIELDS}),
                             plain)

    # A Fortran-ordered 2-D input against the same values in C order (the same points in the
    # same order once flattened: C order is what the result's shape means).
    two_d = {k: np.stack([v, v[::-1]], axis=1) for k, v in layout_points.items()}
    fortran = {k: np.asfortranarray(v) for k, v in two_d.items()}
    assert not next(iter(fortran.values())).flags.c_contiguous
    assert_results_identical(epc_fast.evaluate(**fortran, backend=backend),
                             epc_fast.evaluate(**two_d, backend=backend))


@pytest.mark.parametrize("backend", BACKENDS)
def test_integer_inputs_give_the_float64_results(layout_points, backend):
    # Integral illuminance (invalid entries made -3: still invalid, and an integer).
    illuminance = np.where(np.isfinite(layout_points["illuminance_lux"]),
                           np.round(layout_points["illuminance_lux"]), -3.0)
    plain = epc_fast.evaluate(**{**layout_points, "illuminance_lux": illuminance},
                              backend=backend)
    for int_type in (np.int64, np.int32):
        as_int = {**layout_points, "illuminance_lux": illuminance.astype(int_type)}
        assert_results_identical(epc_fast.evaluate(**as_int, backend=backend), plain)
    # Unsigned pixel counts, and Python ints as scalars.
    counts = np.array([640 * 480, 3200 * 2400, 4000 * 3000], dtype=np.uint32)
    assert_results_identical(
        epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, pixel_count=counts, backend=backend),
        epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, pixel_count=counts.astype(float),
                          backend=backend))
    assert (epc_fast.evaluate(1000, 2, 4, 6, pixel_count=8_000_000, backend=backend)
            == epc_fast.evaluate(1000.0, 2.0, 4.0, 6.0, pixel_count=8e6, backend=backend))


@pytest.mark.parametrize("backend", BACKENDS)
def test_float32_inputs_give_the_float64_results_of_the_same_values(layout_points, backend):
    # float32 carries fewer digits: the answer is that of float64 holding the float32 values.
    as_f32 = {k: v.astype(np.float32) for k, v in layout_points.items()}
    widened = {k: v.astype(np.float64) for k, v in as_f32.items()}
    assert_results_identical(epc_fast.evaluate(**as_f32, backend=backend),
                             epc_fast.evaluate(**widened, backend=backend))


def test_evaluate_does_not_modify_its_inputs(layout_points):
    copies = {k: v.copy() for k, v in layout_points.items()}
    epc_fast.evaluate(**layout_points)
    epc_fast.evaluate(**layout_points, backend="reference")
    for k, v in layout_points.items():
        assert_bits_equal(v, copies[k], k)


# --- Statuses from the physics -----------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_light_is_unreachable_with_infinite_exposure(backend):
    r = epc_fast.evaluate(**{**DESIGN, "illuminance_lux": 0.0}, backend=backend)
    assert (r.status, r.cause) == (Status.UNREACHABLE, Cause.NO_LIGHT)
    assert r.electron_rate_e_per_s == 0.0
    assert r.t_mpe_s == math.inf
    for name in ("electrons", "blur_mm", "f50_cyc_per_mm", "epc"):
        assert math.isnan(getattr(r, name)), name


@pytest.mark.parametrize("backend", BACKENDS)
def test_prnu_above_the_inverse_target_caps_the_snr(backend):
    # 30 dB needs SNR 31.6; PRNU 0.04 caps it at 25.
    r = epc_fast.evaluate(**DESIGN, prnu=0.04, snr_db=30.0, backend=backend)
    assert (r.status, r.cause) == (Status.UNREACHABLE, Cause.PRNU)
    assert r.t_mpe_s == math.inf
    assert r.electron_rate_e_per_s > 0
    for name in ("electrons", "blur_mm", "f50_cyc_per_mm", "epc"):
        assert math.isnan(getattr(r, name)), name


@pytest.mark.parametrize("backend", BACKENDS)
def test_prnu_exactly_at_the_cap_is_unreachable(backend):
    # 10**(40/20) = 100 and 0.01 * 100 rounds to exactly 1.0: u sqrt(s) >= 1 holds.
    assert 0.01 * 10.0 ** (40.0 / 20.0) == 1.0
    r = epc_fast.evaluate(**DESIGN, prnu=0.01, snr_db=40.0, backend=backend)
    assert (r.status, r.cause) == (Status.UNREACHABLE, Cause.PRNU)
    below = epc_fast.evaluate(**DESIGN, prnu=0.0099, snr_db=40.0, backend=backend)
    assert below.status is Status.OK


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_full_well_smaller_than_the_signal_needed_is_unreachable_but_reports_electrons(
        backend):
    # Shot noise only at 30 dB needs s = 10**3 electrons (10**1.5 squared: 1e-15 relative).
    r = epc_fast.evaluate(**DESIGN, full_well_e=999.0, backend=backend)
    assert (r.status, r.cause) == (Status.UNREACHABLE, Cause.FULL_WELL)
    assert r.electrons == pytest.approx(1000.0, rel=1e-15)
    assert r.t_mpe_s == math.inf
    for name in ("blur_mm", "f50_cyc_per_mm", "epc"):
        assert math.isnan(getattr(r, name)), name
    assert epc_fast.evaluate(**DESIGN, full_well_e=1001.0, backend=backend).status is Status.OK


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_full_well_exactly_equal_to_the_electrons_needed_is_enough(backend):
    # "r T_MPE > W" is unreachable: equality is not an overflow.
    design = dict(DESIGN, read_noise_e=3.0, dark_current_e_per_s=50.0, prnu=0.005)
    needed = epc_fast.evaluate(**design, backend=backend).electrons
    at = epc_fast.evaluate(**design, full_well_e=needed, backend=backend)
    assert at.status is Status.OK and at.electrons == needed
    short = epc_fast.evaluate(**design, full_well_e=float(np.nextafter(needed, 0)),
                              backend=backend)
    assert (short.status, short.cause) == (Status.UNREACHABLE, Cause.FULL_WELL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_huge_shake_at_low_light_makes_the_blur_unbounded(backend):
    # At 1e-3 lux T_MPE is hours; at 1e5 deg/s the angle passes pi/2 many times over.
    r = epc_fast.evaluate(**{**DESIGN, "illuminance_lux": 1e-3}, shake_deg_per_s=1e5,
                          backend=backend)
    assert (r.status, r.cause) == (Status.BLUR_UNBOUNDED, Cause.NONE)
    assert r.blur_mm == math.inf
    assert r.f50_cyc_per_mm == 0.0 and r.epc == 0.0
    assert math.isfinite(r.t_mpe_s) and r.t_mpe_s > 0
    assert np.deg2rad(1e5) * r.t_mpe_s >= math.pi / 2
    assert r.electrons == pytest.approx(1000.0, rel=1e-15)  # shot noise only: s electrons


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_blur_becomes_unbounded_exactly_when_the_angle_reaches_a_right_angle(backend):
    # Choose the shake so that omega T_MPE straddles pi/2 by a part in 1e9.
    t = epc_fast.evaluate(**DESIGN, backend=backend).t_mpe_s
    omega_deg = np.rad2deg(math.pi / 2 / t)
    r = epc_fast.evaluate(**DESIGN, shake_deg_per_s=[omega_deg * (1 - 1e-9),
                                                      omega_deg * (1 + 1e-9)], backend=backend)
    assert r.status.tolist() == [Status.OK, Status.BLUR_UNBOUNDED]
    assert 1e8 < r.blur_mm[0] / DESIGN["focal_length_mm"] < math.inf  # tan near pi/2 is huge
    assert r.blur_mm[1] == math.inf


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("snr_db", [-3000.0])
def test_a_target_far_below_zero_db_is_met_at_once(snr_db, backend):
    # snr_db is valid down to -3000 dB (params.py). Far below 0 dB the electrons needed,
    # s (1 + D/r) / w plus the read-noise term ~ sigma_r sqrt(s), vanish: T_MPE ~ 0, no blur,
    # f50 as without shake.
    design = dict(DESIGN, read_noise_e=3.0, dark_current_e_per_s=10.0)
    r = epc_fast.evaluate(**design, snr_db=snr_db, backend=backend)
    assert (r.status, r.cause) == (Status.OK, Cause.NONE)
    assert 0.0 <= r.t_mpe_s < 1e-100
    still = epc_fast.evaluate(**design, shake_deg_per_s=0.0, backend=backend)
    assert r.f50_cyc_per_mm == still.f50_cyc_per_mm


# --- Monotonicity ------------------------------------------------------------------------------

# f50 is bisected to f50_rtol = 1e-14 by the core (to adjacent floats by the reference), so two
# EPCs that should be equal or in order can be out of order by ~2e-14 relative. 1e-13 absorbs it.
MONOTONE_SLACK = 1e-13


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sensor", [
    dict(),
    dict(read_noise_e=5.0, dark_current_e_per_s=100.0, prnu=0.01),
])
def test_epc_increases_with_illuminance(backend, sensor):
    illuminance = np.geomspace(1e-3, 1e7, 241)
    r = epc_fast.evaluate(**{**DESIGN, "illuminance_lux": illuminance}, **sensor,
                          backend=backend)
    assert np.all(r.status != Status.UNREACHABLE)
    epc = r.epc
    assert np.all(epc[1:] >= epc[:-1] * (1 - MONOTONE_SLACK))
    # It starts at zero (blur unbounded in the dark), and rises over orders of magnitude.
    assert epc[0] == 0.0
    ok = r.status == Status.OK
    assert np.all(np.diff(epc[ok][:ok.sum() // 2]) > 0)  # strictly, while blur dominates
    assert epc[-1] > 1e6


@pytest.mark.parametrize("backend", BACKENDS)
def test_epc_decreases_with_shake(backend):
    shake = np.concatenate([[0.0], np.geomspace(1e-3, 1e6, 181)])
    r = epc_fast.evaluate(**{**DESIGN, "illuminance_lux": 100.0}, shake_deg_per_s=shake,
                          backend=backend)
    epc = r.epc
    assert np.all(epc[1:] <= epc[:-1] * (1 + MONOTONE_SLACK))
    assert epc[-1] == 0.0 and r.status[-1] == Status.BLUR_UNBOUNDED
    assert epc[0] > 10 * epc[len(epc) // 2]


@pytest.mark.parametrize("backend", BACKENDS)
def test_stabilization_k_is_the_same_as_shake_divided_by_k(backend):
    # k enters only as omega / k: omega = 4.39 with k = 4 is omega = 4.39 / 4 with k = 1, and
    # dividing by 4 is exact in binary, so the two give the same angle bit for bit.
    a = epc_fast.evaluate(**DESIGN, shake_deg_per_s=4.39, stabilization=4.0, backend=backend)
    b = epc_fast.evaluate(**DESIGN, shake_deg_per_s=4.39 / 4, backend=backend)
    assert a == b
    assert a.epc > epc_fast.evaluate(**DESIGN, backend=backend).epc


# --- Odds and ends -----------------------------------------------------------------------------


def test_result_is_a_frozen_dataclass_with_as_dict():
    r = epc_fast.evaluate(**DESIGN)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.epc = 0.0
    assert r.as_dict() == {name: getattr(r, name) for name in ALL_FIELDS}


def test_the_default_k_is_the_documented_constant():
    default = epc_fast.evaluate(**DESIGN)
    explicit = epc_fast.evaluate(**DESIGN,
                                 electrons_per_lux_s_m2=epc_fast.DEFAULT_ELECTRONS_PER_LUX_S_M2)
    assert default == explicit


def test_a_2x2_binned_pixel_is_the_pixel_twice_its_size():
    # Binning k x k pixels of pitch p at full fill is one pixel of pitch k p: the same light
    # (k^2 r), the same aperture (sinc(k p f)), the same sensor; with no read noise the same
    # EPC to rounding (docs/beyond.md's table of the paper's designs shows it).
    from epc_fast.presets import HIGH_TIER

    lux = np.geomspace(10, 1e5, 13)
    small, big = HIGH_TIER[3].evaluate_kwargs(), HIGH_TIER[0].evaluate_kwargs()
    binned = epc_fast.evaluate(lux, **small, binning=2)
    assert np.allclose(binned.epc, epc_fast.evaluate(lux, **big).epc, rtol=1e-12)
