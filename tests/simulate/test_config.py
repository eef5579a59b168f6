"""The simulator's TOML: the designs read by the scan's parser (presets as their
evaluate_kwargs, where each meets its SNR target), [simulate] over the defaults, and the
example config."""

import numpy as np
import pytest

from epc_fast.presets import HIGH_TIER
from epc_fast.jobs.errors import ConfigError
from epc_fast.simulate.config import load_simulate_config, parse_simulate_config
from epc_fast.simulate.review import DEFAULTS
from helpers.scripts import ROOT


def test_presets_are_their_evaluate_kwargs_and_simulate_defaults_fill_in():
    config = parse_simulate_config('[design]\npresets = ["HIGH_TIER"]\n'
                                   "[simulate]\nspokes = 24\n")
    assert [name for name, _ in config.designs] == [d.name for d in HIGH_TIER]
    for (_, kwargs), design in zip(config.designs, HIGH_TIER):
        assert kwargs == pytest.approx(design.evaluate_kwargs())
    assert config.snr_target == [f"30 dB at {d.snr_at_text}" for d in HIGH_TIER]
    assert config.settings == {**DEFAULTS, "spokes": 24}


def test_the_example_config_is_the_papers_high_tier():
    config = load_simulate_config(ROOT / "examples" / "simulate_designs.toml")
    assert [name for name, _ in config.designs] == [d.name for d in HIGH_TIER]
    assert config.settings["seed"] == 2009 and config.settings["star_width_um"] == 358.4


def test_a_float_seed_that_is_whole_is_taken_and_a_fraction_refused():
    text = '[design]\npresets = ["HIGH_TIER"]\n[simulate]\nseed = '
    assert parse_simulate_config(text + "7.0\n").settings["seed"] == 7
    with pytest.raises(ConfigError, match=r"\[simulate\]: seed = 7.5: expected an integer"):
        parse_simulate_config(text + "7.5\n")


#: A phone's camera as a scan config writes it: a Bayer sensor and a lens table in
#: [evaluate], a design's readout and modes as its keys.
PHONE = """\
[evaluate]
cfa = "bayer"
demosaic = "bilinear"
lens_mtf = [[0.0, 200.0, 400.0, 800.0], [1.0, 0.7, 0.45, 0.0]]

[[design.custom]]
name = "phone"
pixel_pitch_um = 0.8
sensor_width_mm = 6.4
sensor_height_mm = 4.8
f_number = 1.8
focal_length_mm = 5.0
binning_readout = "charge"
modes = [{binning = 1}, {binning = 2}]
"""


def test_the_evaluate_table_and_a_designs_readout_and_modes_reach_its_keywords():
    from epc_fast import evaluate
    from epc_fast.sensor import corner_field_angle_deg

    (name, kwargs), = parse_simulate_config(PHONE).designs
    assert name == "phone"
    assert kwargs["cfa"] == "bayer" and kwargs["demosaic"] == "bilinear"
    assert kwargs["binning_readout"] == "charge"
    assert kwargs["modes"] == [{"binning": 1}, {"binning": 2}]
    (table,) = kwargs["lens_mtf"]
    assert list(table.frequencies) == [0.0, 200.0, 400.0, 800.0]
    # the keywords are the design's: evaluate gives what the same design, typed out, gives
    typed = evaluate([10.0, 1e5], pixel_pitch_um=0.8, sensor_area_mm2=6.4 * 4.8, f_number=1.8,
                     focal_length_mm=5.0, field_angle_deg=corner_field_angle_deg(6.4, 4.8, 5.0),
                     cfa="bayer", demosaic="bilinear", binning_readout="charge",
                     lens_mtf=([0.0, 200.0, 400.0, 800.0], [1.0, 0.7, 0.45, 0.0]),
                     modes=[{"binning": 1}, {"binning": 2}])
    got = evaluate([10.0, 1e5], **kwargs)
    np.testing.assert_array_equal(got.epc, typed.epc)
    np.testing.assert_array_equal(got.mode, typed.mode)
    assert list(got.mode) == [1, 0]
    # and the figures' conditions say so (epc_fast.terms, as a scan's figures do)
    terms = "; ".join(parse_simulate_config(PHONE).terms)
    assert "Bayer" in terms and "lens MTF table" in terms and "readout modes" in terms


def test_a_bad_evaluate_key_is_named_as_the_scan_names_it():
    with pytest.raises(ConfigError, match=r"\[evaluate\]: cfa = 'foveon': expected one of"):
        parse_simulate_config(PHONE.replace('cfa = "bayer"', 'cfa = "foveon"'))


def test_the_phone_example_is_a_quad_bayer_sensor_behind_a_lens_table_with_two_modes():
    (name, kwargs), = load_simulate_config(ROOT / "examples" / "simulate_phone.toml").designs
    assert kwargs["cfa"] == "quad_bayer" and len(kwargs["lens_mtf"]) == 1
    assert kwargs["modes"] == [{"binning": 1}, {"binning": 2}]
    assert kwargs["binning_readout"] == "charge"


def test_a_color_noise_gain_no_capture_has_is_refused_naming_the_design():
    text = PHONE.replace('name = "phone"\n', 'name = "phone"\ncolor_noise_gain = 1.5\n')
    with pytest.raises(ConfigError, match=r"\[design\] 'phone': color_noise_gain = 1.5: "
                                          r"expected the capture's own, 0.9146"):
        parse_simulate_config(text)


@pytest.mark.parametrize("old, new", [
    ('demosaic = "bilinear"', 'demosaic = "bilinear"\nmax_exposure_s = 0.1'),
    ("{binning = 2}]", '{binning = 2, frames = "auto", max_frames = 4}]'),
])
def test_a_frame_cap_and_night_mode_reach_the_designs_keywords(old, new):
    (name, kwargs), = parse_simulate_config(PHONE.replace(old, new)).designs
    assert name == "phone"
    if "max_exposure_s" in new:
        assert kwargs["max_exposure_s"] == 0.1
    else:
        assert kwargs["modes"][1] == {"binning": 2, "frames": "auto", "max_frames": 4}
