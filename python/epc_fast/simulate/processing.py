"""The camera's processing of its read-out image: a linear Gaussian denoising filter."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["gaussian_kernel", "denoise", "kernel_reach_px"]


def kernel_reach_px(sigma_px: float) -> int:
    """Pixels the filter reaches either side: ceil(4 sigma)."""
    return int(math.ceil(4.0 * sigma_px)) if sigma_px > 0 else 0


def gaussian_kernel(sigma_px: float) -> np.ndarray:
    """The filter's taps: exp(-i^2 / (2 sigma^2)) on the integers |i| <= ceil(4 sigma),
    normalised to sum 1 (docs/model.md, the denoising filter)."""
    reach = kernel_reach_px(sigma_px)
    i = np.arange(-reach, reach + 1, dtype=float)
    taps = np.exp(-(i * i) / (2.0 * sigma_px * sigma_px))
    return taps / taps.sum()


def denoise(image, sigma_px: float) -> np.ndarray:
    """The image filtered along its rows and then its columns by :func:`gaussian_kernel`
    (separable); its outer ``kernel_reach_px`` pixels see the border repeated, so a capture
    images that much more scene round its chart and crops it after."""
    if sigma_px == 0:
        return image
    from scipy.ndimage import convolve1d

    taps = gaussian_kernel(sigma_px)
    rows = convolve1d(np.asarray(image, dtype=float), taps, axis=1, mode="nearest")
    return convolve1d(rows, taps, axis=0, mode="nearest")
