"""The simulator's TOML: the designs read by the scan's parser (presets as their
evaluate_kwargs, where each meets its SNR target), [simulate] over the defaults, and the
example config."""

import pytest

from epc_fast.presets import HIGH_TIER
from epc_fast.scan.errors import ConfigError
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
