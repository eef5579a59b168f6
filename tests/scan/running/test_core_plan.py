"""The core's fused scan pass against the NumPy reference of a scan: the same uniforms bit for
bit, the same values to a few ulp, the same points, and the same reductions (counts equal,
statistics to rounding, the same top-k points), for every distribution and grouping a space
offers; and its own exp, log and inverse normal CDF against mpmath."""

import dataclasses
import math

import mpmath
import numpy as np
import pytest

from epc_fast import _core
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (BLOCK_POINTS, Binned, Choice, Empirical, FractionBelow, Grid,
                           Histogram, LogNormal, LogUniform, Normal, Quantiles, Space, Summary,
                           TopK, Truncated, Uniform, run)
from epc_fast.scan.sampling import streams
from epc_fast.scan.running.core_plan import CorePlan

#: Values drawn by the core and by NumPy from the same uniform differ by the rounding of a
#: fused multiply-add and of exp and log (the core's own, elementary.h, and the C library's,
#: each within 2 ulp): log-uniform's exp(a + u b) at |a + u b| <= 12 moves by at most 12 ulp
#: of its argument's rounding, i.e. below 4e-15 relative; ndtri adds its own 1e-16s.
DRAW_RTOL = 4e-15
#: A truncated normal's p = pa + u (pb - pa) rounds differently when the core fuses the
#: multiply-add (an ulp of p, 1e-16 absolute), and the inverse CDF multiplies that by its slope
#: 1/phi(z): up to 3e-14 absolute in z at |z| = 3.5, ~1e-13 relative in the value.
TRUNCATED_NORMAL_RTOL = 1e-12

SEEDS = (0, 1, 2009, 2**32 - 1, 2**32, 2**64 - 1)


@pytest.mark.parametrize("seed", SEEDS)
def test_the_cores_uniforms_are_the_references_bit_for_bit(seed):
    rng = np.random.default_rng(seed % 2**32)
    index = np.concatenate([np.arange(1000), rng.integers(0, 2**63 - 1, 1000),
                            [2**32 - 1, 2**32, 2**63 - 1]]).astype(np.int64)
    for name in ("illuminance_lux", "design", "shake_deg_per_s"):
        stream = streams.stream_id(name)
        assert np.array_equal(_core.testing.stream_uniforms(seed, stream, index),
                              streams.uniforms(seed, stream, index))


def _block_cases():
    """Index arrays for the core's stream_uniforms, which takes them 64 points (a block) at a
    time from the first and pads a partial last block by repeating its last index: blocks of
    whole pairs (consecutive from an even index: one Philox call per two points) and every other
    kind of block (one call per point)."""
    rng = np.random.default_rng(5)
    block = 64
    top = 2**64
    return {
        "consecutive from even": np.arange(0, 40 * block),
        "consecutive from even, far": np.arange(2**40 + 2 * block, 2**40 + 12 * block),
        "consecutive from odd": np.arange(1, 1 + 20 * block),
        "consecutive from odd, far": np.arange(2**50 + 3, 2**50 + 3 + 10 * block),
        "shuffled": rng.permutation(20 * block),
        "arbitrary": rng.integers(0, top, 10 * block, dtype=np.uint64),
        "arbitrary even": rng.integers(0, top // 2, 10 * block, dtype=np.uint64) * 2,
        "descending": np.arange(10 * block)[::-1],
        "each twice": np.repeat(np.arange(10 * block), 2),
        "one even index": np.full(block, 123_456),
        "one odd index": np.full(block, 123_457),
        "pairs' even points only": np.arange(0, 4 * block, 2),
        "around 2^32, from even": np.arange(2**32 - 3 * block, 2**32 + 3 * block),
        "around 2^32, from odd": np.arange(2**32 - 3 * block + 1, 2**32 + 3 * block),
        "around 2^33, from even": np.arange(2**33 - 3 * block, 2**33 + 3 * block),
        "a block across 2^33": np.arange(2**33 - block // 2, 2**33 + block // 2),
        "around 2^33, from odd": np.arange(2**33 - 3 * block - 1, 2**33 + 3 * block),
        "to 2^64 - 1, from even": np.arange(top - 4 * block, top, dtype=np.uint64),
        "to 2^64 - 1, from odd": np.arange(top - 4 * block + 1, top, dtype=np.uint64),
        "wrapping past 2^64 - 1": np.concatenate([np.arange(top - 10, top, dtype=np.uint64),
                                                  np.arange(0, block - 10, dtype=np.uint64)]),
        "padded tail of 1, from even": np.arange(0, 2 * block + 1),
        "padded tail of 2, from even": np.arange(2**33 - block, 2**33 + block + 2),
        "padded tail of 33, from even": np.arange(1000, 1000 + block + 33),
        "padded tail of 63, from odd": np.arange(7, 7 + block + 63),
        "padded tail to 2^64 - 1": np.arange(top - block - 37, top, dtype=np.uint64),
    }


@pytest.mark.parametrize("case", list(_block_cases()))
@pytest.mark.parametrize("seed", (0, 2009, 2**32, 2**64 - 1))
def test_the_cores_block_uniforms_are_the_references_for_every_kind_of_block(case, seed):
    index = np.asarray(_block_cases()[case]).astype(np.uint64)
    for stream in (0, streams.stream_id("shake_deg_per_s"), 2**32 - 1):
        # the binding takes int64: indices from 2^63 up pass as their two's complement
        got = _core.testing.stream_uniforms(seed, stream, index.view(np.int64))
        assert np.array_equal(got, streams.uniforms(seed, stream, index)), (case, stream)


def test_the_cores_ndtri_matches_mpmath_to_2e_16_relative():
    p = np.concatenate([np.geomspace(1e-300, 0.5, 400), 1 - np.geomspace(2**-53, 0.5, 400),
                        [2**-53, 0.025, 0.5 + 2**-40, 0.975, 1e-11, 1.5e-11]])
    # Newton on mpmath's normal CDF (erfc-based: accurate in both tails) from the reference's
    # value; the upper tail through 1 - p, exact in float64 for p >= 1/2
    def exact_ndtri(x):
        lower = x < 0.5
        tail = mpmath.mpf(x) if lower else 1 - mpmath.mpf(x)
        z = mpmath.findroot(lambda t: mpmath.ncdf(t) - tail, -abs(float(streams.ndtri(x))))
        return float(z if lower else -z)

    with mpmath.workdps(40):  # 40 digits here only, not for the tests that run after
        exact = np.array([exact_ndtri(x) for x in p])
    got = _core.testing.ndtri(p)
    # AS 241 is good to about 1e-16; its Horner sums and the core's log (2 ulp) add a few ulp
    nonzero = exact != 0
    assert np.max(np.abs(got[nonzero] / exact[nonzero] - 1)) < 2e-15
    np.testing.assert_allclose(got, streams.ndtri(p), rtol=2e-15, atol=0)


def test_the_draws_block_ndtri_gives_ndtri_s_bits_lane_by_lane():
    # ndtri_block gathers the tail lanes apart and redoes the far ones: every lane must come
    # out as the scalar ndtri gives it, across the centre's edges and in both far tails
    rng = np.random.default_rng(17)
    edges = np.array([0.075, 0.925, np.nextafter(0.075, 0), np.nextafter(0.925, 1), 0.5])
    p = np.concatenate([rng.uniform(0, 1, 100_003), 10.0 ** -rng.uniform(0, 16, 5000),
                        1 - 10.0 ** -rng.uniform(1, 15, 5000), 2.0 ** -np.arange(1, 60), edges])
    p = p[(p > 0) & (p < 1)]
    assert np.array_equal(_core.testing.ndtri_blocks(p), _core.testing.ndtri(p))


def test_the_cores_exp_and_log_are_within_2_ulp_of_mpmath():
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.uniform(-745, 709.7, 2000), rng.uniform(-1, 1, 2000),
                        [0.0, 1e-300, -1e-300, 709.78, -708.4]])
    with mpmath.workdps(40):  # 40 digits here only, not for the tests that run after
        exact = np.array([float(mpmath.exp(mpmath.mpf(v))) for v in x])
    got = _core.testing.elementary_exp(x)
    normal = exact > np.finfo(float).tiny
    ulp = np.spacing(exact[normal])
    assert np.max(np.abs(got[normal] - exact[normal]) / ulp) <= 2
    y = np.concatenate([np.exp(rng.uniform(-700, 700, 2000)), rng.uniform(0.5, 2, 2000),
                        [5e-324, 1e-310, 1.0, 2.0, np.finfo(float).max]])
    with mpmath.workdps(40):
        exact = np.array([float(mpmath.log(mpmath.mpf(v))) for v in y])
    got = _core.testing.elementary_log(y)
    ulp = np.spacing(np.abs(exact))
    assert np.max(np.abs(got - exact)[exact != 0] / ulp[exact != 0]) <= 2
    assert _core.testing.elementary_log(1.0) == 0.0
    assert np.array_equal(_core.testing.elementary_log(np.array([0.0, np.inf])), [-np.inf, np.inf])
    assert np.isnan(_core.testing.elementary_log(np.array([-1.0, np.nan]))).all()
    assert np.array_equal(_core.testing.elementary_exp(np.array([-800.0, 800.0])), [0.0, np.inf])


def test_the_draws_exp_gives_the_same_bits_as_exp_where_its_argument_is_bounded():
    # exp_normal (|x| <= 700) scales by 2^k in one step, exp_any in two: both exact for a
    # normal result, so the bits must agree everywhere in the bound, its ends included
    rng = np.random.default_rng(11)
    x = np.concatenate([rng.uniform(-700, 700, 200_000), rng.uniform(-1, 1, 20_000),
                        [-700.0, 700.0, 0.0, -0.0, 1e-300, np.log(2) / 2, -np.log(2) / 2]])
    assert np.array_equal(_core.testing.elementary_exp_normal(x), _core.testing.elementary_exp(x))
    assert np.isnan(_core.testing.elementary_exp_normal(np.array([-700.5, 701.0]))).all()


# (distribution, |a| + |b|: the largest term of exp's argument a + u b or a + b z)
@pytest.mark.parametrize("distribution, terms", [
    (LogUniform(1e-300, 1e30), abs(math.log(1e-300)) + math.log(1e330)),
    (LogNormal(1.0, 80.0), 0.0)])
def test_draws_whose_exp_argument_is_unbounded_match_numpy(distribution, terms):
    # |a| + |b| z_max beyond exp_normal's bound: the draws take exp_any
    space = Space(design=HIGH_TIER, illuminance_lux=distribution)
    got = CorePlan(space, 5).points(0, 4096).parameters["illuminance_lux"]
    expected = space.points(5, 0, 4096).parameters["illuminance_lux"]
    assert np.array_equal(np.isfinite(got), np.isfinite(expected))
    # exp turns its argument's absolute error into a relative one: 2 ulp of the argument's
    # largest term (the core may fuse a + u b), and ndtri's 2e-15 relative error (the ndtri
    # test) times b z, i.e. 2e-15 |ln value|
    bound = DRAW_RTOL + 2 * np.finfo(float).eps * terms + 2e-15 * np.abs(np.log(expected))
    assert np.all(np.abs(got / expected - 1) <= bound)


#: One parameter of every kind the space offers, each on a parameter it suits.
EVERY_KIND = dict(
    design=HIGH_TIER,
    illuminance_lux=LogUniform(10, 1e5),
    shake_deg_per_s=Truncated(LogNormal(4.39, 0.5), 0.5, 30),
    reflectance=Truncated(Normal(0.4, 0.1), 0.05, 0.95),
    lens_transmittance=Truncated(Normal(0.8, 0.05), 0.85, 0.99),   # upper tail: mirrored
    read_noise_e=Choice((0.0, 1.0, 2.5), weights=(0.2, 0.5, 0.3)),
    dark_current_e_per_s=Choice((0.0, 5.0)),
    prnu=Uniform(0.0, 0.04),             # u sqrt(s) >= 1 above 0.032 at 30 dB: UNREACHABLE
    fill_factor=Truncated(Uniform(0.5, 1.2), 0.6, 1.0),
    stabilization=Grid((1.0, 2.0, 4.0)),
    snr_db=Grid((30.0, 33.0)),
    jitter_um=Empirical((0.0, 0.1, 0.2, 0.5, 1.0)),
    full_well_e=Truncated(Empirical((3000.0, 5000.0, 8000.0, 20000.0)), 4000, 1e5),
    field_angle_deg=Normal(10.0, 40.0),  # |angle| >= 90 degrees: INVALID
    mtf_threshold=Truncated(LogUniform(0.3, 0.7), 0.4, 0.6),
)
SPACE = Space(**EVERY_KIND)
N = 3 * BLOCK_POINTS + 1234


def test_the_core_forms_the_points_numpy_draws():
    core = CorePlan(SPACE, 77).points(0, N)
    numpy = SPACE.points(77, 0, N)
    assert core.indices.keys() == numpy.indices.keys()
    for name in core.indices:
        assert np.array_equal(core.indices[name], numpy.indices[name]), name
    assert core.parameters.keys() == numpy.parameters.keys()
    for name, value in core.parameters.items():
        axis = SPACE.axes.get(name)
        steep = isinstance(axis, Truncated) and isinstance(axis.distribution,
                                                            (Normal, LogNormal))
        expected = np.broadcast_to(numpy.parameters[name], (N,))
        # mean + std z cancels near 0: there the bound is an ulp of the largest term
        np.testing.assert_allclose(np.broadcast_to(value, (N,)), expected,
                                   rtol=TRUNCATED_NORMAL_RTOL if steep else DRAW_RTOL,
                                   atol=DRAW_RTOL * np.max(np.abs(expected)), err_msg=name)


def test_any_points_are_formed_as_in_their_chunk():
    index = np.array([N - 1, 5, 2**40 + 3, 0, 65535, 65536], dtype=np.int64)
    plan = CorePlan(SPACE, 5)
    some = plan.points_at(index)
    for k, i in enumerate(index):
        one = plan.points(int(i), int(i) + 1)
        for name, value in some.parameters.items():
            assert np.broadcast_to(value, index.shape)[k] == np.broadcast_to(
                one.parameters[name], (1,))[0], name
        for name in some.indices:
            assert some.indices[name][k] == one.indices[name][0]


def _reductions():
    by_bins = ("design", Binned("illuminance_lux", tuple(np.geomspace(10, 1e5, 9))))
    return {"summary": Summary(by=("design", "read_noise_e")),
            "t_mpe": Summary(of="t_mpe_s", by="stabilization"),
            "histogram": Histogram(1e2, 1e7, 50, by="design"),
            "linear": Histogram(0.0, 400.0, 40, log=False, of="f50_cyc_per_mm"),
            "streamed": Quantiles((0.05, 0.5, 0.95), by=by_bins, exact_up_to=0,
                                  bins_per_decade=200),
            "edges": FractionBelow(2e6, by=("design", Binned("shake_deg_per_s",
                                                                 (0.5, 2.0, 3.0, 7.5, 30.0)))),
            "pitch": FractionBelow(1e6, by="pixel_pitch_um"),
            "best": TopK(9), "worst": TopK(4, largest=False, of="f50_cyc_per_mm")}


@pytest.fixture(scope="module")
def scans():
    """The same small scan by the core's fused pass and by NumPy around the core's evaluate."""
    common = dict(seed=4, reductions=_reductions(), chunk_points=2 * BLOCK_POINTS,
                  progress=False)
    return run(SPACE, N, **common), run(SPACE, N, backend="numpy", **common)


def _compare(core, numpy, rtol, rtol_of=None):
    """Counts and labels equal; floating-point statistics within rtol (rtol_of[name] for the
    reductions it names)."""
    for name in core.results:
        a, b = core[name], numpy[name]
        rtol_here = (rtol_of or {}).get(name, rtol)
        for field in dataclasses.fields(a):
            x, y = getattr(a, field.name), getattr(b, field.name)
            if field.name in ("labels", "parameters"):
                assert x.keys() == y.keys()
                for k in x:
                    xs, ys = np.asarray(x[k]), np.asarray(y[k])
                    if xs.dtype.kind == "f":
                        np.testing.assert_allclose(xs, ys, rtol=TRUNCATED_NORMAL_RTOL,
                                                   err_msg=name)
                    else:
                        assert np.array_equal(xs, ys), (name, k)
                continue
            x, y = np.asarray(x), np.asarray(y)
            if x.dtype.kind == "f":
                np.testing.assert_allclose(x, y, rtol=rtol_here, atol=0, equal_nan=True,
                                           err_msg=f"{name}.{field.name}")
            else:
                assert np.array_equal(x, y), (name, field.name)


def test_the_fused_pass_reduces_as_numpy_does(scans):
    core, numpy = scans
    # The same points to a few ulp (DRAW_RTOL), the model at each to its own ~1e-14, summed in
    # another order: 1e-12 is far above what they differ by and far below any real error.
    # Except T_MPE near a 90 degree field angle: T_MPE goes as 1/cos^4(angle), so an ulp of the
    # angle (the core fuses mean + std z) moves it by 4 angle tan(angle) ulp, 1.2e4 ulp (2e-12)
    # at 89.97 degrees, and the scan of seed 4 has such a point holding 99% of its group's
    # T_MPE sum: the T_MPE summary gets 1e-11.
    _compare(core, numpy, rtol=1e-12, rtol_of={"t_mpe": 1e-11})
    statuses = core["summary"].status_counts.sum(axis=0)
    assert np.count_nonzero(statuses) >= 3, statuses  # the space reaches OK, INVALID, UNREACHABLE


def test_the_fused_pass_reduces_as_the_numpy_reference_of_the_model_does():
    # the whole scan in NumPy, the model included, on a smaller scan (the reference evaluates
    # ~0.1 M points/s); the reference's model agrees with the core to ~1e-13 (docs/numerics.md)
    n = BLOCK_POINTS + 999
    reductions = {k: v for k, v in _reductions().items() if k not in ("t_mpe",)}
    common = dict(seed=8, reductions=reductions, chunk_points=BLOCK_POINTS, progress=False)
    _compare(run(SPACE, n, **common), run(SPACE, n, backend="reference", **common), rtol=1e-10)


@pytest.mark.parametrize("seed", [0, 2**64 - 1])
def test_seeds_span_0_to_2_to_the_64(seed):
    result = run(SPACE, 1000, seed=seed, progress=False)
    assert result.seed == seed and result["summary"].points.sum() == 1000


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, "1"])
def test_a_seed_outside_0_2_to_the_64_is_refused(seed):
    with pytest.raises((ValueError, TypeError), match="seed"):
        run(SPACE, 10, seed=seed, progress=False)


def test_a_fresh_seed_is_recorded_and_reproduces_the_scan():
    first = run(SPACE, 5000, progress=False)
    again = run(SPACE, 5000, seed=first.seed, progress=False)
    assert 0 <= first.seed < 2**64
    assert np.array_equal(first["summary"].mean, again["summary"].mean)


def test_a_grid_space_is_visited_in_mixed_radix_by_both():
    space = Space(pixel_pitch_um=Grid((1.4, 1.75, 2.2)), f_number=Grid((2.0, 2.8)),
                  focal_length_mm=5.6, sensor_area_mm2=15.7, illuminance_lux=Grid((10.0, 1e3)))
    core = run(space, reductions={"s": Summary(by=("pixel_pitch_um", "f_number",
                                                      "illuminance_lux"))}, progress=False)
    numpy = run(space, reductions={"s": Summary(by=("pixel_pitch_um", "f_number",
                                                       "illuminance_lux"))}, progress=False,
                backend="numpy")
    assert core.points == 12 and np.array_equal(core["s"].points, np.ones(12))
    # one point per cell: both give that cell's EPC, from the same inputs
    assert np.array_equal(core["s"].mean, numpy["s"].mean)


def test_the_default_backend_needs_no_numpy_draw(monkeypatch):
    import epc_fast.scan.sampling.space

    def refuse(*args, **kwargs):
        raise AssertionError("NumPy drew the points")

    monkeypatch.setattr(epc_fast.scan.sampling.space.Space, "points", refuse)
    result = run(SPACE, 2 * BLOCK_POINTS, seed=1, progress=False,
                 reductions={"s": Summary(), "q": Quantiles(exact_up_to=0)})
    assert result["s"].points.sum() == 2 * BLOCK_POINTS


def test_an_unknown_backend_is_refused_by_name():
    with pytest.raises(ValueError, match="backend"):
        run(SPACE, 10, backend="gpu", progress=False)


def test_quantile_bounds_name_what_they_are_when_values_reach_zero():
    # a space whose EPC is 0 (blur unbounded) at some points: no relative bound there
    space = Space(illuminance_lux=LogUniform(1e-3, 1e3), pixel_pitch_um=1.4, f_number=2.8,
                  focal_length_mm=5.6, pixel_count=8e6, shake_deg_per_s=LogUniform(1, 1e4))
    result = run(space, 2 * BLOCK_POINTS, seed=2, progress=False,
                 reductions={"q": Quantiles((0.01, 0.5), exact_up_to=0)})["q"]
    assert result.lower[0, 0] == 0.0
    statement = result.error_statement()
    assert "absolute bounds [0, 1] (epc)" in statement, statement
    # the relative width is stated over the positive bounds only
    positive = result.lower > 0
    assert np.all(result.upper[positive] / result.lower[positive] - 1
                  <= 2.01 * result.relative_resolution)


def test_a_spectrum_and_solver_options_reach_the_fused_pass():
    wavelengths, weights = np.array([450.0, 550.0, 650.0]), np.array([0.2, 0.5, 0.3])
    options = {"spectrum": (wavelengths, weights), "f50_rtol": 1e-10, "t_mpe_solver": "brent"}
    space = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
                  read_noise_e=Uniform(0.0, 3.0), evaluate_options=options)
    common = dict(seed=3, reductions={"s": Summary(by="design")}, progress=False)
    core, numpy = run(space, 20000, **common), run(space, 20000, backend="numpy", **common)
    assert np.array_equal(core["s"].status_counts, numpy["s"].status_counts)
    np.testing.assert_allclose(core["s"].mean, numpy["s"].mean, rtol=1e-12)
    # and the options change the answer: monochromatic at 550 nm gives other EPCs
    mono = run(Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
                     read_noise_e=Uniform(0.0, 3.0)), 20000, **common)
    assert np.all(np.abs(mono["s"].mean / core["s"].mean - 1) > 1e-3)


def test_top_k_beyond_the_cores_bound_is_refused_before_any_work():
    with pytest.raises(MemoryError, match="TopK k = 2000000"):
        TopK(2_000_000)


@pytest.mark.parametrize("sizes", [(7, 3), (1000, 999, 997), (100_000, 100_000, 300_000),
                                   (2**20, 2**20, 2**20, 2**20)])
def test_grid_digits_are_exact_for_any_number_of_cells(sizes):
    # up to 2^51 cells in vectorised double arithmetic, beyond by integer division, beyond
    # 2^63 saturated (point indices are below it); held against Python's integers
    grids = {name: Grid(tuple(float(v) for v in range(1, n + 1)))
             for name, n in zip(("prnu", "read_noise_e", "dark_current_e_per_s",
                                 "jitter_um"), sizes)}
    space = Space(illuminance_lux=100.0, pixel_pitch_um=1.4, f_number=2.8,
                  focal_length_mm=5.6, pixel_count=8e6, **grids)
    rng = np.random.default_rng(1)
    index = np.concatenate([np.arange(200), rng.integers(0, 2**62, 500)]).astype(np.int64)
    core = CorePlan(space, 1).points_at(index)
    cells = math.prod(sizes)
    for k, (name, size) in enumerate(zip(grids, sizes)):
        stride = math.prod(sizes[k + 1:])  # mixed radix, the last axis fastest
        expected = [(int(i) % cells) // stride % size for i in index]
        assert np.array_equal(core.indices[name], expected), name


#: Grid spaces whose keys on grid axes fold by position in the grid's cycle (scan_groups.h
#: set_cycle): one cell (a cycle of 64 points), 3 cells (192), 100 cells (1600), and 4100
#: cells, beyond the longest cycle folded by position (4096), folded lane by lane.
CYCLE_GRIDS = {
    "one cell": {},
    "3 cells": {"pixel_pitch_um": Grid((1.4, 1.75, 2.2))},
    "100 cells": {"pixel_pitch_um": Grid((1.4, 2.2)),
                  "f_number": Grid(tuple(1.6 + 0.1 * k for k in range(50)))},
    "4100 cells": {"pixel_pitch_um": Grid((1.4, 2.2)),
                   "f_number": Grid(tuple(1.0 + 0.001 * k for k in range(2050)))},
}


@pytest.mark.parametrize("grids", CYCLE_GRIDS.values(), ids=CYCLE_GRIDS.keys())
def test_a_key_on_grid_axes_reduces_as_the_same_groups_folded_lane_by_lane(grids):
    # The same groups by a key on grid axes alone (folded per position of the grid's cycle)
    # and by that key with a binned part whose first bin holds every point (folded lane by
    # lane): counts, min and max identical, the moments summed in another order within 1e-12.
    fixed = dict(f_number=2.0, focal_length_mm=5.6, sensor_area_mm2=15.7, pixel_pitch_um=1.75,
                 read_noise_e=1.5)
    space = Space(**{**fixed, **grids}, illuminance_lux=LogUniform(0.1, 1e5),
                  shake_deg_per_s=LogNormal(4.39, 0.5), prnu=Uniform(0.0, 0.04))
    axes = tuple(grids)[:1]
    one_bin = Binned("illuminance_lux", (0.0, 1e9, 1e10))  # every point in bin 0 of 2

    def reductions(by):
        return {"summary": Summary(by=by), "below": FractionBelow(2e6, by=by),
                "streamed": Quantiles((0.05, 0.5, 0.95), by=by, exact_up_to=0)}

    common = dict(seed=11, chunk_points=BLOCK_POINTS, threads=2, progress=False)
    n = 2 * BLOCK_POINTS + 777
    cycled = run(space, n, reductions=reductions(axes), **common)
    lanes = run(space, n, reductions=reductions(axes + (one_bin,)), **common)
    for name in ("summary", "below", "streamed"):
        a, b = cycled[name], lanes[name]
        for field in dataclasses.fields(a):
            x, y = getattr(a, field.name), getattr(b, field.name)
            if field.name in ("labels", "q") or not isinstance(x, np.ndarray):
                continue
            y = y[::2] if x.ndim == 0 or y.shape[0] == 2 * x.shape[0] else y  # bin 0's rows
            if field.name in ("mean", "std", "mean_error", "std_error"):  # rounded sums
                np.testing.assert_allclose(x, y, rtol=1e-12, atol=0, err_msg=name)
            else:
                assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), (name, field.name)
    assert cycled["summary"].status_counts.sum() == n
    assert (cycled["summary"].status_counts[:, 2] > 0).all()  # prnu above 0.032: UNREACHABLE
