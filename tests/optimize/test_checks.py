"""The optimiser's checks of its arguments: bounds, parameters the space varies, objectives,
points, threads and the search's options, each refused naming the argument and value."""

import math

import pytest

from epc_fast import optimize, scan
from epc_fast.presets import HIGH_TIER
from helpers.optimize import PITCH, check_raises, scene


@pytest.mark.parametrize("bounds, error, text", [
    ({"pixel_pitch": (1, 2)}, ValueError, "'pixel_pitch' is not a parameter"),
    ({"pixel_pitch_um": (2.0, 1.0)}, ValueError, "bounds['pixel_pitch_um'] = (2.0, 1.0)"),
    ({"pixel_pitch_um": (-1.0, 2.0)}, ValueError, "bounds['pixel_pitch_um'] = (-1.0, 2.0)"),
    ({"pixel_pitch_um": (1.0, math.inf)}, ValueError, "bounds['pixel_pitch_um'] = (1.0, inf)"),
    ({"pixel_pitch_um": 2.0}, TypeError, "bounds['pixel_pitch_um'] = 2.0"),
    ({"illuminance_lux": (1.0, 10.0)}, ValueError, "illuminance_lux varies in the space"),
    ({"pixel_count": (1e6, 1e7)}, ValueError, "gives the sensor as sensor_area_mm2"),
    ({"focal_length_mm": (4.0, 8.0)}, ValueError, "focal_length_mm of a design that meets"),
    ({}, TypeError, "bounds must be a non-empty dict"),
])
def test_bad_bounds_are_refused_naming_the_parameter_and_value(bounds, error, text):
    check_raises(error, text, lambda: optimize.Problem(scene(), bounds, points=1000))


def test_a_pitch_that_the_designs_vary_is_refused():
    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 1e5))
    check_raises(ValueError, "pixel_pitch_um varies in the space (its designs give 2.8, 2.2",
                  lambda: optimize.Problem(space, PITCH, points=1000))


@pytest.mark.parametrize("call, error, text", [
    (lambda: optimize.Quantile(1.5), ValueError, "q=1.5"),
    (lambda: optimize.Quantile("0.5"), ValueError, "q='0.5'"),
    (lambda: optimize.ProbabilityAtLeast(-1.0), ValueError, "target_pixels=-1.0"),
    (lambda: optimize.ProbabilityAtLeast(math.nan), ValueError, "target_pixels=nan"),
    (lambda: optimize.Problem(scene(), PITCH, "median", points=10), TypeError, "'median'"),
    (lambda: optimize.Problem("space", PITCH, points=10), TypeError, "got 'space'"),
    (lambda: optimize.Problem(scene(), PITCH, points=0), ValueError, "points must be >= 1, got 0"),
    (lambda: optimize.Problem(scene(), PITCH, points=2.5), TypeError, "got 2.5"),
    (lambda: optimize.Problem(scene(), PITCH), TypeError, "needs points="),
    (lambda: optimize.Problem(scene(), PITCH, points=10, threads=0), ValueError,
     "threads must be between 1 and"),
    (lambda: optimize.maximize(scene(), PITCH, points=1000, batches=1), ValueError,
     "batches=1"),
    (lambda: optimize.maximize(scene(), PITCH, points=1000, batches=20), ValueError,
     "batches=20"),
    (lambda: optimize.maximize(scene(), PITCH, points=1000, xtol=0.0), ValueError, "xtol=0.0"),
    (lambda: optimize.maximize(scene(), PITCH, points=1000, start_grid=1), ValueError,
     "start_grid=1"),
    (lambda: optimize.Problem(scene(), PITCH, points=100).curve("f_number", [2.0]), ValueError,
     "'f_number' is not an optimised parameter"),
    (lambda: optimize.Problem(scene(), PITCH, points=100).estimate(f_number=2.0), TypeError,
     "unknown: ['f_number']"),
])
def test_bad_arguments_are_refused_naming_the_argument_and_value(call, error, text):
    check_raises(error, text, call)
