"""The sensor's read-out: Poisson counts (a normal of the same moments for huge means), PRNU's
fixed pattern, the full well, read noise and the black level."""

import numpy as np
import pytest

from epc_fast.simulate.noise import POISSON_NORMAL_ABOVE, read_out

NONE = dict(dark_current_e_per_s=0.0, read_noise_e=0.0, prnu=0.0, full_well_e=np.inf)


def test_shot_noise_alone_is_poisson():
    out = read_out(np.full(200_000, 50.0), exposure_s=1.0, rng=np.random.default_rng(0), **NONE)
    assert np.all(out == np.round(out))  # whole electrons
    # mean and variance within 5 standard errors (Poisson: variance 50, fourth moment ~3 s^4)
    assert abs(out.mean() - 50.0) < 5 * np.sqrt(50 / out.size)
    assert abs(out.var() / 50.0 - 1) < 5 * np.sqrt(2 / out.size)


def test_huge_means_are_drawn_normal_with_poissons_moments():
    mean = np.full(100_000, 1e15)
    out = read_out(mean, exposure_s=1.0, rng=np.random.default_rng(1), **NONE)
    assert mean[0] > POISSON_NORMAL_ABOVE
    assert abs(out.std() / np.sqrt(1e15) - 1) < 5 * np.sqrt(1 / (2 * out.size))


def test_dark_current_adds_its_noise_and_the_black_level_takes_its_mean():
    sensor = dict(NONE, dark_current_e_per_s=40.0)
    out = read_out(np.full(200_000, 100.0), exposure_s=0.5, rng=np.random.default_rng(2),
                   **sensor)
    assert abs(out.mean() - 100.0) < 5 * np.sqrt(120 / out.size)
    assert abs(out.var() / 120.0 - 1) < 5 * np.sqrt(2 / out.size)


def test_prnu_is_a_fixed_pattern_of_the_photo_signal():
    sensor = dict(NONE, prnu=0.02, read_noise_e=1.5)
    mean = 5000.0
    out = read_out(np.full(200_000, mean), exposure_s=1.0, rng=np.random.default_rng(3),
                   **sensor)
    var = mean + (0.02 * mean) ** 2 + 1.5 ** 2
    assert abs(out.var() / var - 1) < 5 * np.sqrt(2 / out.size)
    a = read_out(np.full(1000, mean), exposure_s=1.0, rng=np.random.default_rng(4), **sensor)
    b = read_out(np.full(1000, mean), exposure_s=1.0, rng=np.random.default_rng(4), **sensor)
    assert np.array_equal(a, b)


def test_the_full_well_holds_what_it_holds():
    sensor = dict(NONE, full_well_e=900.0, dark_current_e_per_s=100.0)
    out = read_out(np.full(10_000, 2000.0), exposure_s=1.0, rng=np.random.default_rng(5),
                   **sensor)
    assert np.all(out == 900.0 - 100.0)


@pytest.mark.parametrize("mode, reads", [("digital", 4), ("charge", 1)])
def test_binning_sums_the_signal_and_reads_once_in_charge_k_squared_times_digitally(mode, reads):
    sensor = dict(NONE, read_noise_e=3.0, prnu=0.02)
    mean = np.full((400, 400), 250.0)
    out = read_out(mean, exposure_s=1.0, rng=np.random.default_rng(6), binning=2,
                   binning_readout=mode, **sensor)
    assert out.shape == (200, 200)
    # The sum of 4 pixels: 4 means, their shot noise, their PRNU (u/2 of the sum), the reads.
    var = 4 * 250.0 + 4 * (0.02 * 250.0) ** 2 + reads * 9.0
    assert abs(out.mean() - 1000.0) < 5 * np.sqrt(var / out.size)
    assert abs(out.var() / var - 1) < 5 * np.sqrt(2 / out.size)


def test_a_burst_collects_its_total_light_and_reads_each_frame():
    sensor = dict(NONE, read_noise_e=2.0, dark_current_e_per_s=60.0, full_well_e=300.0)
    frames = [np.full(200_000, 100.0)] * 4  # 400 e- in all: a single frame would clip at 300
    out = read_out(frames, exposure_s=1.0, rng=np.random.default_rng(7), **sensor)
    var = 400.0 + 60.0 + 4 * 4.0
    assert abs(out.mean() - 400.0) < 5 * np.sqrt(var / out.size)
    assert abs(out.var() / var - 1) < 5 * np.sqrt(2 / out.size)
