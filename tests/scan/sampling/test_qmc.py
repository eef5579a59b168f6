"""Scrambled Sobol' sampling (epc_fast/scan/sampling/qmc.py,
cpp/include/epc_fast/scan/sobol_points.h): the sequence against SciPy's, the scrambling's nets, the
core against the NumPy statement bit for bit, the same numbers whatever the chunks and threads, and
bad input."""

import numpy as np
import pytest

from epc_fast.scan import (BLOCK_POINTS, Choice, FractionBelow, Grid, LogUniform, Quantiles,
                           Space, Summary, Uniform, run)
from epc_fast.scan.sampling import qmc
from epc_fast.scan.running.core_plan import CorePlan
from helpers.scan import SPACE, assert_same_numbers

qmc_scipy = pytest.importorskip("scipy.stats.qmc")

#: A space whose random parameters are uniform on [1, 2): its values are 1 + u, exact, so
#: the core's and NumPy's uniforms are compared bit for bit through them; a grid of 3 cells
#: (not a power of two) and a choice among weighted values.
UNIFORM_SPACE = Space(illuminance_lux=Uniform(1.0, 2.0), f_number=Uniform(1.0, 2.0),
                      pixel_pitch_um=Grid((1.0, 1.4, 2.0)), focal_length_mm=4.0,
                      pixel_count=Choice((8e6, 12e6, 48e6), weights=(0.2, 0.3, 0.5)),
                      shake_deg_per_s=Uniform(1.0, 2.0))


def test_the_unscrambled_points_are_scipys_sobol_sequence_in_every_dimension():
    directions = qmc.direction_numbers(qmc.MAX_DIMENSIONS)
    k = np.arange(1 << 12)
    ours = np.stack([qmc.unscrambled_sobol(directions[d], k)
                     for d in range(qmc.MAX_DIMENSIONS)], axis=1) / 2.0**32
    theirs = qmc_scipy.Sobol(qmc.MAX_DIMENSIONS, scramble=False).random(1 << 12)
    assert np.array_equal(ours, theirs)


@pytest.mark.parametrize("m", [4, 10])
def test_each_replicates_first_2_to_the_m_points_are_a_net_in_each_dimension_and_pair(m):
    # Sobol' dimensions 1 and 2 form a (0, m, 2)-net: every 2^-a x 2^-(m-a) box holds one of
    # the first 2^m points; nested scrambling keeps that, and puts one point in each of the
    # 2^m intervals of every single dimension
    directions = qmc.direction_numbers(8)
    keys = qmc.scramble_keys(2026, 3, 8)
    k = np.arange(1 << m)
    for r in range(3):
        u = np.stack([qmc.sobol_uniform(directions[d], keys[r, d], k) for d in range(8)])
        assert np.all((u > 0) & (u < 1))
        for d in range(8):
            assert np.array_equal(np.sort(np.floor(u[d] * 2**m)), np.arange(2**m))
        for a in range(m + 1):
            cell = np.floor(u[0] * 2**a) * 2**(m - a) + np.floor(u[1] * 2**(m - a))
            assert np.array_equal(np.sort(cell), np.arange(2**m)), (r, a)


def test_replicates_and_seeds_are_different_scramblings():
    directions = qmc.direction_numbers(2)
    k = np.arange(64)
    a, b = qmc.scramble_keys(1, 2, 2), qmc.scramble_keys(2, 2, 2)
    first = qmc.sobol_uniform(directions[1], a[0, 1], k)
    assert not np.array_equal(first, qmc.sobol_uniform(directions[1], a[1, 1], k))
    assert not np.array_equal(first, qmc.sobol_uniform(directions[1], b[0, 1], k))
    assert np.array_equal(first, qmc.sobol_uniform(directions[1], a[0, 1], k))


@pytest.mark.parametrize("replicates", [1, 4, 5])
@pytest.mark.parametrize("sampling", ["sobol", "monte_carlo"])
def test_the_cores_points_are_the_numpy_statements_bit_for_bit(sampling, replicates):
    space = UNIFORM_SPACE.sampled(qmc.Sampling(sampling, replicates))
    core = CorePlan(space, seed=77)
    # a range from a later block, a partial last block, and arbitrary indices in any order
    index = np.concatenate([np.arange(3 * BLOCK_POINTS, 3 * BLOCK_POINTS + 70_000),
                            [5, 2**40 + 3, 17, 17, 2**33 - 1]])
    ours, theirs = space.points_at(77, index), core.points_at(index)
    assert sorted(ours.indices) == sorted(theirs.indices)
    for name in ours.indices:
        assert np.array_equal(ours.indices[name], theirs.indices[name]), name
    for name in ("illuminance_lux", "f_number", "shake_deg_per_s", "pixel_count"):
        assert np.array_equal(ours.parameters[name], theirs.parameters[name]), name
    ranged = space.points(77, 3 * BLOCK_POINTS, 3 * BLOCK_POINTS + 70_000)
    assert np.array_equal(ranged.parameters["f_number"], ours.parameters["f_number"][:70_000])


def test_a_replicate_is_its_points_grid_block_and_its_sobol_index_the_block_number():
    space = UNIFORM_SPACE.sampled(qmc.Sampling("sobol", 4))
    points = space.points(1, 0, 3 * 4 * 8)
    assert np.array_equal(points.indices["replicate"], np.tile(np.repeat(np.arange(4), 3), 8))
    # within one cell and replicate, the first 8 points stratify each dimension into eighths
    first = points.indices["replicate"] == 2
    cell = points.indices["pixel_pitch_um"] == 1
    u = points.parameters["f_number"][first & cell] - 1.0
    assert np.array_equal(np.sort(np.floor(u * 8)), np.arange(8))


def _sobol_run(**kwargs):
    options = {"seed": 5, "sampling": "sobol", "replicates": 4, "progress": False,
               "reductions": {"summary": Summary(by="design"),
                              "streamed": Quantiles((0.05, 0.5), by="design", exact_up_to=0),
                              "exact": Quantiles((0.5,)),
                              "below": FractionBelow(2e6, by=("design", "read_noise_e"))}}
    return run(SPACE, 8 * 4 * 2**14, **{**options, **kwargs})


def test_a_sobol_scan_gives_the_same_numbers_whatever_its_chunks_and_threads():
    reference = _sobol_run(chunk_points=BLOCK_POINTS, threads=1)
    assert_same_numbers(_sobol_run(chunk_points=4 * BLOCK_POINTS, threads=2), reference)
    assert_same_numbers(_sobol_run(chunk_points=8 * BLOCK_POINTS, threads=2), reference)


def test_the_numpy_and_reference_backends_agree_with_the_core_on_a_sobol_scan():
    reductions = {"summary": Summary(by="design"), "below": FractionBelow(2e6, by="design"),
                  "q": Quantiles((0.05, 0.5, 0.95), by="design")}
    options = dict(seed=9, sampling="sobol", replicates=4, reductions=reductions,
                   progress=False)
    core = run(SPACE, 8 * 4 * 64, **options)
    for backend in ("numpy", "reference"):
        other = run(SPACE, 8 * 4 * 64, backend=backend, **options)
        assert np.array_equal(core["below"].below, other["below"].below)
        assert np.array_equal(core["below"].standard_error, other["below"].standard_error)
        # the reference model agrees with the core to ~1e-12 (tests/test_core_vs_reference.py)
        np.testing.assert_allclose(other["summary"].mean, core["summary"].mean, rtol=1e-11)
        np.testing.assert_allclose(other["summary"].mean_error, core["summary"].mean_error,
                                   rtol=1e-6)
        np.testing.assert_allclose(other["q"].estimate, core["q"].estimate, rtol=1e-11)


def test_sobol_points_are_balanced_per_replicate_and_cell_or_refused():
    with pytest.raises(ValueError, match=r"2\^m x replicates x grid cells \(4 x 8\): got 1000"):
        run(SPACE, 1000, sampling="sobol", replicates=4, progress=False)
    with pytest.raises(ValueError, match="replicates .16. must not exceed the points .10."):
        run(SPACE, 10, replicates=16, progress=False)


@pytest.mark.parametrize("replicates, error", [(0, ValueError), (-3, ValueError),
                                               (1025, ValueError), (2.5, TypeError),
                                               ("8", TypeError)])
def test_bad_replicates_are_refused_naming_the_value(replicates, error):
    with pytest.raises(error, match="replicates"):
        run(SPACE, 1 << 16, replicates=replicates, progress=False)


def test_an_unknown_sampling_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match="sampling must be one of 'monte_carlo', 'sobol'; "
                                         "got 'halton'"):
        run(SPACE, 1 << 16, sampling="halton", progress=False)


def test_a_space_without_random_parameters_takes_one_replicate():
    grid = Space(illuminance_lux=Grid((10.0, 100.0)), pixel_pitch_um=1.4, f_number=2.0,
                 focal_length_mm=4.0, pixel_count=12e6)
    result = run(grid, sampling="sobol", progress=False)
    assert result.sampling.replicates == 1 and result.points == 2


def test_a_space_with_more_random_parameters_than_direction_numbers_is_refused():
    space = Space(illuminance_lux=LogUniform(1, 10), pixel_pitch_um=1.4, f_number=2.0,
                  focal_length_mm=4.0, pixel_count=12e6)
    space.axes.update({f"x{i}": Uniform(0, 1) for i in range(qmc.MAX_DIMENSIONS)})
    with pytest.raises(ValueError, match="covers up to 64 random parameters"):
        space.sampled(qmc.Sampling("sobol", 2))


@pytest.mark.parametrize("exact_up_to", [1 << 18, 1 << 15])
def test_a_scan_stopped_by_its_target_gives_the_numbers_of_a_scan_of_its_points(exact_up_to):
    # Stopped at 65,536 points of a cap of 2^20: exact quantiles when a scan of 65,536 points
    # has them (exact_up_to 2^18), streamed when it has not (2^15), as the plain scan's.
    from epc_fast.presets import HIGH_TIER

    space = Space(design=HIGH_TIER[:2], illuminance_lux=LogUniform(10, 1e5))

    def reductions(target):
        return {"summary": Summary(by="design", target=target),
                "q": Quantiles((0.05, 0.5, 0.95), by="design", exact_up_to=exact_up_to),
                "below": FractionBelow(1e6, by="design")}

    common = dict(seed=4, sampling="sobol", replicates=16, progress=False)
    stopped = run(space, 1 << 20, reductions=reductions({"relative": 1e-2}), **common)
    assert stopped.points == BLOCK_POINTS and not stopped.unmet_targets
    plain = run(space, BLOCK_POINTS, reductions=reductions(None), **common)
    assert stopped["q"].exact == plain["q"].exact == (exact_up_to >= BLOCK_POINTS)
    assert_same_numbers(stopped, plain)
