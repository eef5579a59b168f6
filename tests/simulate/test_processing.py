"""The camera's denoising filter (epc_fast.simulate.processing): its taps, the variance it
leaves of white noise and its transfer."""

import numpy as np
import pytest

from epc_fast.simulate.processing import denoise, gaussian_kernel, kernel_reach_px


@pytest.mark.parametrize("sigma", [0.4, 1.0, 2.5])
def test_the_kernel_is_a_sampled_gaussian_to_four_sigma(sigma):
    taps = gaussian_kernel(sigma)
    reach = kernel_reach_px(sigma)
    assert taps.size == 2 * reach + 1 and reach == int(np.ceil(4 * sigma))
    assert taps.sum() == pytest.approx(1.0, abs=1e-15)
    i = np.arange(-reach, reach + 1)
    assert np.allclose(taps / taps[reach], np.exp(-i ** 2 / (2 * sigma ** 2)), rtol=1e-14)


@pytest.mark.parametrize("sigma", [0.5, 1.5])
def test_white_noise_keeps_the_kernels_sum_of_squares_squared(sigma):
    noise = np.random.default_rng(0).standard_normal((600, 600))
    inner = denoise(noise, sigma)[20:-20, 20:-20]
    g = np.sum(gaussian_kernel(sigma) ** 2) ** 2
    # The sample variance of 313,600 correlated values: its relative scatter is a few times
    # sqrt(2 / n) (1.3e-3 per independent value), 3% covers it.
    assert abs(inner.var() / g - 1) < 0.03


def test_a_sinusoid_is_scaled_by_the_filters_transfer():
    sigma, f = 1.2, 0.17  # cycles per pixel
    x = np.arange(400)
    row = np.cos(2 * np.pi * f * x)
    out = denoise(np.tile(row, (9, 1)), sigma)[4, 50:-50]
    taps = gaussian_kernel(sigma)
    i = np.arange(taps.size) - taps.size // 2
    transfer = np.sum(taps * np.cos(2 * np.pi * f * i))
    # Only the rows are filtered with a varying signal; the columns' filter keeps a constant.
    assert np.allclose(out, transfer * row[50:-50], atol=1e-12)


def test_no_filter_is_the_identity():
    image = np.arange(12.0).reshape(3, 4)
    assert denoise(image, 0.0) is image
