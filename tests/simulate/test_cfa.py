"""Captures through a Bayer sensor (simulate.capture(cfa="bayer")) against the CFA term of the
model (epc_fast.cfa): cfa="none" is today's capture bit for bit; a Bayer pixel collects t of
the monochrome electrons; the flat-patch SNR of the luminance is the model's, with
color_noise_gain and g_d, within the seeds' scatter (this comparison holds the noise gains);
the shipped demosaicker table reproduces from its script at reduced size; and the MTF50 of a
Bayer edge is the first crossing of the monochrome model MTF times the table (this
comparison holds the table)."""

import functools
import sys

import numpy as np
import pytest
from scipy.optimize import brentq

import epc_fast
from epc_fast import cfa, presets, simulate
from epc_fast.reference.model import mtf_system
from helpers.scripts import load_script
from epc_fast.simulate import camera

DESIGN = presets.HIGH_TIER[0].evaluate_kwargs()  # 2.8 um, F/2.8
SHOT_ONLY = {"read_noise_e": 0.0, "dark_current_e_per_s": 0.0, "prnu": 0.0}

#: The e-SFR's own error on a noise-free edge's MTF50 (tests/simulate/test_agreement.py).
E_SFR = 0.006
#: Below the Nyquist frequency, how far the measured mean transfer rises above the table,
#: which holds at most 1 and never rises (tools/demosaic_mtf.py: Malvar's gradient
#: correction sharpens to 1.061 at 0.15 cycles/pixel, Menon's reaches 1.028 at 0.5;
#: bilinear's never exceeds its table there). An MTF50 where the demosaicker sharpens lies up
#: to this fraction above the model's.
SHARPENING = {"bilinear": 0.0, "malvar2004": 0.061, "menon2007": 0.028}
#: Standard errors a comparison may be off: 4 keeps a true agreement's failure rate near 6e-5.
SEMS = 4.0
#: The standard error of each shipped g_d (tools/demosaic_mtf.py, 16 seeds): 0.0023 at most.
G_D_SEM = 0.0023


def _tool(name):
    return load_script(f"tools/{name}.py")


@pytest.mark.parametrize("extra", [{}, {"denoise_sigma_px": 0.8, "backend": "reference"}])
def test_cfa_none_is_the_monochrome_capture_bit_for_bit(extra):
    # the default and an explicit cfa="none" take the monochrome path: no mosaic, no
    # demosaicking, the same noise draws (tests/simulate/test_camera.py holds that path's physics)
    chart = simulate.slanted_edge((32, 48), 5.0)
    default = simulate.capture(chart, illuminance_lux=300.0, seed=7, **DESIGN, **extra)
    none = simulate.capture(chart, illuminance_lux=300.0, seed=7, cfa="none", **DESIGN, **extra)
    assert np.array_equal(default.image_e, none.image_e)
    assert np.array_equal(default.expected_e, none.expected_e)
    bayer = simulate.capture(chart, illuminance_lux=300.0, seed=7, cfa="bayer", **DESIGN, **extra)
    assert not np.array_equal(bayer.expected_e, none.expected_e)
    same = simulate.capture(chart, illuminance_lux=300.0, seed=7, cfa="none",
                            demosaic="menon2007", **DESIGN, **extra)  # no mosaic to demosaic
    assert np.array_equal(same.image_e, none.image_e)
    assert none.cfa == "none" and none.bayer is None


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
# 0.95: the green channel at 1.12, above K's sensor (a channel may collect more than it)
@pytest.mark.parametrize("transmittance, binning", [(None, 1), (0.5, 1), (0.95, 1), (None, 2)])
def test_a_bayer_flat_patch_collects_t_of_the_monochrome_electrons(demosaic, transmittance,
                                                                   binning):
    design = {**DESIGN, **SHOT_ONLY, "binning": binning}
    chart = simulate.flat(24)
    mono = simulate.capture(chart, illuminance_lux=1000.0, **design)
    c = simulate.capture(chart, illuminance_lux=1000.0, cfa="bayer", demosaic=demosaic,
                         cfa_transmittance=transmittance, exposure_s=mono.exposure_s, **design)
    t = cfa.DEFAULT_CFA_TRANSMITTANCE if transmittance is None else transmittance
    # White balance makes the flat mosaic flat, every demosaicker keeps a flat image flat and
    # the luminance weights sum to 1: exact to rounding (the defaults' t to 4 decimals).
    np.testing.assert_allclose(c.expected_e, t * mono.expected_e, rtol=2e-4 if
                               transmittance is None else 1e-12)
    # without a given exposure, the model's for this colour sensor: its rate t r and noise
    # gain G = g_c g_d (g_c of its channels and weights); with shot noise alone
    # T_MPE = G s / (t r), so G / t times the monochrome sensor's (a demosaicker that averages
    # more noise than the filters lose light, bilinear's, exposes shorter)
    own = simulate.capture(chart, illuminance_lux=1000.0, cfa="bayer", demosaic=demosaic,
                           cfa_transmittance=transmittance, **design)
    g_c = cfa.color_noise_gain(own.bayer.channels, own.bayer.weights)
    model = epc_fast.evaluate(1000.0, **design, cfa="bayer", demosaic=demosaic,
                              cfa_transmittance=own.bayer.transmittance, color_noise_gain=g_c)
    assert own.exposure_s == model.t_mpe_s
    ratio = g_c * cfa.DEMOSAIC_NOISE_GAIN[demosaic] / own.bayer.transmittance
    assert own.exposure_s / mono.exposure_s == pytest.approx(ratio, rel=1e-12)  # roundings


@functools.lru_cache(maxsize=None)
def _flat_gains(demosaic: str, transmittance, seeds: int = 12) -> np.ndarray:
    """The luminance's variance over its mean (cell scale) of a flat Bayer patch, per seed."""
    c = simulate.capture(simulate.flat(112), illuminance_lux=1000.0, seed=0, cfa="bayer",
                         demosaic=demosaic, cfa_transmittance=transmittance,
                         **{**DESIGN, **SHOT_ONLY})
    images = [c.redraw(s).image_e for s in range(seeds)]
    return np.array([image.var(ddof=1) / image.mean() for image in images])


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
@pytest.mark.parametrize("transmittance", [None, 0.6])
def test_a_bayer_flat_patchs_snr_is_the_models(demosaic, transmittance):
    # The model: SNR^2 = (t S)^2 / (color_noise_gain g_d t S), so var / mean = the gain, at a
    # light level, patch and transmittance other than those g_d was measured at.
    gains = _flat_gains(demosaic, transmittance)
    predicted = cfa.DEFAULT_COLOR_NOISE_GAIN * cfa.DEMOSAIC_NOISE_GAIN[demosaic]
    sem = gains.std(ddof=1) / np.sqrt(gains.size)
    tolerance = SEMS * np.hypot(sem, cfa.DEFAULT_COLOR_NOISE_GAIN * G_D_SEM)
    assert abs(gains.mean() - predicted) < tolerance
    assert tolerance < 0.04 * predicted  # a check of a few percent, not a wide band


def test_bilinear_read_noise_has_its_closed_form_gain_below_the_models_one_gain():
    # Read noise of variance s^2 in every pixel: after white balance channel c has
    # s^2 / t_c^2, bilinear interpolation multiplies it by k_c on average over the cell
    # (k_G = 5/8, k_R = k_B = 9/16), and the luminance on the cell's scale has
    # t^2 sum_c y_c^2 k_c / t_c^2 s^2: 0.898 of the model's g_c g_d s^2 (docs/model.md).
    t_c = np.array(cfa.DEFAULT_CHANNEL_TRANSMITTANCES)
    y2 = np.array(cfa.DEFAULT_LUMINANCE_WEIGHTS) ** 2
    t = cfa.DEFAULT_CFA_TRANSMITTANCE
    closed_form = t * t * np.sum(y2 * np.array([9 / 16, 5 / 8, 9 / 16]) / t_c ** 2)
    c = simulate.capture(simulate.flat(128, 0.0), illuminance_lux=100.0, exposure_s=0.01,
                         seed=0, cfa="bayer", demosaic="bilinear",
                         **{**DESIGN, **SHOT_ONLY, "read_noise_e": 3.0})
    gains = np.array([c.redraw(s).image_e.var(ddof=1) / 9.0 for s in range(12)])
    sem = gains.std(ddof=1) / np.sqrt(gains.size)
    assert abs(gains.mean() - closed_form) < SEMS * sem
    model = cfa.DEFAULT_COLOR_NOISE_GAIN * cfa.DEMOSAIC_NOISE_GAIN["bilinear"]
    assert gains.mean() / model == pytest.approx(0.898, abs=0.01)


def test_a_bayer_redraw_is_a_fresh_capture_with_that_seed():
    chart = simulate.flat(32)
    first = simulate.capture(chart, illuminance_lux=500.0, seed=1, cfa="bayer",
                             demosaic="bilinear", **DESIGN)
    fresh = simulate.capture(chart, illuminance_lux=500.0, seed=2, cfa="bayer",
                             demosaic="bilinear", **DESIGN)
    np.testing.assert_array_equal(first.redraw(2).image_e, fresh.image_e)


def _shipped_std(name: str, knots) -> np.ndarray:
    columns = cfa._table_columns()
    return np.interp(knots, columns["f_cyc_per_px"], columns[f"{name}_std"])


def test_the_shipped_table_reproduces_from_its_script_at_reduced_size():
    tool = _tool("demosaic_mtf")
    knots = np.round(np.arange(0.0, 0.5001, 0.05), 10)
    runs = tool.measure_mtf(designs=tool.DESIGNS[:1], angles=(5.0,), widths=(96,),
                            knots=knots)
    for name, (values, _, _) in tool.table(runs).items():
        shipped = cfa.demosaic_mtf_table(name)(knots)
        # One of the shipped captures against their mean: within SEMS of their scatter up to
        # each knot (the running minimum carries a knot's deviation onwards), plus the CSV's
        # rounding to 4 decimals.
        reach = np.maximum.accumulate(_shipped_std(name, knots))
        np.testing.assert_array_less(np.abs(values - shipped), SEMS * reach + 1e-4)


@functools.lru_cache(maxsize=None)
def _bayer_edge(preset: int, lux: float, demosaic: str):
    design = presets.HIGH_TIER[preset].evaluate_kwargs()
    return design, simulate.capture(simulate.slanted_edge((96, 128), 5.0), illuminance_lux=lux,
                                    cfa="bayer", demosaic=demosaic, **design)


def _model_mtf50(design: dict, c, table) -> float:
    """cycles/mm: the first crossing of 1/2 by the monochrome model MTF at the capture's blur
    times the demosaicker's table at f p_out."""
    d = camera.capture_inputs(design)
    p_mm = c.pitch_um * 1e-3

    def mtf(f):
        mono = mtf_system(f, d["f_number"], d["pixel_pitch_um"], d["fill_factor"], c.blur_mm,
                          d["jitter_um"], [d["wavelength_nm"]], [1.0])
        return float(mono * table(f * p_mm)) - 0.5

    f = np.linspace(1e-6, 1.0 / p_mm, 2001)
    first = int(np.flatnonzero(np.array([mtf(x) for x in f]) < 0.0)[0])
    return brentq(mtf, f[first - 1], f[first], xtol=1e-9)


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
@pytest.mark.parametrize("preset, lux", [(0, 1e5), (3, 1e5)])
def test_a_bayer_edges_mtf50_is_the_monochrome_model_times_the_table(demosaic, preset, lux):
    design, c = _bayer_edge(preset, lux, demosaic)
    model = _model_mtf50(design, c, cfa.demosaic_mtf_table(demosaic))
    # the e-SFR with bin-width correction: the camera's own MTF, as the model's is
    measured = simulate.esfr(c.expected_e, c.pitch_um, bin_correction=True).mtf50_cyc_per_mm
    f_px = model * c.pitch_um * 1e-3
    # The e-SFR's own error, what the table gives up where the demosaicker sharpens, and
    # SEMS of the table's captures' scatter at the crossing (a transfer's error moves the
    # crossing by at most as much, relatively, where the system MTF falls at least as fast
    # as 1/f).
    tolerance = E_SFR + SHARPENING[demosaic] + SEMS * float(_shipped_std(demosaic, f_px))
    assert abs(measured / model - 1.0) < tolerance
    assert measured < 1.0 / (2.0 * c.pitch_um * 1e-3) * 1.05  # the crossing is near Nyquist or below


@pytest.mark.parametrize("kwargs, message", [
    ({"cfa": "xtrans"}, r"^cfa: one of 'none', 'bayer', 'quad_bayer', got 'xtrans'"),
    ({"cfa": "bayer", "demosaic": "ahd"}, r"^demosaic: one of .* got 'ahd'"),
    ({"cfa": "none", "demosaic": "ahd"}, r"^demosaic: one of .* got 'ahd'"),
    ({"cfa": "bayer", "cfa_transmittance": 1.5}, r"^cfa_transmittance: a transmittance in"),
    ({"cfa": "bayer", "cfa_transmittance": float("nan")}, r"^cfa_transmittance:"),
    ({"cfa": "bayer", "channel_transmittances": (0.3, 0.4)}, r"^channel_transmittances: three"),
    ({"cfa": "bayer", "channel_transmittances": (0.3, 0.0, 0.3)},
     r"^channel_transmittances: three positive transmittances"),
    ({"cfa": "bayer", "luminance_weights": (0.3, 0.6, 0.3)}, r"^luminance_weights: three weights"),
])
def test_a_bad_cfa_argument_is_refused_naming_it(kwargs, message):
    with pytest.raises(ValueError, match=message):
        simulate.capture(simulate.flat(16), illuminance_lux=100.0, **kwargs, **DESIGN)


def test_without_color_demosaicing_a_bayer_capture_says_which_extra_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "colour_demosaicing", None)  # an import of it fails
    with pytest.raises(ImportError, match=r"pip install 'epc-fast\[simulate\]'"):
        simulate.capture(simulate.flat(16), illuminance_lux=100.0, cfa="bayer", **DESIGN)
    mono = simulate.capture(simulate.flat(16), illuminance_lux=100.0, **DESIGN)
    assert mono.image_e.shape == (16, 16)


def test_a_monochrome_sensor_behind_a_filter_collects_t_of_the_light_and_meets_the_target():
    # cfa="none" with cfa_transmittance t: the model's sensor behind a neutral filter, whose
    # pixels collect t of the light; the capture's flat patch expects the model's electrons
    # at T_MPE and meets the target (96 x 96 pixels: the SNR scatters by 0.064 dB)
    c = simulate.capture(simulate.flat(96), illuminance_lux=1000.0, seed=2,
                         cfa_transmittance=0.5, **DESIGN)
    np.testing.assert_allclose(c.expected_e, float(c.result.electrons), rtol=1e-12)
    assert simulate.snr(c.image_e).snr_db == pytest.approx(30.0, abs=0.3)


@pytest.mark.parametrize("sensor, gain, own", [("bayer", 1.5, "0.9146"), ("none", 0.8, "1")])
def test_a_color_noise_gain_the_capture_does_not_have_is_refused_naming_it(sensor, gain, own):
    with pytest.raises(ValueError, match=rf"^color_noise_gain: {gain} .*the capture's own, {own}"):
        simulate.capture(simulate.flat(16), illuminance_lux=100.0, cfa=sensor,
                         color_noise_gain=gain, **DESIGN)


@pytest.mark.parametrize("sensor, gain", [("bayer", cfa.DEFAULT_COLOR_NOISE_GAIN),
                                          ("none", 1.0)])
def test_a_color_noise_gain_equal_to_the_captures_own_is_taken(sensor, gain):
    c = simulate.capture(simulate.flat(16), illuminance_lux=100.0, seed=1, cfa=sensor,
                         color_noise_gain=gain, **DESIGN)
    assert c.image_e.shape == (16, 16)
