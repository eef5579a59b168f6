"""Designs the tests evaluate: random points over the whole domain and at the corners of its
physical box, points whose lengths float32 cannot hold, and the parameters' defaults."""

from __future__ import annotations

import numpy as np

from epc_fast import params
from epc_fast.selfcheck import random_designs


def parameter_defaults():
    """{name: default} of every parameter of evaluate that has one (epc_fast.params), the one
    spelling of the defaults the tests build points from."""
    return {p.name: p.default for p in params.PARAMETERS if p.default is not None}


# The fraction of points given an invalid value: enough for hundreds per 100,000.
INVALID_FRACTION = 0.01


def log_uniform(rng, lo, hi, n):
    """``n`` draws of ``rng``, log-uniform on lo..hi."""
    return np.exp(rng.uniform(np.log(lo), np.log(hi), n))


def _half_zero(rng, values, zero_fraction=0.5):
    return np.where(rng.random(values.shape) < zero_fraction, 0.0, values)


def random_design_points(n, seed, *, size="sensor_area_mm2", invalid_fraction=INVALID_FRACTION,
                         sensor_terms=False, optics_terms=False):
    """``n`` random design points spread over the whole domain, as keyword arrays for evaluate.

    Illuminance is log-uniform on 1e-3..1e7 lux with a few exact zeros; the sensor terms (read
    noise, dark current, PRNU) are zero on about half the points each, so the shot-noise-only
    path is exercised as much as the general one. A fraction ``invalid_fraction`` of the points
    gets one parameter replaced by a value outside its domain (NaN, a negative pitch,
    reflectance 1.5, an infinite f-number, ...), so that every status occurs. ``size`` is
    "sensor_area_mm2" or "pixel_count".

    ``sensor_terms`` adds binning (k = 1 to 8, 1 on about half the points), bursts (n = 1 to 32,
    1 on about half) and the alignment error (0 to 5 um, 0 on a third), drawn from a stream of
    their own: the other parameters are the same points either way. Their invalid values (k = 0,
    2.5, NaN; n = 0.5; a negative or NaN alignment error) then take part in the invalid points.

    ``optics_terms`` adds the wavefront error (0 to 0.16 waves, 0 on a third) and denoising
    (sigma log-uniform on 0.05 to 20 output pixels, 0 on a third), from a stream of their own,
    with their invalid values (negative, NaN, past the domain's end).
    """
    rng = np.random.default_rng(seed)
    illuminance = log_uniform(rng, 1e-3, 1e7, n)
    illuminance[rng.random(n) < 0.002] = 0.0
    p = {
        "illuminance_lux": illuminance,
        "pixel_pitch_um": rng.uniform(0.3, 20.0, n),
        "f_number": rng.uniform(0.7, 64.0, n),
        "focal_length_mm": rng.uniform(1.0, 100.0, n),
        "reflectance": rng.uniform(0.0, 1.0, n),
        "lens_transmittance": rng.uniform(0.0, 1.0, n),
        "field_angle_deg": rng.uniform(-80.0, 80.0, n),
        "fill_factor": rng.uniform(0.05, 1.0, n),
        "electrons_per_lux_s_m2": 2.5e15 * log_uniform(rng, 0.5, 2.0, n),
        "read_noise_e": _half_zero(rng, rng.uniform(0.0, 50.0, n)),
        "dark_current_e_per_s": _half_zero(rng, rng.uniform(0.0, 1e4, n)),
        "prnu": _half_zero(rng, rng.uniform(0.0, 0.05, n)),
        "full_well_e": np.where(rng.random(n) < 0.5, np.inf, log_uniform(rng, 1e2, 1e6, n)),
        "snr_db": rng.uniform(5.0, 60.0, n),
        "shake_deg_per_s": _half_zero(rng, rng.uniform(0.0, 60.0, n), zero_fraction=0.2),
        "stabilization": rng.uniform(1.0, 8.0, n),
        "jitter_um": _half_zero(rng, rng.uniform(0.0, 5.0, n), zero_fraction=0.8),
        "wavelength_nm": rng.uniform(400.0, 700.0, n),
        "mtf_threshold": rng.uniform(0.1, 0.9, n),
    }
    if size == "sensor_area_mm2":
        p["sensor_area_mm2"] = log_uniform(rng, 0.1, 1e3, n)
    elif size == "pixel_count":
        p["pixel_count"] = np.round(log_uniform(rng, 1e4, 1e9, n))
    else:
        raise ValueError(f"size must be sensor_area_mm2 or pixel_count, got {size!r}")

    # One bad value per chosen point, in a parameter chosen at random.
    bad_values = {
        "illuminance_lux": [np.nan, -1.0, np.inf],
        "pixel_pitch_um": [np.nan, -1.4, 0.0, np.inf],
        "f_number": [np.nan, np.inf, 0.0, -2.8],
        "focal_length_mm": [np.nan, -5.6, np.inf],
        size: [np.nan, -1.0, 0.0, np.inf],
        "reflectance": [np.nan, 1.5, -0.1],
        "lens_transmittance": [np.nan, 1.5, -0.1],
        "field_angle_deg": [np.nan, 90.0, -95.0],
        "fill_factor": [np.nan, 0.0, 1.5],
        "electrons_per_lux_s_m2": [np.nan, 0.0, np.inf],
        "read_noise_e": [np.nan, -1.0, np.inf],
        "dark_current_e_per_s": [np.nan, -1.0, np.inf],
        "prnu": [np.nan, -0.01, np.inf],
        "full_well_e": [np.nan, 0.0, -1.0],
        "snr_db": [np.nan, np.inf, -np.inf],
        "shake_deg_per_s": [np.nan, -1.0, np.inf],
        "stabilization": [np.nan, 0.0, np.inf],
        "jitter_um": [np.nan, -1.0, np.inf],
        "wavelength_nm": [np.nan, 0.0, np.inf],
        "mtf_threshold": [np.nan, 0.0, 1.0],
    }
    if sensor_terms:
        terms = np.random.default_rng([seed, 39])
        p["binning"] = np.where(terms.random(n) < 0.5, 1.0, terms.integers(2, 9, n).astype(float))
        p["frames"] = np.where(terms.random(n) < 0.5, 1.0, terms.integers(2, 33, n).astype(float))
        p["alignment_error_um"] = _half_zero(terms, terms.uniform(0.0, 5.0, n), zero_fraction=1 / 3)
        bad_values.update(binning=[0.0, 2.5, np.nan, -2.0], frames=[0.5, 0.0, np.nan],
                          alignment_error_um=[-0.5, np.nan, np.inf])
    if optics_terms:
        terms = np.random.default_rng([seed, 40])
        p["wavefront_rms_waves"] = _half_zero(terms, terms.uniform(0.0, 0.16, n), zero_fraction=1 / 3)
        p["denoise_sigma_px"] = _half_zero(terms, log_uniform(terms, 0.05, 20.0, n), zero_fraction=1 / 3)
        bad_values.update(wavefront_rms_waves=[-0.01, np.nan, 0.2],
                          denoise_sigma_px=[-1.0, np.nan, 101.0])
    names = sorted(bad_values)
    for i in np.flatnonzero(rng.random(n) < invalid_fraction):
        name = names[rng.integers(len(names))]
        choices = bad_values[name]
        p[name][i] = choices[rng.integers(len(choices))]
    return p


def box_corners(n, seed):
    """Random designs with each parameter, independently, at an end of the generator's range.

    The extremes meet here: 1e7 lux through F/0.7 onto a 20 um pixel, 1e-3 lux through F/64
    with 60 deg/s of shake, a 5 um jitter on a 0.3 um pixel, 60 dB with PRNU 0.05, ...
    """
    rng = np.random.default_rng(seed)
    p = random_design_points(n, seed, invalid_fraction=0.0)
    ends = {
        "illuminance_lux": (1e-3, 1e7), "pixel_pitch_um": (0.3, 20.0), "f_number": (0.7, 64.0),
        "focal_length_mm": (1.0, 100.0), "sensor_area_mm2": (0.1, 1e3),
        "reflectance": (0.01, 1.0), "lens_transmittance": (0.01, 1.0),
        "field_angle_deg": (-80.0, 80.0), "fill_factor": (0.05, 1.0),
        "electrons_per_lux_s_m2": (1.25e15, 5e15), "read_noise_e": (0.0, 50.0),
        "dark_current_e_per_s": (0.0, 1e4), "prnu": (0.0, 0.05), "full_well_e": (1e2, np.inf),
        "snr_db": (5.0, 60.0), "shake_deg_per_s": (0.0, 60.0), "stabilization": (1.0, 8.0),
        "jitter_um": (0.0, 5.0), "wavelength_nm": (400.0, 700.0), "mtf_threshold": (0.1, 0.9),
    }
    for name, (lo, hi) in ends.items():
        at_end = rng.random(n) < 0.7
        p[name] = np.where(at_end, np.where(rng.random(n) < 0.5, lo, hi), p[name])
    return p


# Points whose lengths (lambda F, pixel aperture sqrt(fill) pitch, blur, jitter) float32 cannot
# hold, each inside every parameter's domain. Illuminance 1e29 lux (and little or no shake)
# where the extreme would otherwise leave too little light for a bounded blur, so that f50 is
# solved; one point keeps its unbounded blur, a lane with no f50 to solve.
WIDE_POINTS = {
    "lambda F 5.5e12 mm": {"f_number": 1e16, "shake_deg_per_s": 0.0, "illuminance_lux": 1e29},
    "lambda F 5.5e12 mm, blur unbounded": {"f_number": 1e16},
    "lambda F 1e-18 mm": {"wavelength_nm": 1e-12},
    "aperture 1e-15 mm": {"pixel_pitch_um": 1e-12, "illuminance_lux": 1e29},
    "aperture 1e13 mm": {"pixel_pitch_um": 1e16},
    "aperture 1e-18 mm by fill factor": {"fill_factor": 1e-30, "illuminance_lux": 1e29,
                                         "shake_deg_per_s": 1e-10},
    "jitter 1e17 mm": {"jitter_um": 1e20},
    "jitter 1e-15 mm": {"jitter_um": 1e-12},
    "blur 1e-33 mm": {"shake_deg_per_s": 1e-30},
    "blur 3e-28 mm": {"stabilization": 1e25},
}


def ordinary_points(n, seed):
    """Random designs with jitter, fill factor and threshold varying too."""
    rng = np.random.default_rng(seed)
    kwargs = random_designs(n, seed=seed)
    kwargs.update(jitter_um=rng.uniform(0.0, 2.0, n), fill_factor=rng.uniform(0.3, 1.0, n),
                  mtf_threshold=rng.uniform(0.2, 0.8, n))
    return kwargs


def with_extremes(ordinary, extremes, at):
    """``ordinary``'s points with point ``at[k]`` of the result being extremes[k] (each a
    modification of the ordinary point it is built from), the rest the ordinary ones in order."""
    defaults = parameter_defaults()
    n = len(ordinary["illuminance_lux"]) + len(extremes)
    mixed = {}
    is_extreme = np.zeros(n, bool)
    is_extreme[at] = True
    for name, values in ordinary.items():
        column = np.empty(n)
        column[~is_extreme] = values
        column[at] = values[:len(at)]
        mixed[name] = column
    for k, extreme in enumerate(extremes):
        for name, value in extreme.items():
            if name not in mixed:  # a parameter the ordinary points leave at its default
                mixed[name] = np.full(n, defaults[name])
            mixed[name][at[k]] = value
    return mixed, is_extreme
