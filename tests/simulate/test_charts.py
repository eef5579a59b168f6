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


@pytest.mark.parametrize("angle_deg", [60.0, 75.0, 85.0, 89.0, -60.0, -85.0, -89.0])
def test_a_near_horizontal_edge_runs_through_the_centre_dark_below_for_a_positive_angle(
        angle_deg):
    chart = simulate.slanted_edge((80, 64), angle_deg, low=0.1, high=0.4)
    r = chart.reflectance()
    assert chart.angle_deg == angle_deg
    # 60 to 89 degrees from the vertical is 30 to 1 from the horizontal: the rows far above
    # and below the centre lie wholly on one side (64 columns span 32 tan(30 deg) = 18.5 rows
    # either side of the centre row at most)
    dark, light = (slice(-15, None), slice(None, 15)) if angle_deg > 0 else (
        slice(None, 15), slice(-15, None))
    assert np.all(r[dark] == 0.1) and np.all(r[light] == 0.4)
    # the edge's line: 10 columns right of the centre it lies 10 / tan(angle) rows lower, a
    # hundredth of a pixel either side of it is light (above, for a positive angle) or dark
    cy, cx = 39.5, 31.5
    a = math.radians(angle_deg)
    y = cy + 10.0 / math.tan(a) + np.array([-0.01, 0.01])
    side = chart.reflectance_at(y, np.full(2, cx + 10.0), pitch_um=1.0,
                                band_cyc_per_mm=math.inf)
    assert list(side) == ([0.4, 0.1] if angle_deg > 0 else [0.1, 0.4])


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
    (lambda: simulate.slanted_edge(32, 30.5), "angle_deg"),
    (lambda: simulate.slanted_edge(32, -59.5), "angle_deg"),
    (lambda: simulate.slanted_edge(32, 89.5), "angle_deg"),
    (lambda: simulate.slanted_edge(32, 90.0), "angle_deg"),
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


def exact_step(u_rows, u_cols):
    return 0.5 + sici(np.add.outer(u_rows, u_cols))[0] / math.pi


@pytest.mark.parametrize("per_column, angle_deg", [(3.2, 5.0), (6.3, 5.0), (4.1, 1.0),
                                                   (5.0, 30.0), (3.7, -12.0)])
def test_the_fast_step_is_sicis_within_its_stated_tolerance(per_column, angle_deg):
    # A capture's grid: u advances 2 pi band spacing cos(angle), 3.2 to 6.3 radians, a column
    # (the band is 0.51 to 1 times the grid's rate) and tan(angle) of that a row, here over
    # 300 x 2000 samples, u up to 6,000; the tolerance is the series' bound (charts.py).
    rows = (np.arange(300) - 137.25) * -per_column * math.tan(math.radians(angle_deg))
    cols = (np.arange(2000) - 1100.5) * per_column
    got = charts.band_limited_step(rows, cols)
    error = np.abs(got - exact_step(rows, cols))
    assert error.max() <= charts.STEP_TOLERANCE
    # Beyond |u| = 64 the series takes over, within the bound, not to round-off.
    assert error.max() > 1e-13


def test_the_fast_step_is_exact_where_the_series_does_not_reach():
    # At u = 0, either side of 64, and on rows whose every column is near the edge.
    rows = np.array([-64.0, -63.999, -1e-300, 0.0, 1e-300, 63.999, 64.0, 64.001])
    cols = np.array([-128.0, -64.0, -0.5, 0.0, 0.5, 64.0, 128.0, 1e5])
    got = charts.band_limited_step(rows, cols)
    assert np.abs(got - exact_step(rows, cols)).max() <= charts.STEP_TOLERANCE
    assert got[3, 3] == 0.5 and np.isfinite(got).all()


def test_a_grid_of_points_takes_the_fast_step_and_a_capture_does_not_see_it(monkeypatch):
    chart = simulate.slanted_edge((48, 64), 5.0, low=0.1, high=0.4)
    y, x = (np.arange(-40, 90) / 5)[:, None], (np.arange(-40, 360) / 5)[None, :]
    band = 0.7 * 5 / 2e-3  # a grid of 5 samples a 2 um pixel
    got = chart.reflectance_at(y, x, pitch_um=2.0, band_cyc_per_mm=band)
    d_mm = ((x - 31.5) * math.cos(math.radians(5)) - (y - 23.5) * math.sin(math.radians(5))) * 2e-3
    exact = 0.1 + 0.3 * (0.5 + sici(2 * math.pi * band * d_mm)[0] / math.pi)
    assert np.abs(got - exact).max() <= 0.3 * charts.STEP_TOLERANCE
    # A capture's image is linear in the chart: through sici, the same to 1e-10 of its value.
    design = dict(pixel_pitch_um=2.0, f_number=2.8, focal_length_mm=5.6,
                  sensor_width_mm=4.57, sensor_height_mm=3.43)
    fast = simulate.capture(chart, illuminance_lux=1000.0, seed=1, **design)
    monkeypatch.setattr(charts, "band_limited_step", exact_step)
    slow = simulate.capture(chart, illuminance_lux=1000.0, seed=1, **design)
    assert np.abs(fast.expected_e / slow.expected_e - 1).max() < 1e-10
