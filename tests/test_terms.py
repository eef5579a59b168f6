"""Every model term a scan turns on is said where the scan is described: the printed space
(its defaults the values the points take) and the figures' conditions."""

import pytest

from epc_fast import scan
from epc_fast.cfa import DEFAULT_CFA_TRANSMITTANCE, DEFAULT_COLOR_NOISE_GAIN
from epc_fast.plotting.common import space_conditions

LENS = ((0.0, 100.0, 200.0, 400.0), (1.0, 0.8, 0.5, 0.1))
DESIGN = {"pixel_pitch_um": 1.4, "f_number": 2.8, "focal_length_mm": 5.6,
          "sensor_area_mm2": 15.6751, "stabilization": 4.0}


def _space(**options):
    designs = [{"name": "A", **DESIGN, "read_noise_e": 2.0}, {"name": "B", **DESIGN}]
    return scan.Space(design=designs, illuminance_lux=scan.LogUniform(10, 1e5),
                      evaluate_options=options)


def test_a_bayer_scans_printed_defaults_are_the_bayer_values_its_points_take():
    text = " ".join(_space(cfa="bayer").describe().split())
    assert f"cfa_transmittance={DEFAULT_CFA_TRANSMITTANCE:g}" in text
    assert f"color_noise_gain={DEFAULT_COLOR_NOISE_GAIN:g}" in text
    assert "cfa_transmittance=1," not in text and "color_noise_gain=1," not in text
    monochrome = " ".join(_space().describe().split())
    assert "cfa_transmittance=1," in monochrome and "color_noise_gain=1," in monochrome


def test_the_printed_space_says_which_terms_are_on():
    text = " ".join(_space(cfa="bayer", demosaic="bilinear", lens_mtf=LENS).describe().split())
    assert ("terms on: colour filter Bayer, bilinear demosaicking; lens MTF table (1); "
            "read_noise_e 2 (A), 0 (B); stabilization 4") in text


@pytest.mark.parametrize("options, terms", [
    ({}, ["stabilization 4", "read_noise_e 2 (A), 0 (B)"]),
    ({"cfa": "bayer"}, ["colour filter Bayer, malvar2004 demosaicking", "stabilization 4"]),
    ({"lens_mtf": [LENS, LENS]}, ["lens MTF tables (2), picked by lens", "stabilization 4"]),
])
def test_a_figures_conditions_name_every_term_that_is_on(options, terms):
    text = " ".join(space_conditions(_space(**options)))
    for term in terms:
        assert term in text, (term, text)
    assert "Terms on: " in text


def test_a_figure_of_the_papers_ideal_camera_names_no_term():
    from epc_fast.presets import HIGH_TIER

    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 1e5))
    assert not any(line.startswith("Terms on") for line in space_conditions(space))


def test_the_printed_space_names_the_frame_cap_and_each_designs_night_mode():
    night = {"name": "C", **DESIGN, "modes": [{}, {"frames": "auto", "max_frames": 6}]}
    space = scan.Space(design=[{"name": "A", **DESIGN}, night],
                       illuminance_lux=scan.LogUniform(1, 1e5),
                       evaluate_options={"max_exposure_s": 0.125})
    text = " ".join(space.describe().split())
    assert "frame cap 0.125 s" in text and "night mode up to 6 frames (C)" in text
    assert "frame cap" not in " ".join(_space(max_exposure_s=float("inf")).describe().split())
