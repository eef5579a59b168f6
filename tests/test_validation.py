"""epc_fast._validation: the argument checks every entry point shares, and their fast paths
for the arguments calls pass most (Python floats, float64 arrays)."""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import _validation
from epc_fast._validation import as_float_array, column


def test_a_float_is_a_read_only_0d_array_kept_for_the_next_call():
    first = as_float_array("reflectance", 0.4375)
    assert first.shape == () and first.dtype == np.float64 and float(first) == 0.4375
    assert not first.flags.writeable  # shared by every call that passes 0.4375
    assert as_float_array("fill_factor", 0.4375) is first
    with pytest.raises(ValueError, match="read-only"):
        first[()] = 1.0


def test_minus_zero_and_nan_keep_their_own_bits():
    # -0.0 == 0.0 and NaN != NaN: neither may come back as another value's kept array
    zero = as_float_array("jitter_um", 0.0)
    minus = as_float_array("jitter_um", -0.0)
    assert math.copysign(1.0, float(zero)) == 1.0 and math.copysign(1.0, float(minus)) == -1.0
    kept = len(_validation._SCALARS)
    assert np.isnan(as_float_array("prnu", math.nan)) and np.isnan(as_float_array("prnu", math.nan))
    assert len(_validation._SCALARS) == kept


def test_the_kept_floats_are_bounded():
    for k in range(_validation._SCALARS_KEPT + 10):
        as_float_array("illuminance_lux", 1.0 + k / 7.0)
    assert len(_validation._SCALARS) <= _validation._SCALARS_KEPT
    assert float(as_float_array("illuminance_lux", 2.5)) == 2.5


def test_a_float64_array_is_returned_as_it_is_and_others_are_converted():
    a = np.linspace(1.0, 2.0, 5)
    assert as_float_array("f_number", a) is a
    swapped = a.astype(">f8")
    converted = as_float_array("f_number", swapped)
    assert converted.dtype == np.float64 and converted.dtype.isnative
    np.testing.assert_array_equal(converted, a)
    assert as_float_array("binning", np.arange(3)).dtype == np.float64
    with pytest.raises(TypeError, match="f_number is a masked array"):
        as_float_array("f_number", np.ma.masked_array(a))


def test_a_column_is_the_array_itself_when_the_core_can_read_it_flat():
    grid = np.ones((3, 4))
    assert column(grid, (3, 4)) is grid  # C order: the points in broadcast order
    scalar = as_float_array("x", 3.0)
    assert column(scalar, (3, 4)) is scalar  # a 0-d array: a broadcast value
    row = np.arange(4.0)
    np.testing.assert_array_equal(column(row, (3, 4)), np.tile(row, 3))
    fortran = np.asfortranarray(np.arange(12.0).reshape(3, 4))
    np.testing.assert_array_equal(column(fortran, (3, 4)), np.arange(12.0))


def test_2d_and_fortran_ordered_inputs_give_the_flat_call_s_bits():
    rng = np.random.default_rng(5)
    lux = rng.uniform(1.0, 1e4, (6, 7))
    pitch = rng.uniform(0.5, 3.0, (6, 7))
    flat = epc_fast.evaluate(lux.ravel(), pitch.ravel(), 2.0, 4.0, sensor_area_mm2=20.0)
    for order in ("C", "F"):
        grid = epc_fast.evaluate(np.asarray(lux, order=order), np.asarray(pitch, order=order),
                                 2.0, 4.0, sensor_area_mm2=20.0)
        assert grid.epc.shape == (6, 7)
        np.testing.assert_array_equal(grid.epc.ravel(), flat.epc)
        np.testing.assert_array_equal(grid.status.ravel(), flat.status)


@pytest.mark.parametrize("value", [0.4375, 0.0, -0.0, math.nan, math.inf, 7.123456789e-300,
                                   np.arange(3.0), np.float32(2.5), 3, [1, 2], np.int16(4),
                                   np.arange(4.0).reshape(2, 2)[:, 0],
                                   np.arange(3.0).view(type("Sub", (np.ndarray,), {}))])
def test_float_arrays_is_as_float_array_value_by_value(value):
    # the batch's inlined cases (kept floats, float64 arrays) and the general one agree, bits
    # and sign of zero included, whether the float is kept already (second call) or not
    for _ in range(2):
        [got], shapes, contiguous = _validation.float_arrays(("reflectance",), (value,))
        assert shapes == ({got.shape} if got.ndim else set())
        # whether the core may read it as it is (a strided view may not)
        assert contiguous == (got.ndim == 0 or got.flags.c_contiguous)
        expected = as_float_array("reflectance", value)
        assert got.dtype == np.float64 and got.shape == expected.shape
        assert got.tobytes() == expected.tobytes()
        assert type(got) is np.ndarray  # a subclass's values, in a plain array
        if type(value) is np.ndarray and value.dtype == np.float64:
            assert got is value


@pytest.mark.parametrize("value, error, match", [
    (None, TypeError, "prnu must be a number"), ("0.1", TypeError, "prnu must be a number"),
    (np.array(["a"]), TypeError, "prnu must hold real numbers"),
    (10**400, ValueError, r"prnu=.* does not fit a float64"),
    (np.ma.masked_array([1.0, 2.0], mask=[0, 1]), TypeError, "prnu is a masked array")])
def test_float_arrays_names_the_argument_it_cannot_read(value, error, match):
    with pytest.raises(error, match=match):
        _validation.float_arrays(("reflectance", "prnu"), (0.5, value))
