"""The optimiser's problem (epc_fast.optimize.Problem): every candidate on the same draws
(common random numbers), bit-identical values, the Monte Carlo uncertainty of the value and of
the optimum, draws that are not OK, points outside the domain."""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import optimize, scan
from helpers.optimize import DESIGN, PITCH, shaky_scene


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


def test_a_fixed_binning_and_burst_reach_every_candidate():
    space = scan.Space(design=[DESIGN.with_(read_noise_e=2.0, binning=2, frames=4)],
                       illuminance_lux=scan.LogUniform(10, 1e5), alignment_error_um=0.3)
    problem = optimize.Problem(space, PITCH, points=5_000, seed=9)
    drawn = space.points(9, 0, 5_000).parameters
    assert drawn["binning"] == 2.0 and drawn["frames"] == 4.0
    for pitch in (0.9, 2.6):
        expected = epc_fast.evaluate(**{**drawn, "pixel_pitch_um": pitch}).epc
        assert np.array_equal(problem.epc(pixel_pitch_um=pitch), np.nan_to_num(expected))
    assert 0.8 <= problem.maximize(batches=0).x["pixel_pitch_um"] <= 4.0


def test_readout_modes_give_each_candidate_the_best_mode_per_draw():
    modes = ({"binning": 1}, {"binning": 2, "binning_readout": "charge"})
    space = scan.Space(design=[DESIGN.with_(read_noise_e=2.0, modes=modes)],
                       illuminance_lux=scan.LogUniform(10, 1e5))
    problem = optimize.Problem(space, PITCH, points=5_000, seed=9)
    drawn = space.points(9, 0, 5_000).parameters
    expected = epc_fast.evaluate(**{**drawn, "pixel_pitch_um": 0.8}, modes=list(modes)).epc
    assert np.array_equal(problem.epc(pixel_pitch_um=0.8), np.nan_to_num(expected))
    bursts = scan.Space(design=[DESIGN.with_(modes=({"frames": 1}, {
        "frames": 4, "alignment_error_um": 0.2}))], illuminance_lux=scan.LogUniform(10, 1e5))
    with pytest.raises(ValueError, match="alignment_error_um is optimised and set by the "
                                         "designs' readout modes"):
        optimize.Problem(bursts, {"alignment_error_um": (0, 1)}, points=100, seed=1)


@pytest.mark.parametrize("name", ["binning", "frames"])
def test_a_whole_number_parameter_is_not_searched_as_a_continuous_range(name):
    with pytest.raises(ValueError, match=f"bounds: {name} takes whole numbers only"):
        optimize.Problem(shaky_scene(), {name: (1, 8)}, points=100, seed=1)


def test_a_frame_cap_gives_a_draw_over_it_zero_pixels():
    # 1 to 1000 lux with a 1/20 s frame cap: the dim draws need longer frames (EXPOSURE_LIMIT)
    space = scan.Space(design=[DESIGN], illuminance_lux=scan.LogUniform(1, 1000),
                       evaluate_options={"max_exposure_s": 0.05})
    problem = optimize.Problem(space, PITCH, points=4_000, seed=3)
    drawn = space.points(3, 0, 4_000).parameters
    expected = epc_fast.evaluate(**{**drawn, "pixel_pitch_um": 1.5}, max_exposure_s=0.05)
    capped = expected.status == epc_fast.Status.EXPOSURE_LIMIT
    assert 0 < capped.sum() < capped.size
    epc = problem.epc(pixel_pitch_um=1.5)
    assert np.all(epc[capped] == 0.0) and np.array_equal(epc, np.nan_to_num(expected.epc))
