"""The test charts: their reflectances, the slanted edge's band-limited rendering, a picture's
border carried beyond it, and bad sizes and values refused by name."""

import math

import numpy as np
import pytest
from scipy.special import sici

from epc_fast import simulate
from epc_fast.simulate import charts


def test_a_slanted_edge_is_dark_left_light_right_through_the_centre():
    chart = simulate.slanted_edge((64, 80), 5.0, low=0.1, high=0.4)
    r = chart.reflectance()
    assert r.shape == (64, 80)
    assert np.all(r[:, :20] == 0.1) and np.all(r[:, -20:] == 0.4)
    # The edge's line runs through the centre at 5 degrees from the vertical: the point
    # (centre_y + 10, centre_x + 10 tan 5deg) lies on it, a hundredth of a pixel either side
    # is dark or light.
    cy, cx = 31.5, 39.5
    x = cx + 10 * math.tan(math.radians(5)) + np.array([-0.01, 0.01])
    side = chart.reflectance_at(np.full(2, cy + 10.0), x, pitch_um=1.0, band_cyc_per_mm=math.inf)
    assert list(side) == [0.1, 0.4]


def test_the_band_limited_edge_is_the_step_through_an_ideal_low_pass():
    chart = simulate.slanted_edge(32, 5.0, low=0.0, high=1.0)
    x = np.linspace(-5, 5, 11) + 15.5
    got = chart.reflectance_at(np.full_like(x, 15.5), x, pitch_um=2.0, band_cyc_per_mm=300.0)
    d_mm = (x - 15.5) * math.cos(math.radians(5)) * 2e-3
    assert np.allclose(got, 0.5 + sici(2 * math.pi * 300.0 * d_mm)[0] / math.pi, rtol=1e-14)


def test_a_flat_patch_and_a_picture_carry_on_beyond_the_chart():
    assert np.all(simulate.flat(4, 0.3).reflectance_at(np.arange(-9.0, 9.0), 0.0, pitch_um=1,
                                                        band_cyc_per_mm=1.0) == 0.3)
    values = np.arange(12.0).reshape(3, 4) / 12
    chart = simulate.image(values)
    assert np.array_equal(chart.reflectance(), values)
    assert chart.reflectance_at(np.array(-5.0), np.array(9.0), pitch_um=1,
                                band_cyc_per_mm=1.0) == values[0, 3]
    assert chart.reflectance_at(np.array(1.4), np.array(1.6), pitch_um=1,
                                band_cyc_per_mm=1.0) == values[1, 2]
    assert not chart.values.flags.writeable


@pytest.mark.parametrize("call, match", [
    (lambda: simulate.slanted_edge(0), "size_px"),
    (lambda: simulate.slanted_edge(-3), "size_px"),
    (lambda: simulate.slanted_edge(charts.MIN_EDGE_PX - 1), "e-SFR"),
    (lambda: simulate.slanted_edge((32, 8)), "size_px"),
    (lambda: simulate.slanted_edge(32.5), "whole numbers"),
    (lambda: simulate.slanted_edge((1, 2, 3)), "rows, columns"),
    (lambda: simulate.slanted_edge(32, 0.0), "angle_deg"),
    (lambda: simulate.slanted_edge(32, 45.0), "angle_deg"),
    (lambda: simulate.slanted_edge(32, math.nan), "angle_deg"),
    (lambda: simulate.slanted_edge(32, low=0.5, high=0.4), "high"),
    (lambda: simulate.slanted_edge(32, high=1.5), "high"),
    (lambda: simulate.flat(1), "size_px"),
    (lambda: simulate.flat(8, reflectance=-0.1), "reflectance"),
    (lambda: simulate.flat(8, reflectance=True), "reflectance"),
    (lambda: simulate.image(np.ones(5)), "2-D"),
    (lambda: simulate.image(np.ones((0, 3))), "at least 1 x 1"),
    (lambda: simulate.image(np.full((2, 2), 1.5)), r"\[0, 1\]"),
    (lambda: simulate.image(np.array([[0.1, np.nan]])), r"index \(0, 1\)"),
])
def test_bad_charts_are_refused_by_name(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("values", [np.ones((2, 2), dtype=complex), np.array([["a"]]),
                                    np.ones((2, 2), dtype=bool)])
def test_a_picture_must_be_real_numbers(values):
    with pytest.raises(TypeError, match="reflectance_array"):
        simulate.image(values)
