"""precision="float32": the core solves f50 in float32 and everything else in float64.

Checked against precision="float64" (the same core) and the NumPy reference, for every f50
solver on scenes that use every MTF term: statuses, causes, T_MPE, blur and the electron counts
bit-identical, f50 and EPC within float32's accuracy but really in float32; the tolerance clamp
at 2^-21; lanes whose lengths float32 cannot hold (outside 2^-40 .. 2^40 mm) redone in float64
without touching their block's other lanes; thread-count independence; the option's checks, and
its passage through the reference backend and scan spaces.
"""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import BLOCK_POINTS, LogUniform, Space, Summary, run
from epc_fast.scan.sampling.space import EVALUATE_OPTIONS
from epc_fast.selfcheck import random_designs
from epc_fast.spectra import Spectrum
from helpers.designs import WIDE_POINTS, ordinary_points, with_extremes

SOLVERS = ("halley", "newton", "brent", "bisection")
N = 50_000
#: The outputs computed in float64 in both modes: the same bits in both.
FLOAT64_OUTPUTS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "status", "cause")
#: float32's unit roundoff, 2^-24 = 6.0e-8.
U32 = 2.0**-24
#: The smallest f50_rtol honoured in float32 (4 float32 ulps), 2^-21 = 4.8e-7.
RTOL_FLOOR = 2.0**-21

# f50's relative error at threshold 1/2: the tolerance floor 4.8e-7 plus the float32 rounding of
# the MTF at the solution, a few units of U32 divided by |d ln M / d ln f| >= ln 2 (see
# _spread_threshold_bound). Measured on 1e6 designs per scene and solver: at most 6.3e-7.
F50_BOUND = 1e-6
# The "not trivially zero" check: float32 rounding leaves a median error of 3e-8..1e-7, while
# float64's own differences (or float32 not being used at all) are below 1e-13.
MEDIAN_ERROR_FLOOR = 1e-9


def _spread_threshold_bound(threshold):
    """f50's relative error bound per point, for an MTF threshold t in (0, 1).

    An error of d (relative) in the MTF M moves f50 by d / |d ln M / d ln f| (relative). Each
    factor of a monochromatic M (diffraction, pixel and motion sincs, Gaussian jitter) has a
    log-slope of at least ln(1 / factor) in magnitude (diffraction: ratio >= 1.00006, sincs
    >= 2, Gaussian exactly 2, checked numerically), so |d ln M / d ln f| >= ln(1/t): as t -> 1
    the MTF is flat near f = 0 and float32's rounding of M is amplified up to 1 / ln(1/0.95) =
    19.5 times. Measured on 4 x 1e6 designs with t in [0.05, 0.95]: at most 4.9 U32 / ln(1/t)
    beyond the tolerance floor (worst 5e-6, near t = 0.93); 10 U32 leaves a factor 2.
    """
    return RTOL_FLOOR + 10 * U32 / np.log(1 / threshold)


def _scenes():
    rng = np.random.default_rng(31)
    base = random_designs(N, seed=17)
    return base, {
        "phones": {},
        "jitter and fill factor": {"jitter_um": 0.7, "fill_factor": 0.6},
        "4 wavelengths": {"spectrum": Spectrum([450.0, 520.0, 580.0, 640.0], [1, 2, 2, 1])},
        "spread thresholds": {"mtf_threshold": rng.uniform(0.05, 0.95, N)},
    }


BASE, SCENES = _scenes()


def _evaluate(kwargs, **options):
    return epc_fast.evaluate(**kwargs, **options)


def _assert_same_bits(a, b, names=FLOAT64_OUTPUTS, where=None):
    """Every output in ``names`` identical (NaN where NaN), on the points ``where`` (all: None)."""
    for name in names:
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        if where is not None:
            x, y = x[where], y[where]
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name


def _relative_error(result, truth, name, ok):
    return np.abs(getattr(result, name)[ok] / getattr(truth, name)[ok] - 1)


@pytest.fixture(scope="module", params=list(SCENES))
def scene(request):
    return request.param, dict(BASE, **SCENES[request.param])


@pytest.mark.parametrize("solver", SOLVERS)
def test_float32_changes_only_f50_and_epc_and_those_within_float32_accuracy(scene, solver):
    name, kwargs = scene
    double = _evaluate(kwargs, f50_solver=solver)
    single = _evaluate(kwargs, f50_solver=solver, precision="float32")
    _assert_same_bits(single, double)
    for output in ("f50_cyc_per_mm", "epc"):
        assert getattr(single, output).dtype == np.float64
    ok = double.status == Status.OK
    assert ok.sum() > N // 2
    # a point with no f50 to solve has none in either mode
    _assert_same_bits(single, double, ("f50_cyc_per_mm", "epc"), where=~ok)
    f50 = _relative_error(single, double, "f50_cyc_per_mm", ok)
    epc = _relative_error(single, double, "epc", ok)
    if name == "spread thresholds":
        f50_bound = _spread_threshold_bound(kwargs["mtf_threshold"][ok])
    else:
        f50_bound = F50_BOUND
    assert np.all(f50 <= f50_bound), (name, solver, f50.max())
    # EPC = 4 S f50^2 with S in float64: twice f50's relative error, plus float64 rounding
    assert np.all(epc <= 2 * f50_bound), (name, solver, epc.max())
    assert np.median(f50) > MEDIAN_ERROR_FLOOR, (name, solver)


@pytest.mark.parametrize("solver", SOLVERS)
def test_float32_against_the_reference(solver):
    kwargs = {k: v[:2000] for k, v in BASE.items()}
    kwargs["jitter_um"] = np.random.default_rng(2).uniform(0.0, 2.0, 2000)
    reference = _evaluate(kwargs, backend="reference")
    single = _evaluate(kwargs, f50_solver=solver, precision="float32")
    assert np.array_equal(single.status, reference.status)
    ok = reference.status == Status.OK
    assert ok.sum() > 1000
    # the same bound as against the core's float64: the reference is within ~1e-14 of it
    error = _relative_error(single, reference, "f50_cyc_per_mm", ok)
    assert error.max() <= F50_BOUND, (solver, error.max())
    assert np.median(error) > MEDIAN_ERROR_FLOOR
    # T_MPE's hypot and tan differ from NumPy's by an ulp (test_f50_solvers.py), as in float64
    np.testing.assert_allclose(single.t_mpe_s[ok], reference.t_mpe_s[ok], rtol=1e-14)


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_tolerance_above_the_floor_is_honoured_in_float32(solver):
    double = _evaluate(BASE, f50_solver=solver)
    single = _evaluate(BASE, f50_solver=solver, precision="float32", f50_rtol=1e-4)
    ok = double.status == Status.OK
    # the tolerance plus the float32 error at the solution (F50_BOUND, which includes the
    # floor, so this is loose by 5e-7). Measured: bisection 4.9e-5 (half its final bracket),
    # Brent 2.5e-5, Newton 1e-6 and Halley 4e-7 (their last step overshoots the tolerance).
    error = _relative_error(single, double, "f50_cyc_per_mm", ok)
    assert error.max() <= 1e-4 + F50_BOUND, (solver, error.max())


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_tolerance_below_the_floor_is_raised_to_it_in_float32(solver):
    kwargs = dict(BASE, mtf_threshold=SCENES["spread thresholds"]["mtf_threshold"])
    floor = _evaluate(kwargs, f50_solver=solver, precision="float32", f50_rtol=RTOL_FLOOR)
    assert RTOL_FLOOR == 4.76837158203125e-07
    for rtol in (1e-14, 0.0):
        below = _evaluate(kwargs, f50_solver=solver, precision="float32", f50_rtol=rtol)
        _assert_same_bits(below, floor, ("f50_cyc_per_mm", "epc") + FLOAT64_OUTPUTS)


@pytest.mark.parametrize("spectrum", [None, Spectrum([450.0, 520.0, 580.0, 640.0], [1, 2, 2, 1])],
                         ids=["monochromatic", "4 wavelengths"])
def test_lanes_float32_cannot_hold_are_float64_and_leave_their_neighbours_alone(spectrum):
    # a spectrum replaces wavelength_nm
    extremes = [p for p in WIDE_POINTS.values() if spectrum is None or "wavelength_nm" not in p]
    ordinary = ordinary_points(3 * 64, seed=8)
    # every extreme point in the middle 64-point block, among ordinary points
    at = 70 + 5 * np.arange(len(extremes))
    assert at[-1] < 128
    mixed, is_extreme = with_extremes(ordinary, extremes, at)
    options = {"spectrum": spectrum}
    double = _evaluate(mixed, **options)
    single = _evaluate(mixed, **options, precision="float32")
    alone = _evaluate(ordinary, **options, precision="float32")
    # not vacuous: most extreme points are OK, so their f50 was solved (in float64)
    assert np.sum(double.status[is_extreme] == Status.OK) >= len(extremes) - 1
    assert np.all(double.f50_cyc_per_mm[is_extreme & (double.status == Status.OK)] > 0)
    every_output = tuple(double.as_dict())
    _assert_same_bits(single, double, every_output, where=is_extreme)
    for name in every_output:
        x = np.asarray(getattr(single, name))[~is_extreme]
        y = np.asarray(getattr(alone, name))
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
    # and each extreme point alone gives the same bits as among the others
    for k, extreme in enumerate(extremes):
        point = {name: values[at[k]] for name, values in mixed.items()}
        one = _evaluate(point, **options, precision="float32")
        for name in every_output:
            assert np.array_equal(getattr(one, name), getattr(single, name)[at[k]],
                                  equal_nan=True), (extreme, name)


# Points whose lengths float32 holds, made of parameters it cannot: f_number or wavelength_nm
# above float32's largest value 3.4e38, or fill_factor below its smallest normal 1.2e-38,
# compensated by another parameter. These are solved in float32 (the lengths decide), so f50
# must still be within F50_BOUND of float64's.
FLOAT32_LENGTHS_OF_FLOAT64_PARAMETERS = {
    "f_number 1e39, lambda F 1e4 mm": {"f_number": 1e39, "wavelength_nm": 1e-29,
                                       "shake_deg_per_s": 0.0, "illuminance_lux": 1e29},
    "wavelength 1e39 nm, lambda F 1e4 mm": {"f_number": 1e-29, "wavelength_nm": 1e39,
                                            "shake_deg_per_s": 0.0},
    "fill factor 1e-58, aperture 1.4e-3 mm": {"fill_factor": 1e-58, "pixel_pitch_um": 1.4e29},
    "fill factor 1e-44, aperture 1.4e-3 mm": {"fill_factor": 1e-44, "pixel_pitch_um": 1.4e22},
    "spectrum 1e39..2e39 nm, lambda F 1e4..2e4 mm": {
        "f_number": 1e-29, "shake_deg_per_s": 0.0, "spectrum": Spectrum([1e39, 2e39], [1, 1])},
}


@pytest.mark.parametrize("point", list(FLOAT32_LENGTHS_OF_FLOAT64_PARAMETERS))
def test_float32_lengths_made_of_parameters_float32_cannot_hold_are_accurate(point):
    kwargs = {"illuminance_lux": 1000.0, "pixel_pitch_um": 1.4, "f_number": 2.0,
              "focal_length_mm": 5.0, "sensor_area_mm2": 20.0}
    kwargs.update(FLOAT32_LENGTHS_OF_FLOAT64_PARAMETERS[point])
    double = _evaluate(kwargs)
    single = _evaluate(kwargs, precision="float32")
    assert double.status == Status.OK and double.f50_cyc_per_mm > 0
    _assert_same_bits(single, double)
    error = abs(single.f50_cyc_per_mm / double.f50_cyc_per_mm - 1)
    assert error <= F50_BOUND, (point, double.f50_cyc_per_mm, single.f50_cyc_per_mm)


def test_float32_gives_the_same_bits_on_any_thread_count():
    n = 100_000  # 1563 blocks
    kwargs = ordinary_points(n, seed=9)
    # a lane float32 cannot hold every 997 points: blocks redone in float64 on both threads
    kwargs["jitter_um"][::997] = 1e20
    one = _evaluate(kwargs, precision="float32", threads=1)
    two = _evaluate(kwargs, precision="float32", threads=2)
    _assert_same_bits(one, two, tuple(one.as_dict()))


@pytest.mark.parametrize("precision", ["float16", None, "Float32", 32])
@pytest.mark.parametrize("backend", ["core", "reference"])
def test_an_unknown_precision_is_refused_by_name_and_value(precision, backend):
    with pytest.raises(ValueError, match="precision") as error:
        epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, sensor_area_mm2=15.7, precision=precision,
                          backend=backend)
    assert repr(precision) in str(error.value)


def test_the_reference_ignores_the_precision():
    kwargs = {k: v[:500] for k, v in BASE.items()}
    single = _evaluate(kwargs, backend="reference", precision="float32")
    double = _evaluate(kwargs, backend="reference")
    _assert_same_bits(single, double, tuple(double.as_dict()))


def test_a_scan_space_may_solve_in_float32():
    assert "precision" in EVALUATE_OPTIONS
    scans = {}
    for precision in ("float64", "float32"):
        space = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
                      evaluate_options={"precision": precision})
        scans[precision] = run(space, BLOCK_POINTS, seed=7, progress=False,
                               reductions={"t": Summary(of="t_mpe_s"),
                                           "f50": Summary(of="f50_cyc_per_mm")})
    double, single = scans["float64"], scans["float32"]
    for field in ("points", "status_counts", "count", "mean", "std", "min", "max"):
        assert np.array_equal(getattr(single["t"], field), getattr(double["t"], field)), field
    for field in ("mean", "min", "max"):
        # each point's f50 within F50_BOUND, so their mean, min and max too
        np.testing.assert_allclose(getattr(single["f50"], field), getattr(double["f50"], field),
                                   rtol=F50_BOUND)
    assert not np.array_equal(single["f50"].mean, double["f50"].mean)
