"""The SNR of a flat patch (epc_fast.simulate.flat_patch): known values by hand, Gaussian noise of
a known SNR, the roi, and every bad input."""

import math

import numpy as np
import pytest

from epc_fast.simulate import FlatSNR, snr


def test_a_hand_made_patch_gives_its_mean_and_sample_deviation():
    result = snr([[1.0, 2.0], [3.0, 4.0]])
    # mean 2.5; deviations -1.5, -0.5, 0.5, 1.5: squares sum to 5, over n - 1 = 3
    assert result == FlatSNR(mean=2.5, std=math.sqrt(5 / 3), snr=2.5 / math.sqrt(5 / 3),
                             snr_db=20 * math.log10(2.5 / math.sqrt(5 / 3)), pixels=4)


def test_gaussian_noise_of_a_known_snr_is_measured():
    # mean 1000, standard deviation 10: SNR 100, 40 dB. The sample deviation of n = 40000
    # pixels has a relative standard error 1/sqrt(2 (n - 1)) = 0.35 %: 1.5 % is over 4 of them
    rng = np.random.default_rng(38)
    result = snr(rng.normal(1000.0, 10.0, (200, 200)))
    assert result.pixels == 40000
    assert result.mean == pytest.approx(1000.0, abs=0.25)  # 5 standard errors, 10 / 200 each
    assert result.snr == pytest.approx(100.0, rel=0.015)
    assert result.snr_db == pytest.approx(40.0, abs=20 * math.log10(1.015))


def test_shot_noise_gives_the_square_root_of_the_electrons():
    # Poisson electrons, mean 2500: SNR sqrt(2500) = 50 (the same 1.5 % bound as above)
    result = snr(np.random.default_rng(1).poisson(2500.0, (200, 200)))
    assert result.snr == pytest.approx(50.0, rel=0.015)


def test_a_roi_takes_the_patch():
    image = np.zeros((10, 12))
    image[2:6, 3:9] = np.arange(24).reshape(4, 6)
    result = snr(image, roi=(2, 6, 3, 9))
    assert result.pixels == 24
    assert result.mean == 11.5
    assert result.std == pytest.approx(np.arange(24).std(ddof=1), rel=1e-15)


def test_a_noiseless_patch_has_an_infinite_snr_and_a_zero_one_none():
    assert snr(np.full((4, 4), 3.0)).snr == math.inf
    assert snr(np.full((4, 4), 3.0)).snr_db == math.inf
    zero = snr(np.zeros((4, 4)))
    assert math.isnan(zero.snr) and math.isnan(zero.snr_db)


def test_a_negative_mean_has_a_negative_snr_and_no_decibels():
    result = snr([[-1.0, -2.0], [-3.0, -4.0]])
    assert result.snr == pytest.approx(-2.5 / math.sqrt(5 / 3))
    assert math.isnan(result.snr_db)


@pytest.mark.parametrize("image, error, match", [
    (np.ones(5), ValueError, "image must be 2-D"),
    (np.ones((3, 3, 3)), ValueError, "image must be 2-D"),
    (np.ones((3, 3), complex), TypeError, "image must hold real numbers"),
    (np.ones((3, 3), bool), TypeError, "image must hold real numbers"),
    ("flat", TypeError, "image must"),
    (None, TypeError, "image must"),
    ([[1.0, np.nan], [1.0, 1.0]], ValueError, "NaN or infinite"),
    ([[1.0, np.inf], [1.0, 1.0]], ValueError, "NaN or infinite"),
    (np.ones((1, 5)), ValueError, "at least 2 rows and 2 columns"),
])
def test_a_bad_image_is_refused_naming_it(image, error, match):
    with pytest.raises(error, match=match):
        snr(image)


@pytest.mark.parametrize("roi, error, match", [
    ((0, 4), ValueError, "roi must be"),
    ((0, 4, 0, 4.5), TypeError, "roi must be an integer"),
    ((0, 9, 0, 4), ValueError, "roi=.* must satisfy"),
    ((3, 3, 0, 4), ValueError, "roi=.* must satisfy"),
    ((0, 1, 0, 4), ValueError, "at least 2 rows and 2 columns in its roi"),
])
def test_a_bad_roi_is_refused_naming_it(roi, error, match):
    with pytest.raises(error, match=match):
        snr(np.ones((8, 8)), roi=roi)
