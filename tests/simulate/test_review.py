"""A design review's captures: the same width of star for every design, the edge's MTF50 and
the flat patch's SNR near the model's, a cell without an image or without an MTF50 saying why,
and the same pictures from the same seed."""

import math

import numpy as np
import pytest

from epc_fast.presets import HIGH_TIER
from epc_fast.simulate.review import DEFAULTS, review
from helpers.reviews import DESIGNS, LUX, SETTINGS, small_review


def test_the_review_holds_every_design_at_every_light_level():
    r = small_review()
    assert r.designs == tuple(d.name for d in DESIGNS) and r.illuminance_lux == LUX
    assert [[c.illuminance_lux for c in row] for row in r.cells] == [list(LUX)] * 2
    assert r.settings == {**DEFAULTS, **SETTINGS}


def test_every_design_sees_the_same_width_of_star():
    # 67.2 um is 24 pixels of 2.8 um and 30.5 -> 31 of 2.2 um: the same scene within a pixel
    stars = [row[2].star for row in small_review().cells]
    assert [s.image_e.shape for s in stars] == [(24, 24), (31, 31)]
    widths = [s.image_e.shape[1] * s.pitch_um for s in stars]
    assert all(abs(w - 67.2) <= s.pitch_um / 2 for w, s in zip(widths, stars))


def test_a_cell_without_an_image_says_why():
    cell = small_review().cells[0][0]  # 0.1 lux
    assert cell.star is None and cell.sfr is None
    assert "90 degrees" in cell.why and cell.mtf_why == "no image"
    assert math.isnan(cell.snr_db) and math.isnan(cell.mtf50_cyc_per_mm)
    assert cell.epc == float(cell.result.epc)


def test_a_blur_longer_than_the_widest_edge_is_not_measured_and_says_why():
    cell = small_review().cells[1][1]  # 2.2 um at 100 lux: about 20 pixels of blur
    assert cell.star is not None and cell.sfr is None
    assert "max_edge_columns 160" in cell.mtf_why and math.isnan(cell.mtf50_fraction)


def test_the_measured_mtf50_and_snr_are_near_the_models():
    # one capture's MTF50 of a 64-row edge scatters by 1.4% at 100 lux and 5% at 1000 lux
    # (12 seeds; the narrow line spread of bright light rests on few bins), and the SNR of
    # 1,024 flat pixels by 1/sqrt(2048) = 2.2%, 0.19 dB: 20% and 0.6 dB are three to four of
    # those scatters
    measured = [c for row in small_review().cells for c in row if c.sfr is not None]
    assert len(measured) == 3
    for cell in measured:
        assert cell.mtf50_fraction == pytest.approx(1.0, abs=0.20)
        assert cell.snr_db == pytest.approx(cell.snr_target_db, abs=0.6)


def test_the_mtf50_across_the_motion_is_measured_in_every_cell_with_an_image():
    # The near-horizontal edge, the image moving along it, sees no motion: it is measured even
    # where the blur is too long for the near-vertical edge (2.2 um at 100 lux), its
    # noise-free MTF50 within the e-SFR's error (0.6%, tests/simulate/test_agreement.py) of
    # f50_across at 100 and at 1000 lux alike, one noisy capture's within 20% as above.
    cells = [c for row in small_review().cells for c in row]
    measured = [c for c in cells if c.sfr_across is not None]
    assert [(c.design, c.illuminance_lux) for c in measured] == [
        (d.name, lux) for d in DESIGNS for lux in LUX[1:]]
    for cell in measured:
        f50 = cell.f50_across_model_cyc_per_mm
        assert cell.sfr_across_noiseless.mtf50_cyc_per_mm == pytest.approx(f50, rel=0.006)
        assert cell.mtf50_across_fraction == pytest.approx(1.0, abs=0.20)
        assert f50 > 5 * cell.f50_model_cyc_per_mm or cell.illuminance_lux == 1000.0
    assert all(c.mtf_across_why == "no image" for c in cells if c.why)


def test_the_pictures_white_is_the_stars_lightest_reflectance_without_noise():
    # the star's expected electrons are its reflectance times one scale: its mean reflectance
    # is 0.25 (the mean of 0.1 and 0.4), its lightest pixel about 0.4 (a sharp design)
    cell = small_review().cells[0][2]
    expected = cell.star.expected_e
    assert expected.mean() == pytest.approx(cell.white_e * 0.25 / 0.4, rel=0.02)
    assert expected.max() <= cell.white_e * 1.02


def test_a_blur_longer_than_max_blur_px_is_not_captured_and_says_why():
    design = [(DESIGNS[0].name, DESIGNS[0].evaluate_kwargs())]
    (cell,) = review(design, [100.0], **{**SETTINGS, "max_blur_px": 5}).cells[0]
    assert cell.star is None and math.isnan(cell.snr_db)
    assert cell.why == "the image moves 10 px during T_MPE, more than max_blur_px 5"


def test_the_same_seed_gives_the_same_pictures_and_another_seed_others():
    design = [(DESIGNS[0].name, DESIGNS[0].evaluate_kwargs())]
    small = {**SETTINGS, "star_width_um": 30.0}
    a, b = (review(design, [1000.0], **small).cells[0][0] for _ in range(2))
    c = review(design, [1000.0], **{**small, "seed": 12}).cells[0][0]
    np.testing.assert_array_equal(a.star.image_e, b.star.image_e)
    assert a.mtf50_cyc_per_mm == b.mtf50_cyc_per_mm and a.snr_db == b.snr_db
    assert not np.array_equal(a.star.image_e, c.star.image_e)


def test_an_unknown_setting_is_refused_by_name():
    with pytest.raises(TypeError, match="unknown setting.*star_px"):
        review([], [1.0], star_px=3)


def test_a_binned_designs_review_measures_at_the_binned_pixels_pitch():
    # the 1.4 um design read 2 x 2 is a 2.8 um camera: the star covers the same 67.2 um of
    # scene in 24 of its output pixels, and the edge's MTF50 is measured in cycles/mm of them
    base = HIGH_TIER[3].evaluate_kwargs()
    (cell,) = review([("1.4 um 2x2", {**base, "binning": 2})], [1000.0], **SETTINGS).cells[0]
    assert cell.pitch_um == pytest.approx(2.8) and cell.star.pitch_um == pytest.approx(2.8)
    assert cell.star.image_e.shape == (24, 24)
    # the noise-free edge holds the model's f50 to the e-SFR's accuracy on a 64-row edge
    # (2%); the noisy one to the scatter of test_the_measured_mtf50_and_snr_are_near_the_models
    f50 = cell.f50_model_cyc_per_mm
    assert cell.sfr_noiseless.mtf50_cyc_per_mm == pytest.approx(f50, rel=0.02)
    assert cell.mtf50_fraction == pytest.approx(1.0, abs=0.20)
    assert cell.snr_db == pytest.approx(30.0, abs=0.6)


def test_a_design_with_modes_is_captured_in_the_mode_the_model_picks():
    # 1.4 um read 1x1 or 2x2: at 1000 lux the model picks 2x2 (EPC 1.0 against 0.17 Mpx), in
    # daylight 1x1 (2.5 against 1.5)
    modes = [{"binning": 1}, {"binning": 2}]
    design = {**HIGH_TIER[3].evaluate_kwargs(), "modes": modes}
    cells = review([("1.4 um, 2 modes", design)], [1000.0, 1e5], **SETTINGS).cells[0]
    assert [int(c.result.mode) for c in cells] == [1, 0]
    assert [c.pitch_um for c in cells] == pytest.approx([2.8, 1.4])
    assert [c.star.image_e.shape for c in cells] == [(24, 24), (48, 48)]
    assert [c.mode_text for c in cells] == ["binning=2", "binning=1"]
    for cell in cells:
        assert cell.sfr_noiseless.mtf50_cyc_per_mm == pytest.approx(
            cell.f50_model_cyc_per_mm, rel=0.02)
        assert cell.snr_db == pytest.approx(30.0, abs=0.6)
