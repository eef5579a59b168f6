"""The companion figures of what limits each design: the bands drawn are evaluate's shares of
the loss at f50, stacked, and every text on the figure has room of its own."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import epc_fast
from epc_fast.api import SHARE_OUTPUTS
from epc_fast.plotting.limits import FACTORS, SHARE_LABEL, plot_limits_over_illuminance
from epc_fast.paper import FIGURES
from epc_fast.presets import HIGH_TIER, LOW_TIER

LUX_CHECKED = (100.0, 1000.0, 10000.0, 100000.0)


def bands(ax) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """lux, and the bottom and top edge of each band drawn in ``ax`` (bands, lux), read from
    the filled polygons: at each lux a band's vertices are its bottom and its top."""
    edges, lux = [], None
    for band in ax.collections:
        xy = np.concatenate([path.vertices for path in band.get_paths()])
        lux, where = np.unique(xy[:, 0], return_inverse=True)
        bottom, top = np.full(len(lux), np.inf), np.full(len(lux), -np.inf)
        np.minimum.at(bottom, where, xy[:, 1])
        np.maximum.at(top, where, xy[:, 1])
        edges.append((bottom, top))
    return lux, np.array([b for b, _ in edges]), np.array([t for _, t in edges])


@pytest.fixture(scope="module")
def figure1():
    pytest.importorskip("matplotlib")
    return plot_limits_over_illuminance(HIGH_TIER, title="Figure 1")


def test_each_band_is_evaluates_share_and_the_bands_stack_to_1(figure1):
    for design, ax in zip(HIGH_TIER, figure1.axes):
        lux, bottom, top = bands(ax)
        assert lux[0] == pytest.approx(100.0) and lux[-1] == pytest.approx(1e5)
        assert len(lux) == 241  # 80 points a decade, both ends
        shares = epc_fast.evaluate(lux, **design.evaluate_kwargs(), outputs=SHARE_OUTPUTS)
        # The design has no jitter: the three bands drawn are all of the loss.
        np.testing.assert_array_equal(shares.share_jitter, 0.0)
        expected = np.array([getattr(shares, output) for output, _, _ in FACTORS])
        # A band's thickness is a difference of running sums of shares of order 1.
        np.testing.assert_allclose(top - bottom, expected, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(bottom[0], 0.0)
        np.testing.assert_array_equal(bottom[1:], top[:-1])  # each band sits on the one below
        np.testing.assert_allclose(top[-1], 1.0, rtol=0, atol=1e-12)


def test_motion_limits_the_1_4_um_design_in_dim_light_and_the_optics_in_bright_light(figure1):
    lux, bottom, top = bands(figure1.axes[3])
    drawn = dict(zip([output for output, _, _ in FACTORS], top - bottom))
    at = {L: int(np.argmin(np.abs(np.log(lux / L)))) for L in LUX_CHECKED}
    assert all(lux[i] == pytest.approx(L, rel=1e-12) for L, i in at.items())
    # docs/limits.md: 100 lux 0.02, 0.00, 0.98; 100,000 lux 0.77, 0.22, 0.00.
    assert drawn["share_motion"][at[100.0]] == pytest.approx(0.9839, abs=5e-4)
    assert drawn["share_diffraction"][at[100.0]] == pytest.approx(0.0160, abs=5e-4)
    assert drawn["share_diffraction"][at[1e5]] == pytest.approx(0.7748, abs=5e-4)
    assert drawn["share_pixel"][at[1e5]] == pytest.approx(0.2239, abs=5e-4)
    assert drawn["share_motion"][at[1e5]] < 0.002
    # Between them the limit changes hands: motion most of the loss at 1000 lux, the optics
    # most of it at 10,000 lux.
    assert drawn["share_motion"][at[1000.0]] == pytest.approx(0.8314, abs=5e-4)
    assert drawn["share_motion"][at[10000.0]] == pytest.approx(0.1089, abs=5e-4)


def test_the_smallest_pixels_lose_the_most_to_diffraction_in_bright_light(figure1):
    # At F/2.8 the Airy disc is the same for every pitch, the pixel aperture shrinks with it.
    bright = [bands(ax) for ax in figure1.axes]
    diffraction = [top[0][-1] - bottom[0][-1] for _, bottom, top in bright]
    assert np.all(np.diff(diffraction) > 0.05), diffraction
    # docs/paper.md: 52% with 2.8 um pixels, 77% with 1.4 um.
    assert diffraction[0] == pytest.approx(0.518, abs=5e-4)
    assert diffraction[-1] == pytest.approx(0.775, abs=5e-4)


def test_the_biggest_pixels_hand_over_from_motion_to_the_optics_first(figure1):
    motion = []
    for ax in figure1.axes:
        lux, bottom, top = bands(ax)
        i = int(np.argmin(np.abs(np.log(lux / 1000.0))))
        assert lux[i] == pytest.approx(1000.0, rel=1e-12)
        motion.append((top[2][0] - bottom[2][0], top[2][i] - bottom[2][i]))
    # docs/paper.md: at 100 lux 93% (2.8 um) to 98% (1.4 um); at 1000 lux 28% against 83%.
    assert motion[0][0] == pytest.approx(0.928, abs=5e-4)
    assert motion[-1][0] == pytest.approx(0.984, abs=5e-4)
    assert motion[0][1] == pytest.approx(0.281, abs=5e-4)
    assert motion[-1][1] == pytest.approx(0.831, abs=5e-4)
    assert np.all(np.diff([at_1000 for _, at_1000 in motion]) > 0.1), motion


def test_the_figure_names_the_designs_the_factors_and_the_quantities(figure1):
    assert [ax.get_title() for ax in figure1.axes] == [
        '1/3.2" 2.8 µm', '1/3.2" 2.2 µm', '1/3.2" 1.75 µm', '1/3.2" 1.4 µm']
    legend = [t.get_text() for t in figure1.legends[0].get_texts()]
    assert legend == ["diffraction", "pixel aperture", "motion blur (hand shake)"]
    assert [ax.get_xlabel() for ax in figure1.axes] == ["", "", "Illuminance (lux)",
                                                        "Illuminance (lux)"]
    assert [ax.get_ylabel() for ax in figure1.axes] == [SHARE_LABEL, "", SHARE_LABEL, ""]
    assert SHARE_LABEL == "Share of the MTF loss at f50"
    for ax in figure1.axes:
        assert ax.get_xscale() == "log"
        assert ax.get_xlim() == pytest.approx((100.0, 1e5))
        assert ax.get_ylim() == (0.0, 1.0)
    title = figure1.get_suptitle()
    assert title.startswith("Figure 1\n") and "cos⁴" in title and "^" not in title


@pytest.mark.parametrize("figure_spec", FIGURES, ids=lambda f: f.name)
def test_no_text_touches_another_or_leaves_the_figure(figure_spec):
    pytest.importorskip("matplotlib")
    from helpers.figures import boxes_outside, overlapping_pairs, text_boxes

    figure = plot_limits_over_illuminance(figure_spec.designs, title=figure_spec.limits_title)
    boxes = text_boxes(figure)
    # The title, four panel titles, two axis labels a panel on the outside, 4 x 4 lux ticks
    # on the bottom row, 2 x 6 share ticks on the left, three legend entries, the conditions.
    assert len(boxes) == 1 + 4 + 4 + 8 + 12 + 3 + 1, sorted(boxes)
    assert overlapping_pairs(boxes) == []
    assert boxes_outside(boxes, figure) == []
    renderer = figure.canvas.get_renderer()
    legend = figure.legends[0].get_window_extent(renderer)
    assert all(legend.y1 <= ax.get_tightbbox(renderer).y0 for ax in figure.axes)


def test_an_odd_number_of_designs_leaves_no_empty_panel_and_labels_the_lowest():
    pytest.importorskip("matplotlib")
    from helpers.figures import overlapping_pairs, text_boxes

    figure = plot_limits_over_illuminance(LOW_TIER[:3])
    assert len(figure.axes) == 3
    # The top right panel has nothing below it: it carries its lux ticks and label.
    assert [ax.get_xlabel() for ax in figure.axes] == ["", "Illuminance (lux)",
                                                       "Illuminance (lux)"]
    assert overlapping_pairs(text_boxes(figure)) == []


def test_designs_under_two_readings_are_refused():
    # Checked before anything is drawn: no matplotlib needed.
    with pytest.raises(ValueError, match="one reading"):
        plot_limits_over_illuminance([HIGH_TIER[0], HIGH_TIER[1].read_as("on_axis_33db")])


def test_the_reference_draws_the_same_bands_to_1e_12():
    pytest.importorskip("matplotlib")
    core = bands(plot_limits_over_illuminance(HIGH_TIER[3:]).axes[0])
    reference = bands(plot_limits_over_illuminance(HIGH_TIER[3:], backend="reference").axes[0])
    np.testing.assert_array_equal(core[0], reference[0])
    np.testing.assert_allclose(core[2], reference[2], rtol=0, atol=1e-12)


def test_plotting_the_limits_without_matplotlib_names_the_plot_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(ImportError, match=r"epc-fast\[plot\]"):
        plot_limits_over_illuminance(HIGH_TIER)


def test_a_limits_figure_carries_its_designs_snr_target_scene_points_and_build():
    pytest.importorskip("matplotlib")
    import epc_fast
    from epc_fast import _core
    from helpers.figures import figure_text, legend_boxes

    figure = plot_limits_over_illuminance(LOW_TIER[:3])
    text = figure_text(figure)
    assert "Designs: " + ", ".join(d.name.replace(" um", " µm") for d in LOW_TIER[:3]) in text
    assert "SNR target: " in text and " dB at " in text
    assert "Scene: illuminance 100 to 100000 lux (the x axis)" in text
    assert f"{3 * 241:,} points" in text  # 80 a decade over three decades, both ends: 241
    assert f"epc_fast {epc_fast.__version__}, core {_core.isa}" in text
    renderer = figure.canvas.get_renderer()
    assert figure.texts[-1].get_window_extent(renderer).y1 < legend_boxes(figure)[0].y0
