"""The optimiser's search (epc_fast.optimize.maximize, Problem.maximize): its optimum against a
dense grid on the same draws and against answers known from the model's physics, for one
parameter and two, and what it says without SciPy."""

import math
import sys

import numpy as np
import pytest

import epc_fast
from epc_fast import optimize, scan
from helpers.optimize import DESIGN, PITCH, check_raises, scene, shaky_scene


@pytest.mark.parametrize("objective, points", [
    (optimize.Mean(), 20_000), (optimize.Quantile(0.5), 20_000), (optimize.Quantile(0.9), 20_000),
    (optimize.ProbabilityAtLeast(1e6), 100_000)])
def test_the_optimum_agrees_with_a_dense_grid_search_on_the_same_draws(objective, points):
    problem = optimize.Problem(shaky_scene(), PITCH, objective, points=points, seed=7)
    best = problem.maximize(batches=0)
    grid = np.linspace(0.8, 4.0, 321)
    values = np.array([problem.value_at((pitch,)) for pitch in grid])
    found = best.x["pixel_pitch_um"]
    # the grid's best value is at one pitch, or (a probability, a step function of the pitch)
    # on a plateau of them: the optimum is within one grid step of it
    tied = grid[values == values.max()]
    step = grid[1] - grid[0]
    assert tied.min() - step <= found <= tied.max() + step
    # and it is at least as good as every grid point (the search refines past the grid)
    assert best.value >= values.max()
    assert best.value == problem.value_at((found,))


def test_the_median_optimum_covers_the_pitch_that_is_best_at_the_median_light():
    # With the light the only random parameter, EPC rises with the light at every pitch, so
    # the median EPC is the EPC at the median light, 1000 lux: the best pitch for the median
    # is the best pitch at 1000 lux, found here on the deterministic model alone.
    kwargs = {k: v for k, v in DESIGN.evaluate_kwargs().items() if k != "pixel_pitch_um"}
    pitches = np.linspace(2.9, 3.2, 3001)
    known = pitches[np.argmax(epc_fast.evaluate(1000.0, pitches, **kwargs).epc)]
    best = optimize.maximize(scene(), PITCH, optimize.Quantile(0.5), points=100_000, seed=11)
    error = best.x_standard_error["pixel_pitch_um"]
    # the median light of 10^5 log-uniform draws is within ~1.5% of 1000 lux, which moves the
    # best pitch by ~0.5% (it goes as light^-1/3): a standard error of ~0.015 um, which must
    # cover the known answer within 4 of itself
    assert 0.003 < error < 0.05
    assert abs(best.x["pixel_pitch_um"] - known) < 4 * error
    assert not best.at_bound["pixel_pitch_um"]


def _sinc(x):
    return math.sin(math.pi * x) / (math.pi * x)


def _log_sinc_slope(x):
    """d ln sinc(x) / dx."""
    return math.pi / math.tan(math.pi * x) - 1.0 / x


def test_the_pitch_that_balances_pixel_aperture_against_motion_blur():
    # Without diffraction (a 1e-6 nm wavelength) and with shot noise only, a fixed light gives
    # a blur b = C / p^2 (C = focal length x shake x electrons needed / focal-plane electron
    # rate per um^2, small angle) and an MTF sinc(p f) sinc(b f). With the sensor's area fixed,
    # EPC = 4 S f50^2 is largest where f50 is; there x = p f and y = b f solve
    # x dln sinc(x) = 2 y dln sinc(y) and sinc(x) sinc(y) = 1/2, constants of no parameter, so
    # the best pitch is p = (C x / y)^(1/3), in closed form but for those two numbers.
    from scipy.optimize import fsolve

    x, y = fsolve(lambda v: [v[0] * _log_sinc_slope(v[0]) - 2 * v[1] * _log_sinc_slope(v[1]),
                             math.log(_sinc(v[0]) * _sinc(v[1]) / 0.5)], [0.5, 0.3], xtol=1e-12)
    lux, reflectance, f_number, focal_mm, shake = 300.0, 0.4, 2.8, 5.6, 4.39
    rate_per_um2 = lux * reflectance / (4 * f_number**2) * epc_fast.DEFAULT_ELECTRONS_PER_LUX_S_M2 \
        * 1e-12
    blur_mm_um2 = focal_mm * math.radians(shake) * 1000.0 / rate_per_um2
    known = (1e3 * blur_mm_um2 * x / y) ** (1 / 3)  # um (1e3: the pitch in mm in x)
    space = scan.Space(illuminance_lux=lux, pixel_pitch_um=1.0, f_number=f_number,
                       focal_length_mm=focal_mm, sensor_area_mm2=15.6751, wavelength_nm=1e-6)
    best = optimize.maximize(space, {"pixel_pitch_um": (0.5, 5.0)}, xtol=1e-7)
    # tan against the small angle (5e-4 rad: 1e-7 relative), the 1e-6 nm diffraction (1e-12)
    # and f50's tolerance move the answer far less than 1e-6; the search stops at 1e-7 of 4.5 um
    assert best.x["pixel_pitch_um"] == pytest.approx(known, rel=1e-6)
    assert best.x_standard_error["pixel_pitch_um"] == 0.0 and best.value_standard_error == 0.0
    assert "area" in best.held


def test_a_fixed_pixel_count_makes_the_largest_pixels_best():
    # The same scene with the pixel count fixed instead of the area: the sensor grows with the
    # pitch, EPC = N (f50 / f_Nyquist)^2 = 4 N (p f50)^2 grows as the blur shrinks, so the
    # best pitch is the upper bound, and EPC there approaches 4 N x0^2, sinc(x0) = 1/2.
    space = scan.Space(illuminance_lux=300.0, pixel_pitch_um=1.0, f_number=2.8,
                       focal_length_mm=5.6, pixel_count=2e6, wavelength_nm=1e-6)
    best = optimize.maximize(space, {"pixel_pitch_um": (0.5, 5.0)})
    assert best.x["pixel_pitch_um"] == 5.0 and best.at_bound["pixel_pitch_um"]
    assert "pixel count" in best.held
    assert 0.85 * 4 * 2e6 * 0.60335**2 < best.value < 4 * 2e6 * 0.60335**2


def test_two_parameters_agree_with_a_dense_grid_on_the_same_draws():
    problem = optimize.Problem(shaky_scene(), {"pixel_pitch_um": (0.8, 4.0),
                                               "f_number": (2.0, 4.0)},
                               points=5_000, seed=6)
    best = problem.maximize(batches=0)
    pitches, f_numbers = np.linspace(0.8, 4.0, 41), np.linspace(2.0, 4.0, 21)
    values = np.array([[problem.value_at((p, f)) for f in f_numbers] for p in pitches])
    i, j = np.unravel_index(np.argmax(values), values.shape)
    # a smaller f-number gives more light and less diffraction: its lower bound is best
    assert best.x["f_number"] == pytest.approx(f_numbers[j], abs=f_numbers[1] - f_numbers[0])
    assert best.x["pixel_pitch_um"] == pytest.approx(pitches[i], abs=pitches[1] - pitches[0])
    # Powell stops within xtol (1e-4 of each range) of the maximum, where the objective is
    # flat to ~1e-8 of itself in the pitch (the f-number's bound is found exactly)
    assert best.x["f_number"] == 2.0
    assert best.value >= values.max() * (1 - 1e-7)
    curve = problem.curve("pixel_pitch_um", pitches, at=best.x)
    assert curve.at == {"f_number": best.x["f_number"]}
    assert curve.objective.max() <= best.value


def test_the_search_without_scipy_says_which_extra_to_install(monkeypatch):
    problem = optimize.Problem(scene(), PITCH, points=1000, seed=1)
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)
    check_raises(ImportError, "pip install 'epc-fast[optimize]'", problem.maximize)
