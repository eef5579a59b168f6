"""The Siemens star: an image chart of spokes round its centre, area-sampled, sized by the
scene's width over the design's pitch, and its refusals."""

import numpy as np
import pytest

from epc_fast import simulate
from epc_fast.simulate.star import SUBSAMPLES


def test_the_star_is_an_image_chart_between_its_reflectances():
    star = simulate.siemens_star(64, spokes=16, low=0.1, high=0.4)
    assert star.kind == "image" and star.shape == (64, 64)
    assert 0.1 <= star.values.min() < 0.12 and 0.38 < star.values.max() <= 0.4
    # the spokes average to their mean over the disc, and outside it the chart is that mean
    assert star.values[0, 0] == pytest.approx(0.25, abs=1e-12)
    assert star.values.mean() == pytest.approx(0.25, abs=2e-3)


def test_a_sine_stars_pixel_is_its_mean_over_the_pixels_square():
    # far from the centre the sine varies slowly, and the 8 x 8 mean is the integral's to
    # the midpoint rule's error, (h^2/24) times the curvature: under 1e-3 of the amplitude here
    n, spokes = 64, 8
    values = simulate.siemens_star(n, spokes=spokes, low=0.0, high=1.0).values
    i, j = 31, 60  # a pixel near the disc's edge, off the axes
    y, x = i - (n - 1) / 2.0, j - (n - 1) / 2.0
    fine = np.linspace(-0.5, 0.5, 401)
    yy, xx = np.meshgrid(y + fine, x + fine, indexing="ij")
    exact = np.mean(0.5 + 0.5 * np.cos(spokes * np.arctan2(yy, xx)))
    assert values[i, j] == pytest.approx(exact, abs=1e-3)
    assert SUBSAMPLES == 8


def test_a_binary_star_takes_its_two_reflectances_away_from_the_spokes_edges():
    values = simulate.siemens_star(64, spokes=8, profile="binary").values
    # theta = 0 is the middle of a light spoke, theta = pi/8 of a dark one
    assert values[31, 50] == pytest.approx(0.4) and values[31, 13] == pytest.approx(0.4)
    r = 20.0
    i, j = round(31.5 - r * np.sin(np.pi / 8)), round(31.5 + r * np.cos(np.pi / 8))
    assert values[i, j] == pytest.approx(0.1)
    assert np.isclose(values, 0.1).sum() > 200 and np.isclose(values, 0.4).sum() > 200


def test_the_same_width_is_half_the_pixels_at_twice_the_pitch():
    fine = simulate.siemens_star(width_um=358.4, pitch_um=1.4)
    coarse = simulate.siemens_star(width_um=358.4, pitch_um=2.8)
    assert fine.shape == (256, 256) and coarse.shape == (128, 128)
    assert simulate.star_size_px(100.0, 3.0) == 33


@pytest.mark.parametrize("kwargs, message", [
    ({"size_px": 7}, "size_px: a whole number of pixels >= 8"),
    ({"size_px": 16.5}, "size_px"),
    ({"size_px": True}, "size_px"),
    ({"spokes": 3}, "spokes: a whole number >= 4"),
    ({"profile": "square"}, "profile: one of sine, binary"),
    ({"low": 0.5, "high": 0.4}, "high: must exceed low"),
    ({"high": 1.5}, r"high: a reflectance in \[0, 1\]"),
    ({"width_um": 100.0}, "give both or neither"),
    ({"width_um": -1.0, "pitch_um": 1.4}, "width_um: a length > 0"),
    ({"width_um": 10.0, "pitch_um": 2.8}, "size_px: a whole number of pixels >= 8"),
    ({"width_um": 1e9, "pitch_um": 1.4},
     r"^width_um: 1e\+09 µm is 714,285,714 pixels of 1.4 µm; a star has at most 8,192"),
    ({"size_px": 10**9}, r"^size_px: a whole number of pixels from 8 to 8,192, got 1000000000$"),
])
def test_a_bad_star_is_refused_by_name(kwargs, message):
    with pytest.raises(ValueError, match=message):
        simulate.siemens_star(**kwargs)
