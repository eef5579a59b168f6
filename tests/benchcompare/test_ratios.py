"""The paired ratio, its interval and the verdict, on times made up with a known ratio."""

import numpy as np
import pytest

from epc_fast.benchcompare.ratios import Ratio, paired_ratio, trimmed_mean


def _times(ratio, rounds=30, noise=0.03, drift=0.3, seed=0):
    # the baseline drifts by +-30% from round to round, as a shared machine's speed does;
    # the candidate is the same call `ratio` times slower, with 3% noise of its own
    rng = np.random.default_rng(seed)
    baseline = 0.1 * np.exp(rng.uniform(-drift, drift, rounds))
    candidate = baseline * ratio * np.exp(rng.normal(0, noise, rounds))
    return baseline, candidate


def test_a_ten_percent_slowdown_is_found_through_drift_and_noise():
    r = paired_ratio(*_times(1.10))
    # 30 rounds of 3% noise: the mean's standard error is 0.55%, the interval about +-1.1%
    assert r.estimate == pytest.approx(1.10, rel=0.02)
    assert r.low < 1.10 < r.high
    assert r.high - r.low < 0.05
    assert r.verdict(0.05) == "slower"
    assert r.rounds == 30


def test_the_same_times_on_both_sides_pass():
    baseline, _ = _times(1.0)
    r = paired_ratio(baseline, baseline)
    assert (r.estimate, r.low, r.high) == (1.0, 1.0, 1.0)
    assert r.verdict(0.05) == "same"


def test_a_faster_candidate_is_called_faster_and_passes():
    r = paired_ratio(*_times(0.8))
    assert r.verdict(0.05) == "faster"


def test_a_slowdown_within_the_threshold_is_not_a_failure():
    # 3% slower, surely (the interval excludes 1) but not beyond 5%
    r = paired_ratio(*_times(1.03, noise=0.01))
    assert r.low > 1.0
    assert r.verdict(0.05) == "same"


def test_too_noisy_a_run_is_unclear_not_slower():
    r = paired_ratio(*_times(1.06, rounds=6, noise=0.15, seed=3))
    assert r.low < 1.05 < r.high
    assert r.verdict(0.05) == "unclear"


def test_one_round_hit_by_a_burst_of_load_does_not_move_the_estimate_much():
    baseline, candidate = _times(1.0, noise=0.01)
    candidate[7] *= 3.0  # one candidate sample three times as slow
    r = paired_ratio(baseline, candidate)
    # trimming 10% from each end drops the burst: the estimate stays within 1% of 1
    assert r.estimate == pytest.approx(1.0, abs=0.01)
    assert r.verdict(0.05) == "same"


def test_a_difference_that_lasts_as_long_as_a_process_widens_the_interval():
    # six blocks of five rounds, each block's processes 0-8% apart by their own luck
    baseline, candidate = _times(1.0, noise=0.005)
    blocks = np.repeat(np.arange(6), 5)
    luck = np.array([1.00, 1.08, 1.01, 1.07, 1.02, 1.06])
    candidate = candidate * luck[blocks]
    by_round = paired_ratio(baseline, candidate)
    by_block = paired_ratio(baseline, candidate, blocks)
    assert by_block.estimate == by_round.estimate
    assert by_block.high - by_block.low > 2 * (by_round.high - by_round.low)


def test_the_interval_is_the_same_for_the_same_times():
    times = _times(1.1)
    assert paired_ratio(*times) == paired_ratio(*times)


def test_trimmed_mean_cuts_a_tenth_from_each_end():
    values = np.array([100.0, 1, 2, 3, 4, 5, 6, 7, 8, -100.0])
    assert trimmed_mean(values) == pytest.approx(4.5)


@pytest.mark.parametrize("baseline, candidate, words", [
    ([1.0, 1.0], [1.0, 1.0], "length >= 3"),
    ([1.0, 1.0, 1.0], [1.0, 1.0], "same length"),
    ([1.0, 0.0, 1.0], [1.0, 1.0, 1.0], "positive"),
])
def test_bad_times_are_refused_with_the_reason(baseline, candidate, words):
    with pytest.raises(ValueError, match=words):
        paired_ratio(baseline, candidate)


@pytest.mark.parametrize("low, high, verdict", [
    (1.051, 1.2, "slower"), (1.0, 1.2, "unclear"), (0.9, 1.04, "same"), (0.8, 0.95, "faster"),
])
def test_the_verdict_reads_the_interval_against_the_threshold(low, high, verdict):
    assert Ratio(1.0, low, high, 10).verdict(0.05) == verdict
