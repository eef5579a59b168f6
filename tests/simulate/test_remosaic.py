"""The quad Bayer sensor's remosaic (simulate.remosaic) and its captures against the model
(cfa="quad_bayer"): the remosaic keeps the pixels whose colour the two patterns share and
reproduces a grey ramp exactly; binned 2 x 2 the quad capture is the Bayer capture bit for bit;
read full size a flat patch collects t of the monochrome electrons, its luminance's noise gain
is the model's REMOSAIC_NOISE_GAIN, an edge's MTF50 is the model's with the remosaic table, and
the shipped table reproduces from its script at reduced size."""

import functools

import numpy as np
import pytest
from scipy.optimize import brentq

import epc_fast
from epc_fast import cfa, presets, simulate
from epc_fast.reference.model import mtf_system
from helpers.scripts import load_script
from epc_fast.simulate import camera, remosaic

DESIGN = presets.HIGH_TIER[0].evaluate_kwargs()  # 2.8 um, F/2.8
SHOT_ONLY = {"read_noise_e": 0.0, "dark_current_e_per_s": 0.0, "prnu": 0.0}
#: The e-SFR's own error on a noise-free edge's MTF50 (tests/simulate/test_agreement.py).
E_SFR = 0.006
#: Below the Nyquist frequency, how far the measured mean transfer rises above the table
#: (tools/remosaic_mtf.py: Malvar's gradient correction sharpens to 1.055 at 0.15
#: cycles/pixel; bilinear and Menon never exceed their tables there).
SHARPENING = {"bilinear": 0.0, "malvar2004": 0.056, "menon2007": 0.0}
#: Standard errors a comparison may be off: 4 keeps a true agreement's failure rate near 6e-5.
SEMS = 4.0
#: The standard error of each shipped g_d (tools/remosaic_mtf.py, 16 seeds): 0.0018 at most.
G_D_SEM = 0.0018


def _tool(name):
    return load_script(f"tools/{name}.py")


def test_the_quad_pattern_is_2x2_blocks_of_the_rggb_cell():
    np.testing.assert_array_equal(remosaic.quad_colors((4, 6)),
                                  [[0, 0, 1, 1, 0, 0], [0, 0, 1, 1, 0, 0],
                                   [1, 1, 2, 2, 1, 1], [1, 1, 2, 2, 1, 1]])
    np.testing.assert_array_equal(remosaic.bayer_colors((2, 2)), [[0, 1], [1, 2]])
    # the Bayer sensor binned 2 x 2 puts the same filters over its sensor pixels
    sensor = simulate.bayer.bayer()
    np.testing.assert_array_equal(remosaic.quad_mosaic(sensor.channels, (8, 12)),
                                  sensor.mosaic((4, 6), 2))


def test_the_remosaic_keeps_the_pixels_whose_colour_the_patterns_share():
    x = np.random.default_rng(3).uniform(1.0, 2.0, (16, 20))
    out = remosaic.remosaic(x)
    same = remosaic.quad_colors(x.shape) == remosaic.bayer_colors(x.shape)
    assert same.mean() == pytest.approx(6 / 16)  # 6 pixels of each 4 x 4 tile
    np.testing.assert_array_equal(out[same], x[same])
    assert not np.allclose(out[~same], x[~same])  # the others are estimates
    np.testing.assert_array_equal(remosaic.remosaic(x), out)  # deterministic


@pytest.mark.parametrize("gy, gx", [(0.0, 1.0), (1.0, 0.0), (0.3, -0.7), (0.0, 0.0)])
def test_the_remosaic_of_a_grey_ramp_is_the_ramp(gy, gx):
    # A grey scene white-balanced is one plane: the linear estimates (2 G_near + G_far) / 3 are
    # exact on a linear ramp in either direction, whichever the classifier picks, and the colour
    # differences vanish: the interior (past the reach) is the ramp to rounding.
    i, j = np.mgrid[0:40, 0:44]
    ramp = 100.0 + gy * i + gx * j
    out = remosaic.remosaic(ramp)
    r = remosaic.REACH_PX
    np.testing.assert_allclose(out[r:-r, r:-r], ramp[r:-r, r:-r], rtol=0, atol=1e-12)


def test_a_quad_sensor_is_read_full_size_only():
    sensor = remosaic.quad_bayer(simulate.bayer.bayer())
    with pytest.raises(ValueError, match=r"binning 1.*got binning 2"):
        sensor.mosaic((8, 8), 2)
    with pytest.raises(ValueError, match=r"^remosaic: a 2-D mosaic"):
        remosaic.remosaic(np.ones(8))


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_binned_2x2_a_quad_capture_is_the_bayer_capture_bit_for_bit(demosaic):
    chart = simulate.slanted_edge((32, 40), 5.0)
    design = {**DESIGN, "binning": 2, "read_noise_e": 2.0}
    quad = simulate.capture(chart, illuminance_lux=300.0, seed=5, cfa="quad_bayer",
                            demosaic=demosaic, **design)
    bayer = simulate.capture(chart, illuminance_lux=300.0, seed=5, cfa="bayer",
                             demosaic=demosaic, **design)
    assert np.array_equal(quad.image_e, bayer.image_e)
    assert np.array_equal(quad.expected_e, bayer.expected_e)
    assert quad.exposure_s == bayer.exposure_s and quad.pitch_um == bayer.pitch_um
    assert type(quad.bayer) is simulate.bayer.Bayer


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_a_full_size_quad_flat_patch_collects_t_and_takes_the_models_exposure(demosaic):
    design = {**DESIGN, **SHOT_ONLY}
    chart = simulate.flat(24)
    mono = simulate.capture(chart, illuminance_lux=1000.0, **design)
    c = simulate.capture(chart, illuminance_lux=1000.0, cfa="quad_bayer", demosaic=demosaic,
                         exposure_s=mono.exposure_s, **design)
    # white balance makes the flat quad mosaic flat, the remosaic and the demosaicker keep it
    # flat, the luminance weights sum to 1: t of the monochrome electrons to rounding
    np.testing.assert_allclose(c.expected_e, cfa.DEFAULT_CFA_TRANSMITTANCE * mono.expected_e,
                               rtol=2e-4)
    assert isinstance(c.bayer, remosaic.QuadBayer) and c.border_px == remosaic.BORDER_PX
    own = simulate.capture(chart, illuminance_lux=1000.0, cfa="quad_bayer", demosaic=demosaic,
                           **design)
    model = epc_fast.evaluate(1000.0, **design, cfa="quad_bayer", demosaic=demosaic,
                              cfa_transmittance=own.bayer.transmittance,
                              color_noise_gain=cfa.color_noise_gain(own.bayer.channels,
                                                                    own.bayer.weights))
    assert own.exposure_s == model.t_mpe_s


@functools.lru_cache(maxsize=None)
def _flat_gains(demosaic: str, seeds: int = 12) -> np.ndarray:
    """The luminance's variance over its mean (cell scale) of a flat full-size quad patch."""
    c = simulate.capture(simulate.flat(112), illuminance_lux=1000.0, seed=0, cfa="quad_bayer",
                         demosaic=demosaic, **{**DESIGN, **SHOT_ONLY})
    images = [c.redraw(s).image_e for s in range(seeds)]
    return np.array([image.var(ddof=1) / image.mean() for image in images])


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_a_full_size_quad_flat_patchs_noise_gain_is_the_models(demosaic):
    # SNR^2 = (t S)^2 / (color_noise_gain g_d t S): var / mean is the gain, here on another
    # design, light level and patch than tools/remosaic_mtf.py measured g_d on
    gains = _flat_gains(demosaic)
    predicted = cfa.DEFAULT_COLOR_NOISE_GAIN * cfa.REMOSAIC_NOISE_GAIN[demosaic]
    sem = gains.std(ddof=1) / np.sqrt(gains.size)
    tolerance = SEMS * np.hypot(sem, cfa.DEFAULT_COLOR_NOISE_GAIN * G_D_SEM)
    assert abs(gains.mean() - predicted) < tolerance
    assert tolerance < 0.04 * predicted  # a check of a few percent, not a wide band


def _shipped_std(name: str, knots) -> np.ndarray:
    columns = cfa._table_columns(cfa.REMOSAIC_MTF_PATH)
    return np.interp(knots, columns["f_cyc_per_px"], columns[f"{name}_std"])


def test_the_shipped_remosaic_table_reproduces_from_its_script_at_reduced_size():
    tool = _tool("remosaic_mtf")
    knots = np.round(np.arange(0.0, 0.5001, 0.05), 10)
    runs = tool.measure_mtf(designs=tool.demosaic_mtf.DESIGNS[:1], angles=(5.0,), widths=(98,),
                            knots=knots)
    for name, (values, _, _) in tool.demosaic_mtf.table(runs).items():
        shipped = cfa.remosaic_mtf_table(name)(knots)
        # one capture against the shipped mean: within SEMS of their scatter up to each knot,
        # plus the CSV's rounding to 4 decimals
        reach = np.maximum.accumulate(_shipped_std(name, knots))
        np.testing.assert_array_less(np.abs(values - shipped), SEMS * reach + 1e-4)


def test_the_shipped_remosaic_table_is_a_table_and_at_most_the_bayer_one():
    knots = np.round(np.arange(0.0, 1.0001, 0.05), 10)
    for name in cfa.DEMOSAICS:
        quad = cfa.remosaic_mtf_table(name)(knots)
        assert quad[0] == 1.0 and np.all(np.diff(quad) <= 0.0)
        # the remosaic interpolates five pixels in eight: never sharper than the Bayer sensor
        assert np.all(quad <= cfa.demosaic_mtf_table(name)(knots) + 1e-4)


@functools.lru_cache(maxsize=None)
def _quad_edge(preset: int, lux: float, demosaic: str):
    design = presets.HIGH_TIER[preset].evaluate_kwargs()
    return design, simulate.capture(simulate.slanted_edge((96, 128), 5.0), illuminance_lux=lux,
                                    cfa="quad_bayer", demosaic=demosaic, **design)


def _model_mtf50(design: dict, c, table) -> float:
    """cycles/mm: the first crossing of 1/2 by the monochrome model MTF at the capture's blur
    times the table at f p_out."""
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
def test_a_full_size_quad_edges_mtf50_is_the_model_with_the_remosaic_table(demosaic, preset,
                                                                           lux):
    design, c = _quad_edge(preset, lux, demosaic)
    model = _model_mtf50(design, c, cfa.remosaic_mtf_table(demosaic))
    # the e-SFR with bin-width correction: the camera's own MTF, as the model's is
    measured = simulate.esfr(c.expected_e, c.pitch_um, bin_correction=True).mtf50_cyc_per_mm
    f_px = model * c.pitch_um * 1e-3
    # the e-SFR's own error, what the table gives up where the chain sharpens, and SEMS of
    # the table's captures' scatter at the crossing
    tolerance = E_SFR + SHARPENING[demosaic] + SEMS * float(_shipped_std(demosaic, f_px))
    assert abs(measured / model - 1.0) < tolerance


@pytest.mark.parametrize("binning", [3, 4])
def test_a_quad_capture_at_another_binning_is_refused_naming_it(binning):
    with pytest.raises(ValueError, match=rf"^cfa='quad_bayer': binning must be 1 .* or 2 "
                                         rf".*got binning {binning}"):
        simulate.capture(simulate.flat(16), illuminance_lux=100.0, cfa="quad_bayer",
                         **{**DESIGN, "binning": binning})


def test_a_quad_capture_with_modes_reads_the_picked_modes_layout():
    # dim light: the model picks binning 2, whose capture is the Bayer sensor of pitch 2p;
    # bright light: full size, remosaicked
    modes = [{"binning": 1}, {"binning": 2}]
    dim = simulate.capture(simulate.flat(16), illuminance_lux=1.0, seed=1, cfa="quad_bayer",
                           modes=modes, **DESIGN)
    bright = simulate.capture(simulate.flat(32), illuminance_lux=1e5, seed=1, cfa="quad_bayer",
                              modes=modes, **DESIGN)
    assert int(dim.result.mode) == 1 and type(dim.bayer) is simulate.bayer.Bayer
    assert dim.pitch_um == 2 * DESIGN["pixel_pitch_um"]
    assert int(bright.result.mode) == 0 and isinstance(bright.bayer, remosaic.QuadBayer)
