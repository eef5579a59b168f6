"""The sensor's side of a capture: photo-electrons, dark electrons, their noise, PRNU, the full
well, binning and the read-out of each frame, drawn from a seeded generator."""

from __future__ import annotations

import numpy as np

__all__ = ["read_out", "bin_sum", "readout_parameters", "POISSON_NORMAL_ABOVE"]

#: e-, a mean above which a count is drawn from the normal distribution of the same mean and
#: variance instead of Poisson's (NumPy's Poisson refuses means near 1e19; at 1e12 the two
#: differ by a skewness of 1e-6).
POISSON_NORMAL_ABOVE = 1e12


def _counts(rng, mean):
    mean = np.asarray(mean, dtype=float)
    small = mean <= POISSON_NORMAL_ABOVE
    out = np.empty(mean.shape)
    out[small] = rng.poisson(mean[small])
    big = ~small
    if big.any():
        out[big] = rng.normal(mean[big], np.sqrt(mean[big]))
    return out


def readout_parameters(resolved) -> dict:
    """A resolved design's (:class:`epc_fast.design.ResolvedDesign`) noise parameters, as
    :func:`read_out` takes them."""
    return {"dark_current_e_per_s": float(resolved.parameter("dark_current_e_per_s")),
            "read_noise_e": float(resolved.parameter("read_noise_e")),
            "prnu": float(resolved.parameter("prnu")),
            "full_well_e": float(resolved.parameter("full_well_e")),
            "binning": int(resolved.parameter("binning")),
            "binning_readout": "charge" if resolved.parameter("binning_readout") == 1.0
                               else "digital"}


def bin_sum(image, binning: int) -> np.ndarray:
    """The sums of ``image``'s k x k blocks (its sides are multiples of k)."""
    if binning == 1:
        return image
    rows, cols = image.shape
    return image.reshape(rows // binning, binning, cols // binning, binning).sum(axis=(1, 3))


def read_out(photo_mean_e, *, exposure_s: float, dark_current_e_per_s: float,
             read_noise_e: float, prnu: float, full_well_e: float, rng: np.random.Generator,
             binning: int = 1, binning_readout: str = "digital") -> np.ndarray:
    """e-, each output pixel's signal as the camera reports it.

    ``photo_mean_e`` is one frame's expected photo-electrons per sensor pixel, or a list of
    frames' (the exposure split evenly among them). Each sensor pixel's photo-response is
    scaled by 1 + u g (g a standard normal drawn once per pixel: the PRNU's fixed pattern,
    the same in every frame). In each frame it collects a Poisson number of photo-electrons of
    that mean and a Poisson number of dark electrons of mean D T / n. Read digitally, each
    sensor pixel's well holds at most ``full_well_e`` and its read-out adds Gaussian noise of
    rms ``read_noise_e``, and the k x k read values are summed; binned in charge, the k x k
    charges are summed first, into a well of k^2 ``full_well_e``, and read once. The frames'
    values are summed and the mean dark signal k^2 D T subtracted (the camera's black level);
    its noise stays.
    """
    frames = list(photo_mean_e) if isinstance(photo_mean_e, (list, tuple)) else [photo_mean_e]
    frames = [np.asarray(m, dtype=float) for m in frames]
    k = int(binning)
    gain = None
    if prnu > 0.0:
        gain = np.maximum(1.0 + prnu * rng.standard_normal(frames[0].shape), 0.0)
    dark = dark_current_e_per_s * exposure_s / len(frames)
    total = 0.0
    for mean in frames:
        electrons = _counts(rng, mean if gain is None else mean * gain)
        if dark > 0.0:
            electrons += _counts(rng, np.full(mean.shape, dark))
        if binning_readout == "charge" and k > 1:
            electrons = bin_sum(electrons, k)
            well = full_well_e * k * k
        else:
            well = full_well_e
        if np.isfinite(well):
            np.minimum(electrons, well, out=electrons)
        if read_noise_e > 0.0:
            electrons += rng.normal(0.0, read_noise_e, electrons.shape)
        if binning_readout != "charge":
            electrons = bin_sum(electrons, k)
        total = total + electrons
    return total - dark * len(frames) * k * k
