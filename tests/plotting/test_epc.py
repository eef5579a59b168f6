"""The paper's figures of EPC over illuminance (epc_fast.plotting.plot_epc_over_illuminance):
the model's curves and pixel counts, labels that touch nothing, units and legend; without
matplotlib, an error naming the plot extra."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from epc_fast.paper import FIGURES
from epc_fast.plotting import plot_epc_over_illuminance
from epc_fast.presets import HIGH_TIER, evaluate_over_illuminance


def test_a_figure_draws_the_model_and_marks_each_pixel_count():
    figure = plot_epc_over_illuminance(HIGH_TIER, title="Figure 1")
    ax = figure.axes[0]
    curves = [line for line in ax.lines if line.get_linestyle() == "-"]
    marks = {line.get_ydata()[0] for line in ax.lines if line.get_linestyle() == ":"
             and len(line.get_ydata())}
    lux = curves[0].get_xdata()
    assert lux[0] == pytest.approx(100.0) and lux[-1] == pytest.approx(1e5)
    expected = evaluate_over_illuminance(HIGH_TIER, lux).epc / 1e6
    np.testing.assert_array_equal(np.array([c.get_ydata() for c in curves]), expected)
    assert marks == {_physical_count(d) / 1e6 for d in HIGH_TIER}
    assert ax.get_xscale() == "log"


def _physical_count(design) -> float:
    """pixels: the design's sensor area over its pitch squared (docs/model.md)."""
    return design.sensor_area_mm2 * 1e6 / design.pixel_pitch_um ** 2


def test_the_papers_figure_and_a_scans_plot_mark_one_design_at_one_pixel_count():
    # The figure drew columns x rows (1.92 Mpixel for the 2.8 um design), the scan's bands
    # area / pitch^2 (2.00 Mpixel).
    from epc_fast import scan
    from epc_fast.plotting.common import physical_pixel_count
    from epc_fast.scan.plot import scan_pixel_counts

    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 1e5))
    in_scan = scan_pixel_counts(space)
    figure = plot_epc_over_illuminance(HIGH_TIER)
    marks = sorted(line.get_ydata()[0] * 1e6 for line in figure.axes[0].lines
                   if line.get_linestyle() == ":" and len(line.get_ydata()))
    assert marks == pytest.approx(sorted(in_scan.values()), rel=1e-15)
    for design in HIGH_TIER:
        count = physical_pixel_count(design.sensor_area_mm2, design.pixel_pitch_um)
        assert in_scan[design.name] == count == pytest.approx(_physical_count(design), rel=1e-15)
    assert in_scan['1/3.2" 2.8 um'] == pytest.approx(1.999e6, rel=1e-3)


def test_plotting_without_matplotlib_names_the_plot_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(ImportError, match=r"epc-fast\[plot\]"):
        plot_epc_over_illuminance(HIGH_TIER)


def test_the_cli_and_the_plotting_module_import_without_matplotlib():
    code = ("import sys, epc_fast.__main__, epc_fast.plotting, epc_fast.plotting.limits,"
            " epc_fast.paper;"
            "sys.exit('matplotlib' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize("figure_spec", FIGURES, ids=lambda f: f.name)
def test_no_pixel_count_label_touches_a_curve_or_another_label(figure_spec):
    pytest.importorskip("matplotlib")
    from helpers.figures import label_boxes, labels_on_lines, labels_outside, overlapping_pairs

    figure = plot_epc_over_illuminance(figure_spec.designs, title=figure_spec.title)
    ax = figure.axes[0]
    boxes = label_boxes(figure, ax)
    assert len(boxes) == len({_physical_count(d) for d in figure_spec.designs})
    curves = [line for line in ax.lines if line.get_linestyle() == "-"]
    dotted = [line for line in ax.lines if line.get_linestyle() == ":" and len(line.get_xdata())]
    assert overlapping_pairs(boxes) == []
    assert labels_on_lines(boxes, curves + dotted) == []
    assert labels_outside(boxes, figure, ax) == []


def test_each_pixel_count_label_sits_beside_its_own_line():
    pytest.importorskip("matplotlib")
    from helpers.figures import label_boxes

    figure = plot_epc_over_illuminance(HIGH_TIER)
    ax = figure.axes[0]
    for design in HIGH_TIER:
        text = f"{_physical_count(design) / 1e6:.2f} Mpixel"
        box = label_boxes(figure, ax)[text]
        line_y = ax.transData.transform((1.0, _physical_count(design) / 1e6))[1]
        gap = min(abs(box.y0 - line_y), abs(box.y1 - line_y))
        # 2 pt from the line, at 100 dpi 2.8 px; the renderer's text box may start a pixel
        # off that.
        assert gap == pytest.approx(2 * 100 / 72, abs=1.5), text


def test_the_figure_writes_micrometres_and_human_axis_labels():
    pytest.importorskip("matplotlib")
    figure = plot_epc_over_illuminance(HIGH_TIER, title="Figure 1")
    ax = figure.axes[0]
    legend = [t.get_text() for t in figure.legends[0].get_texts()]
    assert legend == ['1/3.2" 2.8 µm', '1/3.2" 2.2 µm', '1/3.2" 1.75 µm', '1/3.2" 1.4 µm',
                      "physical pixel count"]
    assert ax.get_xlabel() == "Illuminance (lux)"
    assert ax.get_ylabel() == "Effective pixel count, EPC (Mpixel)"
    assert "cos⁴" in ax.get_title() and "^" not in ax.get_title()


def test_the_legend_sits_outside_the_axes():
    pytest.importorskip("matplotlib")
    figure = plot_epc_over_illuminance(HIGH_TIER)
    renderer = figure.canvas.get_renderer()
    legend = figure.legends[0].get_window_extent(renderer)
    frame = figure.axes[0].get_tightbbox(renderer)
    assert legend.y1 <= frame.y0  # below the axes, their tick labels and x label


def test_a_figure_carries_its_designs_snr_target_scene_points_and_build_under_the_legend():
    pytest.importorskip("matplotlib")
    import epc_fast
    from epc_fast import _core
    from helpers.figures import (boxes_outside, figure_text, legend_boxes, overlapping_pairs,
                                 text_boxes)

    figure = plot_epc_over_illuminance(HIGH_TIER, title="Figure 1")
    text = figure_text(figure)
    assert "Designs: " + ", ".join(d.name.replace(" um", " µm") for d in HIGH_TIER) in text
    assert "SNR target: 30 dB at corner (27.03 deg, default)" in text
    assert "Scene: illuminance 100 to 100000 lux (the x axis)" in text
    assert f"{4 * 241:,} points" in text  # 80 a decade over three decades, both ends
    assert f"epc_fast {epc_fast.__version__}, core {_core.isa}" in text
    boxes = text_boxes(figure)
    assert overlapping_pairs(boxes) == []
    assert boxes_outside(boxes, figure) == []
    assert boxes["figure text 0"].y1 < legend_boxes(figure)[0].y0


def test_a_figure_of_designs_names_each_term_that_is_on_in_its_conditions():
    # Figure 3's stabilised designs said only "the designs' own parameters".
    from dataclasses import replace

    from epc_fast.plotting.common import designs_conditions

    designs = [d for d in FIGURES if d.name == "fig3"][0].designs
    text = " ".join(designs_conditions(designs, np.array([100.0, 1e5])))
    assert ("Terms on: stabilization 1 (1/3.2\" 1.75 µm), 4 (1/3.2\" 1.75 µm 4x IS), "
            "1 (3x zoom 1.75 µm), 4 (3x zoom 1.75 µm 4x IS)") in text
    noisy = [replace(d, read_noise_e=2.0, binning_readout="charge", binning=2) for d in HIGH_TIER]
    text = " ".join(designs_conditions(noisy, np.array([100.0, 1e5])))
    assert "Terms on: read_noise_e 2; binning 2; charge binning (every design)" in text
    assert not any(line.startswith("Terms on") for line in designs_conditions(
        HIGH_TIER, np.array([100.0, 1e5])))
