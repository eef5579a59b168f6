"""The signal-to-noise ratio of a flat patch: the mean over the standard deviation of its pixels.

The patch must be uniformly lit (a flat chart, or a flat-field exposure) and the signal in
linear units (e.g. electrons): any shading, texture or edge inside it counts as noise, and a
gamma-encoded signal gives another ratio.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .edge_sfr import image_in_roi

__all__ = ["FlatSNR", "snr", "MIN_PATCH_SIDE_PIXELS"]

#: The fewest rows and columns a patch (after its roi) must have.
MIN_PATCH_SIDE_PIXELS = 2


@dataclass(frozen=True)
class FlatSNR:
    """A flat patch's statistics.

    Attributes
    ----------
    mean : float
        the image's unit: the pixels' mean.
    std : float
        the image's unit: their standard deviation (ddof=1, the sample's).
    snr : float
        1: mean / std (inf for a noiseless patch, NaN for a noiseless patch of 0).
    snr_db : float
        dB: 20 log10(snr).
    pixels : int
        the patch's pixel count.
    """

    mean: float
    std: float
    snr: float
    snr_db: float
    pixels: int


def snr(image, *, roi=None) -> FlatSNR:
    """The SNR of a flat patch (see the module).

    Parameters
    ----------
    image : array_like
        the signal in linear units (e.g. electrons), 2-D, real and finite, uniformly lit; at
        least 2 rows and 2 columns (after ``roi``).
    roi : (row0, row1, col0, col1), optional
        pixel indices: the patch image[row0:row1, col0:col1].

    Raises
    ------
    TypeError, ValueError
        naming the argument and its value.
    """
    patch = image_in_roi(image, roi, MIN_PATCH_SIDE_PIXELS)
    mean = float(patch.mean())
    std = float(patch.std(ddof=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(np.float64(mean) / np.float64(std))
        decibels = float(20.0 * np.log10(np.float64(ratio))) if ratio >= 0 else math.nan
    return FlatSNR(mean=mean, std=std, snr=ratio, snr_db=decibels, pixels=int(patch.size))
