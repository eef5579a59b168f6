"""The optimiser (epc_fast.optimize): its optimum against a dense grid on the same draws and
against answers known from the model's physics, common random numbers, the Monte Carlo
uncertainty of the optimum, its objectives and their standard errors, and its errors."""

import math
import sys

import numpy as np
import pytest

import epc_fast
from epc_fast import optimize, scan
from epc_fast.optimize_objectives import order_statistics
from epc_fast.presets import HIGH_TIER

#: The paper's 1/3.2" 1.75 um design: its format, lens and corner SNR target; the pitch is what
#: the tests optimise.
DESIGN = HIGH_TIER[2]
PITCH = {"pixel_pitch_um": (0.8, 4.0)}


def scene(**more):
    """Log-uniform 10..100,000 lux (and whatever else ``more`` draws) on the 1/3.2" design."""
    return scan.Space(design=[DESIGN], illuminance_lux=scan.LogUniform(10, 1e5), **more)


def shaky_scene():
    """Light and a log-normal hand shake: the EPC of different draws cross as the pitch
    changes, so no single draw decides a quantile."""
    return scene(shake_deg_per_s=scan.LogNormal(median=4.39, sigma=0.5))


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


def test_the_objective_is_bit_identical_when_evaluated_again_and_on_other_threads():
    one = optimize.Problem(shaky_scene(), PITCH, optimize.Quantile(0.5), points=30_000, seed=3,
                           threads=1)
    two = optimize.Problem(shaky_scene(), PITCH, optimize.Quantile(0.5), points=30_000, seed=3,
                           threads=2)
    first = one.value_at((1.7,))
    one.value_at((2.9,))
    assert one.value_at((1.7,)) == first == two.value_at((1.7,))
    assert np.array_equal(one.epc(pixel_pitch_um=2.2), two.epc(pixel_pitch_um=2.2))
    assert one.maximize(batches=0).x == two.maximize(batches=0).x


def test_every_candidate_is_evaluated_on_the_scans_draws():
    space = shaky_scene()
    problem = optimize.Problem(space, PITCH, points=5_000, seed=9)
    drawn = space.points(9, 0, 5_000).parameters
    for pitch in (1.1, 2.6):
        expected = epc_fast.evaluate(**{**drawn, "pixel_pitch_um": pitch}).epc
        assert np.array_equal(problem.epc(pixel_pitch_um=pitch), expected)


def test_common_draws_make_the_difference_of_two_candidates_far_sharper_than_either():
    space, pitch, near = shaky_scene(), 2.0, 2.01
    problem = optimize.Problem(space, PITCH, points=50_000, seed=1)
    here, there = problem.epc(pixel_pitch_um=pitch), problem.epc(pixel_pitch_um=near)
    # Per draw, a 0.5% step of the pitch changes EPC by far less than EPC varies between
    # draws (0.6% of it here): the step's effect has ~1/160 of the noise either value has.
    paired_error = np.std(there - here, ddof=1) / math.sqrt(here.size)
    value_error = problem.estimate(pixel_pitch_um=pitch).standard_error
    assert paired_error < 0.02 * value_error
    # The step's true effect, from 10x the draws (paired too): the same draws find it within
    # 4 of their combined standard errors, while on independent draws it would drown in noise
    # of sqrt(2) value errors.
    large = optimize.Problem(space, PITCH, points=500_000, seed=5)
    far, close = large.epc(pixel_pitch_um=pitch), large.epc(pixel_pitch_um=near)
    true_change = np.mean(close - far)
    true_error = np.std(close - far, ddof=1) / math.sqrt(far.size)
    assert abs(np.mean(there - here) - true_change) < 4 * math.hypot(paired_error, true_error)
    assert math.sqrt(2) * value_error > abs(true_change) > 10 * paired_error


def test_the_uncertainty_shrinks_as_one_over_the_root_of_the_draws():
    small = optimize.maximize(shaky_scene(), PITCH, optimize.Quantile(0.5), points=20_000, seed=4)
    large = optimize.maximize(shaky_scene(), PITCH, optimize.Quantile(0.5), points=320_000,
                              seed=4)
    # 16 times the draws: a quarter of the errors. The objective's error is a smooth function
    # of the sample (within 10%); the optimum's comes from 10 batches, each spread estimated
    # to ~25%, so their ratio is within a factor 2 of 4.
    assert small.value_standard_error / large.value_standard_error == pytest.approx(4, rel=0.1)
    ratio = small.x_standard_error["pixel_pitch_um"] / large.x_standard_error["pixel_pitch_um"]
    assert 2 < ratio < 8


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


def test_a_draw_that_is_not_ok_counts_as_zero_pixels():
    # Half the scenes are dark (0 lux: the SNR target is unreachable, EPC NaN).
    space = scan.Space(design=[DESIGN], illuminance_lux=scan.Choice((0.0, 1000.0)))
    problem = optimize.Problem(space, PITCH, points=4_000, seed=2)
    epc = problem.epc(pixel_pitch_um=1.5)
    dark = space.points(2, 0, 4_000).parameters["illuminance_lux"] == 0.0
    lit = epc_fast.evaluate(1000.0, **{**DESIGN.evaluate_kwargs(), "pixel_pitch_um": 1.5}).epc
    assert np.all(epc[dark] == 0.0) and np.all(epc[~dark] == lit)
    estimate = problem.estimate(pixel_pitch_um=1.5)
    assert estimate.not_ok_fraction == dark.mean()
    assert estimate.value == pytest.approx(lit * (1 - dark.mean()), rel=1e-12)


def test_a_point_outside_its_domain_raises_naming_it():
    space = scan.Space(design=[DESIGN], illuminance_lux=scan.Normal(10.0, 20.0))
    problem = optimize.Problem(space, PITCH, points=1_000, seed=1)
    with pytest.raises(ValueError, match="illuminance_lux=-"):
        problem.value_at((2.0,))


@pytest.mark.parametrize("n", [1, 7, 1000, 300_000, 1_000_000])
def test_order_statistics_are_exact(n):
    rng = np.random.default_rng(n)
    values = rng.lognormal(size=n)
    values[: n // 5] = 0.0  # ties, as the draws that are not OK give
    rng.shuffle(values)
    ranks = np.unique(np.array([0, n // 3, n // 2, n - 1]))
    assert np.array_equal(order_statistics(values, ranks), np.sort(values)[ranks])


def test_order_statistics_stay_exact_when_the_first_draws_mislead():
    values = np.sort(np.random.default_rng(1).normal(size=1_000_000))  # the prefix: the smallest
    assert order_statistics(values, [500_000])[0] == values[500_000]


@pytest.mark.parametrize("q", [0.0, 0.05, 0.5, 1 / 3, 0.95, 1.0])
def test_the_quantile_is_numpys(q):
    values = np.random.default_rng(2).lognormal(size=400_000)
    # NumPy writes the same interpolation with the weights the other way round above 0.5:
    # a few ulp apart
    assert optimize.Quantile(q).value(values) == pytest.approx(np.quantile(values, q), rel=1e-14)


def test_the_standard_errors_are_the_textbook_ones():
    rng = np.random.default_rng(3)
    uniform = rng.uniform(size=100_000)
    # the median of n uniforms: sqrt(1/4 / n) / density 1 = 0.00158; the interval's ends are
    # order statistics, themselves known to ~1/sqrt(n q (1 - q)) = 0.6% each
    assert optimize.Quantile(0.5).standard_error(uniform) == pytest.approx(0.5 / math.sqrt(1e5),
                                                                          rel=0.03)
    assert optimize.Mean().standard_error(uniform) == np.std(uniform, ddof=1) / math.sqrt(1e5)
    p = np.mean(uniform >= 0.3)
    assert optimize.ProbabilityAtLeast(0.3).standard_error(uniform) == math.sqrt(p * (1 - p) / 1e5)


def _check_raises(error, text, call):
    with pytest.raises(error) as caught:
        call()
    assert text in str(caught.value), str(caught.value)


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
    _check_raises(error, text, lambda: optimize.Problem(scene(), bounds, points=1000))


def test_a_pitch_that_the_designs_vary_is_refused():
    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 1e5))
    _check_raises(ValueError, "pixel_pitch_um varies in the space (its designs give 2.8, 2.2",
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
    _check_raises(error, text, call)


def test_the_search_without_scipy_says_which_extra_to_install(monkeypatch):
    problem = optimize.Problem(scene(), PITCH, points=1000, seed=1)
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)
    _check_raises(ImportError, "pip install 'epc-fast[optimize]'", problem.maximize)


def test_the_optimum_is_written_as_plain_json_values():
    best = optimize.maximize(scene(), PITCH, optimize.Quantile(0.5), points=2_000, seed=1)
    document = best.as_dict()
    assert document["objective"] == {"kind": "Quantile", "q": 0.5, "label": "median EPC"}
    assert document["x"]["pixel_pitch_um"] == best.x["pixel_pitch_um"]
    assert len(document["batch_x"]["pixel_pitch_um"]) == best.batches == 10
    assert document["bounds"] == {"pixel_pitch_um": [0.8, 4.0]}
    table = best.markdown()
    assert f"| pixel_pitch_um | {best.x['pixel_pitch_um']:.6g} |" in table
    assert "| median EPC (pixels) |" in table
