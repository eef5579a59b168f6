"""The f50 solvers' starting guesses (cpp/include/epc_fast/f50/guesses.h) against the exact f50,
and the per-lane choice between them."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, _core
from epc_fast.selfcheck import random_designs
from helpers.designs import parameter_defaults
from helpers.f50_cases import exact_f50, lengths
from helpers.scripts import load_script

DEFAULTS = parameter_defaults()

WAVELENGTH_NM = 550.0


def _exact_f50(f_number, aperture_mm, blur_mm, jitter_mm, threshold):
    """The reference's f50 for one wavelength, from lengths."""
    return exact_f50(f_number, aperture_mm, blur_mm, jitter_mm, threshold, [WAVELENGTH_NM], [1.0])


#: Each accurate start's largest relative error, as tools/fit_f50_start.py measures it over the
#: whole (v_d, w) domain, with room for the rounding of the lengths and of Horner's rule. One
#: Halley step from 5.2e-6 leaves an error of order (5.2e-6)^3 and meets the default stop test
#: (f50/solvers.h); from 0.1's 5.2e-5 it takes a second step.
ACCURATE_BOUND = {0.5: 5e-8, 0.3: 1.5e-6, 0.2: 6e-6, 0.1: 6e-5}


def test_the_thresholds_with_an_accurate_start_are_mtf50_30_20_10():
    assert list(_core.testing.accurate_start_thresholds) == list(ACCURATE_BOUND)
    assert _core.testing.accurate_start_coefficients.shape == (4, 36)


@pytest.mark.parametrize("threshold", list(ACCURATE_BOUND))
def test_each_accurate_start_is_within_its_fit_everywhere(threshold):
    f_number, lambda_f, aperture, blur = lengths(20_000, seed=3, wavelength_nm=WAVELENGTH_NM)
    # and the edges of the domain: one factor alone, two equal, the three equal
    lf = WAVELENGTH_NM * 1e-6 * 4.0
    edges = np.array([[lf, lf * 1e-9, 0.0], [lf, lf * 1e9, 0.0], [lf, lf * 1e-9, lf * 1e9],
                      [lf, lf * 1e9, lf * 1e9], [lf, lf, lf], [lf, lf, 0.0], [lf, lf * 1e-9, lf],
                      [lf, lf * 3.0, lf * 3.0]])
    f_number = np.concatenate([f_number, np.full(len(edges), 4.0)])
    lambda_f = np.concatenate([lambda_f, edges[:, 0]])
    aperture = np.concatenate([aperture, edges[:, 1]])
    blur = np.concatenate([blur, edges[:, 2]])
    exact = _exact_f50(f_number, aperture, blur, 0.0, threshold)
    start = _core.testing.f50_start(lambda_f, aperture, blur, 0.0, threshold)
    error = np.max(np.abs(start / exact - 1))
    assert error <= ACCURATE_BOUND[threshold]
    # and it is this threshold's row: the bound is far below what the cubic start gets
    cubic = _core.testing.f50_cubic_start(lambda_f, aperture, blur, 0.0, threshold)
    assert np.max(np.abs(cubic / exact - 1)) > 100 * error


def test_the_cubic_start_is_within_its_fit_at_one_half():
    # tools/fit_f50_start.py: 0.37% over ratios e^-7..e^7; measured 0.369% over these e^-9..e^9.
    f_number, lambda_f, aperture, blur = lengths(20_000, seed=4, wavelength_nm=WAVELENGTH_NM)
    exact = _exact_f50(f_number, aperture, blur, 0.0, 0.5)
    start = _core.testing.f50_cubic_start(lambda_f, aperture, blur, 0.0, 0.5)
    assert np.max(np.abs(start / exact - 1)) <= 3.8e-3


@pytest.mark.parametrize("threshold", [0.05, 0.3, 0.95])
def test_the_start_for_other_thresholds_and_jitter_is_a_finite_positive_guess(threshold):
    # Jitter, or a threshold without an accurate start, scales the cubic by
    # sqrt(ln(1/c) / ln 2), exact for jitter alone and
    # coarse otherwise (measured: median 25% at c = 0.05, up to 180% at c = 0.95). It only sets
    # the solvers' first abscissa; one outside the bracket is replaced by f_hi / 2 (f50/start.h),
    # so what it must be is finite and positive.
    f_number, lambda_f, aperture, blur = lengths(5_000, seed=4, wavelength_nm=WAVELENGTH_NM)
    rng = np.random.default_rng(5)
    jitter = lambda_f * np.exp(rng.uniform(-3.0, 3.0, len(lambda_f))) * (rng.random(len(lambda_f)) < 0.5)
    start = _core.testing.f50_start(lambda_f, aperture, blur, jitter, threshold)
    assert np.all(np.isfinite(start)) and np.all(start > 0)
    exact = _exact_f50(f_number, aperture, blur, jitter, threshold)
    assert np.median(np.abs(start / exact - 1)) <= 0.3


def test_the_accurate_start_is_the_cubic_one_where_it_does_not_apply():
    # a threshold without a row, or jitter at another threshold than 1/2: no accurate
    # polynomial was fitted there
    lf = WAVELENGTH_NM * 1e-6 * 2.8
    aperture, blur = np.array([0.5, 2.0, 8.0]) * lf, np.array([0.0, 1.0, 3.0]) * lf
    exact = _exact_f50(2.8, aperture, blur, 0.0, 0.5)
    accurate = _core.testing.f50_start(lf, aperture, blur, 0.0, 0.5)
    cubic_at_half = _core.testing.f50_cubic_start(lf, aperture, blur, 0.0, 0.5)
    assert np.max(np.abs(accurate / exact - 1)) <= 5e-8
    assert np.max(np.abs(cubic_at_half / exact - 1)) > 1e-6  # the cubic's own error
    assert np.max(np.abs(cubic_at_half / exact - 1)) <= 4e-3
    # 0.25 has no row: the cubic start, scaled, with or without jitter
    scaled = _core.testing.f50_start(lf, aperture, blur, 0.0, 0.25)
    assert np.array_equal(scaled, _core.testing.f50_cubic_start(lf, aperture, blur, 0.0, 0.25))
    assert np.array_equal(_core.testing.f50_start(lf, aperture, blur, 0.3 * lf, 0.25),
                          _core.testing.f50_cubic_start(lf, aperture, blur, 0.3 * lf, 0.25))
    assert np.max(np.abs(scaled / _exact_f50(2.8, aperture, blur, 0.0, 0.25) - 1)) > 1e-3
    # 0.3 has a row without jitter only: with jitter, the cubic start
    assert np.array_equal(_core.testing.f50_start(lf, aperture, blur, 0.3 * lf, 0.3),
                          _core.testing.f50_cubic_start(lf, aperture, blur, 0.3 * lf, 0.3))


#: The jitter start's largest relative error: tools/fit_f50_start.py (fit_jitter) measures
#: 1.27e-6 over the whole (v_d, v_j, w) domain; 1.5e-6 leaves room for the rounding of the
#: lengths and of Horner's rule. One Halley step from it meets the default stop test, as from
#: MTF30's 1.3e-6.
JITTER_BOUND = 1.5e-6


def test_the_jitter_start_is_within_its_fit_everywhere():
    f_number, lambda_f, aperture, blur = lengths(20_000, seed=6, wavelength_nm=WAVELENGTH_NM)
    rng = np.random.default_rng(6)
    jitter = lambda_f * np.exp(rng.uniform(-9.0, 9.0, len(lambda_f)))
    # and the edges: jitter alone, jitter with diffraction only, jitter negligible, all equal
    lf = WAVELENGTH_NM * 1e-6 * 4.0
    edges = np.array([[lf, 0.0, 0.0, lf * 1e9], [lf, 0.0, 0.0, lf], [lf, lf * 1e-9, 0.0, lf],
                      [lf, lf, lf, 1e-12 * lf], [lf, lf, lf, lf], [lf, lf * 1e9, 0.0, lf],
                      [lf, 0.0, lf * 1e9, lf], [lf, lf * 3.0, lf * 3.0, lf * 3.0]])
    f_number = np.concatenate([f_number, np.full(len(edges), 4.0)])
    lambda_f, aperture, blur, jitter = (np.concatenate([a, e]) for a, e in
                                        zip((lambda_f, aperture, blur, jitter), edges.T))
    exact = _exact_f50(f_number, aperture, blur, jitter, 0.5)
    start = _core.testing.f50_start(lambda_f, aperture, blur, jitter, 0.5)
    error = np.max(np.abs(start / exact - 1))
    assert error <= JITTER_BOUND
    # and it is the jitter start: the cubic one is far coarser with jitter
    cubic = _core.testing.f50_cubic_start(lambda_f, aperture, blur, jitter, 0.5)
    assert np.max(np.abs(cubic / exact - 1)) > 100 * error


def _designs(n, seed):
    d = random_designs(n, seed=seed)
    rng = np.random.default_rng(seed)
    # lanes of both kinds in every block: a third with jitter, a third with another threshold
    kind = rng.integers(0, 3, n)
    d["jitter_um"] = np.where(kind == 1, rng.uniform(0.1, 2.0, n), 0.0)
    d["mtf_threshold"] = np.where(kind == 2, rng.uniform(0.1, 0.9, n), 0.5)
    return d


def test_a_point_gets_the_same_bits_in_a_mixed_block_as_among_its_own_kind():
    # start_f50 picks the start per lane: a block that mixes accurate-start lanes with cubic
    # ones computes both and selects, a block of one kind computes one. A point's result must
    # not depend on which kind of block it lands in.
    d = _designs(3000, seed=11)
    mixed = epc_fast.evaluate(**d, threads=1)
    accurate = (d["jitter_um"] == 0) & (d["mtf_threshold"] == 0.5)
    for kind in (accurate, ~accurate):
        alone = epc_fast.evaluate(**{k: v[kind] for k, v in d.items()}, threads=1)
        for field in ("f50_cyc_per_mm", "epc", "status"):
            assert np.array_equal(getattr(mixed, field)[kind], getattr(alone, field),
                                  equal_nan=True), field


def test_a_point_gets_the_same_bits_whichever_accurate_starts_share_its_block():
    # a block whose lanes take several rows computes the first in its main loop and each
    # further one in a pass of its own; a block of one row (a broadcast threshold) decides the
    # row once. A point's result must be the same in all of them.
    n = 3000
    d = random_designs(n, seed=14)
    rng = np.random.default_rng(14)
    choices = np.array([0.5, 0.3, 0.2, 0.1, 0.25])  # 0.25: no row (the cubic start)
    d["mtf_threshold"] = choices[rng.integers(0, len(choices), n)]
    d["jitter_um"] = np.where(rng.random(n) < 0.2, 0.4, 0.0)
    mixed = epc_fast.evaluate(**d, threads=1)
    for c in choices:
        for jitter in (0.0, 0.4):
            kind = (d["mtf_threshold"] == c) & (d["jitter_um"] == jitter)
            rest = {k: v[kind] for k, v in d.items() if k not in ("mtf_threshold", "jitter_um")}
            alone = epc_fast.evaluate(**rest, mtf_threshold=c, jitter_um=jitter, threads=1)
            for field in ("f50_cyc_per_mm", "epc", "status"):
                assert np.array_equal(getattr(mixed, field)[kind], getattr(alone, field),
                                      equal_nan=True), (c, jitter, field)
    ref = epc_fast.evaluate(**d, backend="reference")
    ok = ref.status == Status.OK
    assert np.array_equal(mixed.status, ref.status) and ok.sum() > 1500
    # f50_rtol 1e-14 plus both engines' rounding (as below)
    assert np.max(np.abs(mixed.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)) <= 1e-14 + 3e-14


def test_a_broadcast_threshold_of_one_half_gives_the_bits_of_an_array_of_halves():
    d = random_designs(2000, seed=12)
    broadcast = epc_fast.evaluate(**d, mtf_threshold=0.5, jitter_um=0.0)
    arrays = epc_fast.evaluate(**d, mtf_threshold=np.full(2000, 0.5), jitter_um=np.zeros(2000))
    assert np.array_equal(broadcast.f50_cyc_per_mm, arrays.f50_cyc_per_mm, equal_nan=True)


@pytest.mark.parametrize("solver", ["halley", "newton"])
def test_mixed_blocks_meet_the_tolerance(solver):
    d = _designs(3000, seed=13)
    core = epc_fast.evaluate(**d, f50_solver=solver)
    ref = epc_fast.evaluate(**d, backend="reference")
    ok = ref.status == Status.OK
    assert np.array_equal(core.status, ref.status) and ok.sum() > 1500
    # f50_rtol 1e-14 plus both engines' rounding of these well-conditioned phones
    # (test_f50_solvers.py)
    assert np.max(np.abs(core.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)) <= 1e-14 + 3e-14


# --- Certified starts: a start within f50_rtol ends Halley's and Newton's solve -------------

#: start_f50's rows: the thresholds' (accurate_start_thresholds), then the jitter start.
ROW_NAMES = ("threshold 0.5", "threshold 0.3", "threshold 0.2", "threshold 0.1", "jitter")


def test_each_certified_error_is_twice_the_largest_error_measured_or_more():
    # tools/fit_f50_start.py --check measures the core's starts densely (4e6 random points and
    # grids: 4.2e-8, 1.32e-6, 5.2e-6, 5.19e-5, 1.27e-6); here a sparser run of the same check,
    # so that a refit that left the certified bounds behind fails.
    fit_f50_start = load_script("tools/fit_f50_start.py")
    errors = fit_f50_start.core_start_errors(n_random=40_000, n_grid=101, n_grid_jitter=21)
    assert list(errors) == list(ROW_NAMES)
    certified = _core.testing.certified_start_error
    assert len(certified) == len(ROW_NAMES)
    for name, bound in zip(ROW_NAMES, certified):
        assert 0 < errors[name] <= bound / 2, name
    # and each is the row's own: far below the next coarser row's
    assert certified[0] < certified[1] < certified[2] < certified[3]


def _lengths_of(d, result):
    """lambda F, the pixel aperture and the blur (mm) of each design, as the core forms them."""
    wavelength_nm = d.get("wavelength_nm", DEFAULTS["wavelength_nm"])
    fill_factor = d.get("fill_factor", DEFAULTS["fill_factor"])
    lambda_f = wavelength_nm * 1e-6 * d["f_number"]
    aperture = np.sqrt(fill_factor) * d["pixel_pitch_um"] * 1e-3
    return lambda_f, aperture, result.blur_mm


def _mtf50_designs(n, seed):
    d = random_designs(n, seed=seed)
    d["mtf_threshold"] = 0.5
    d["jitter_um"] = 0.0
    return d


@pytest.mark.parametrize("solver", ["halley", "newton"])
def test_a_tolerance_above_the_certified_error_takes_the_start_as_f50(solver):
    d = _mtf50_designs(4000, seed=21)
    loose = epc_fast.evaluate(**d, f50_solver=solver, f50_rtol=1e-6)
    ref = epc_fast.evaluate(**d, backend="reference")
    ok = ref.status == Status.OK
    assert np.array_equal(loose.status, ref.status) and ok.sum() > 2000
    error = np.abs(loose.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)
    # the start itself: within its certified 1e-7 (measured at most 4.2e-8), and not solved
    # further (a step would leave ~1e-16, the reference's own rounding)
    assert error.max() <= _core.testing.certified_start_error[0]
    assert np.median(error) > 1e-9
    lambda_f, aperture, blur = _lengths_of(d, loose)
    start = _core.testing.f50_start(lambda_f[ok], aperture[ok], blur[ok], 0.0, 0.5)
    # the same formula as the core's start, on lengths formed here (a rounding apart)
    assert np.max(np.abs(loose.f50_cyc_per_mm[ok] / start - 1)) <= 1e-14


@pytest.mark.parametrize("solver", ["halley", "newton"])
@pytest.mark.parametrize("threshold, jitter_um, row", [(0.5, 0.0, 0), (0.3, 0.0, 1), (0.2, 0.0, 2),
                                                       (0.1, 0.0, 3), (0.5, 0.6, 4)])
def test_each_row_settles_above_its_certified_error_and_solves_below_it(solver, threshold,
                                                                        jitter_um, row):
    d = random_designs(2000, seed=22)
    ref = epc_fast.evaluate(**d, mtf_threshold=threshold, jitter_um=jitter_um, backend="reference")
    ok = ref.status == Status.OK
    assert ok.sum() > 1000
    bound = _core.testing.certified_start_error[row]

    def error(rtol):
        r = epc_fast.evaluate(**d, mtf_threshold=threshold, jitter_um=jitter_um,
                              f50_solver=solver, f50_rtol=rtol)
        assert np.array_equal(r.status, ref.status)
        return np.abs(r.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)

    settled = error(bound)  # the tolerance at the bound: the start
    assert settled.max() <= bound and np.median(settled) > bound / 1000
    # just below it: solved, to the tolerance, and far closer than the start (one step from
    # it: Halley's error is of order its cube, Newton's of its square, 4e-9 at 0.1's 5e-5)
    solved = error(bound * 0.99)
    assert solved.max() <= bound * 0.99 and solved.max() <= 1e-8
    assert np.median(solved) < np.median(settled) / 1000


@pytest.mark.parametrize("solver", ["brent", "bisection"])
def test_brent_and_bisection_take_no_start(solver):
    # they solve on the bracket alone: at a loose tolerance their results are theirs, within
    # it, not the start
    d = _mtf50_designs(2000, seed=23)
    r = epc_fast.evaluate(**d, f50_solver=solver, f50_rtol=1e-6)
    ok = r.status == Status.OK
    lambda_f, aperture, blur = _lengths_of(d, r)
    start = _core.testing.f50_start(lambda_f[ok], aperture[ok], blur[ok], 0.0, 0.5)
    ref = epc_fast.evaluate(**d, backend="reference")
    error = np.abs(r.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)
    assert error.max() <= 1e-6
    assert np.median(np.abs(r.f50_cyc_per_mm[ok] / start - 1)) > 1e-9


def test_a_point_gets_the_same_bits_whether_its_block_settles_or_solves():
    # at f50_rtol 1e-6 MTF50 lanes settle and MTF30 lanes (certified 3e-6) are solved; a block
    # may hold both. Each point's result is its own, whatever its neighbours, in both precisions.
    n = 3000
    d = random_designs(n, seed=24)
    rng = np.random.default_rng(24)
    d["mtf_threshold"] = np.where(rng.random(n) < 0.5, 0.5, 0.3)
    for precision in ("float64", "float32"):
        mixed = epc_fast.evaluate(**d, f50_rtol=1e-6, precision=precision, threads=1)
        for c in (0.5, 0.3):
            kind = d["mtf_threshold"] == c
            rest = {k: v[kind] for k, v in d.items() if k != "mtf_threshold"}
            alone = epc_fast.evaluate(**rest, mtf_threshold=c, f50_rtol=1e-6, precision=precision,
                                      threads=1)
            assert np.array_equal(mixed.f50_cyc_per_mm[kind], alone.f50_cyc_per_mm,
                                  equal_nan=True), (precision, c)


def test_lengths_at_the_ends_of_the_domains_still_meet_the_tolerance():
    # the certified bound holds where the start's squares stay normal doubles (lengths inside
    # 2^-400..2^400 mm); at the domains' ends every length is, and the loose tolerance must
    # still hold against the reference, settled or not
    n = 400
    rng = np.random.default_rng(25)
    d = random_designs(n, seed=25)
    d["wavelength_nm"] = 10.0 ** rng.uniform(-29, 29, n)
    d["pixel_pitch_um"] = 10.0 ** rng.uniform(-29, 29, n)
    d["f_number"] = 10.0 ** rng.uniform(-5, 5, n)
    d["shake_deg_per_s"] = 0.0
    for precision in ("float64", "float32"):
        core = epc_fast.evaluate(**d, f50_rtol=1e-6, precision=precision)
        ref = epc_fast.evaluate(**d, backend="reference")
        ok = ref.status == Status.OK
        assert np.array_equal(core.status, ref.status) and ok.sum() > 300
        error = np.abs(core.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)
        # 1e-6 the tolerance; float32 adds its rounding of the lanes it solves (test_precision)
        assert error.max() <= 1e-6 + (1e-6 if precision == "float32" else 0.0), precision


@pytest.mark.parametrize("threshold, jitter_um", [(0.5, 0.0), (0.3, 0.0), (0.1, 0.0), (0.5, 0.6)])
def test_float32_settles_on_the_float64_start_rounded_once(threshold, jitter_um):
    # float32 computes a certified start in float64 from the float64 lengths and rounds it once
    # (f50/settle.h): at a tolerance that settles the row in both precisions, float32's f50 is
    # float64's rounded to float32 (within half a float32 ulp, 2^-24 relative)
    d = random_designs(2000, seed=26)
    row = {0.5: 0, 0.3: 1, 0.1: 3}[threshold] if jitter_um == 0 else 4
    # (1% above the bound: float32 compares its tolerance rounded to float32)
    rtol = _core.testing.certified_start_error[row] * 1.01 + 2.0**-24
    kwargs = dict(d, mtf_threshold=threshold, jitter_um=jitter_um, f50_rtol=rtol)
    wide = epc_fast.evaluate(**kwargs)
    narrow = epc_fast.evaluate(**kwargs, precision="float32")
    ok = wide.status == Status.OK
    assert np.array_equal(narrow.status, wide.status) and ok.sum() > 1000
    f64, f32 = wide.f50_cyc_per_mm[ok], narrow.f50_cyc_per_mm[ok]
    assert np.array_equal(f32, f32.astype(np.float32).astype(np.float64))  # a float32 value
    assert np.max(np.abs(f32 / f64 - 1)) <= 2.0**-24
    ref = epc_fast.evaluate(**{k: v for k, v in kwargs.items() if k != "f50_rtol"},
                            backend="reference")
    assert np.max(np.abs(f32 / ref.f50_cyc_per_mm[ok] - 1)) <= rtol


def test_the_fit_at_other_degrees_reproduces_the_committed_row_and_improves_with_degree():
    # tools/fit_f50_start.py --degrees (README "Where the time goes": a start precise enough to
    # need no step costs as much as the step). Its settings at degree 10 give the committed
    # MTF50 row's error (4.20e-8 max); two degrees more cut it by about 8x (measured 5.0e-9
    # over these points).
    fit_f50_start = load_script("tools/fit_f50_start.py")
    assert fit_f50_start.accurate_terms(10) == 36 and fit_f50_start.accurate_terms(24) == 169
    errors = [fit_f50_start.fit_accurate(0.5, nodes=80, rounds=40, degree=d, check=20_000)[1]
              for d in (10, 12)]
    assert 3.5e-8 < errors[0] <= 4.2e-8 * 1.01
    assert errors[1] < errors[0] / 5
