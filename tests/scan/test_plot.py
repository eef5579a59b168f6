"""The scan's figures (epc_fast.scan.plot): what a reader must find in them, read back from
the matplotlib objects: units in the labels, the threshold drawn where it is, the low cut
stated, one readable panel per group, no label on a curve."""

from __future__ import annotations

import numpy as np
import pytest

from epc_fast import scan
from epc_fast.presets import HIGH_TIER

matplotlib = pytest.importorskip("matplotlib")

from epc_fast.plotting.layout import line_points  # noqa: E402
from epc_fast.scan.plot import (bands_figure, distribution_figure, plot_bands,  # noqa: E402
                                 plot_distributions, scan_conditions, scan_pixel_counts)

THRESHOLD = 2e6
POINTS = 40_000


@pytest.fixture(scope="module")
def result():
    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 100_000),
                       shake_deg_per_s=scan.LogNormal(median=4.39, sigma=0.5))
    return scan.run(space, points=POINTS, seed=7, threads=1, reductions={
        "distribution": scan.Histogram(1e3, 1e7, 80, by="design"),
        "below": scan.FractionBelow(THRESHOLD, by="design"),
        "below_all": scan.FractionBelow(THRESHOLD),
        "bands": scan.Quantiles([0.05, 0.25, 0.5, 0.75, 0.95], by=(
            "design", scan.Binned("illuminance_lux", np.geomspace(10, 1e5, 9)))),
    })


def _fractions(result):
    return [result["below"], result["below_all"]]


def _renderer(figure):
    return figure.canvas.get_renderer()


def test_the_distribution_draws_the_threshold_at_2_mpixel_and_labels_it(result):
    figure = distribution_figure(result["distribution"], _fractions(result))
    ax = figure.axes[0]
    dashed = [line for line in ax.lines if line.get_linestyle() == "--"]
    # Two fraction_below results with the same threshold: one line.
    assert len(dashed) == 1 and list(dashed[0].get_xdata()) == [2.0, 2.0]
    labels = [t for t in ax.texts if "2 Mpixel" in t.get_text()]
    assert len(labels) == 1 and labels[0].get_text() == "threshold 2 Mpixel"
    assert ax.get_xlabel() == "EPC (Mpixel)"


def test_the_distribution_marks_each_groups_fraction_below_the_threshold(result):
    figure = distribution_figure(result["distribution"], _fractions(result))
    ax = figure.axes[0]
    dots = [line for line in ax.lines if line.get_marker() == "o"]
    # Only the per-design result has the histogram's groups: four dots, none for the total.
    assert len(dots) == len(HIGH_TIER)
    np.testing.assert_array_equal([d.get_ydata()[0] for d in dots], result["below"].fraction)
    assert all(d.get_xdata()[0] == 2.0 for d in dots)
    legend = figure.legends[0]
    for text, fraction in zip(legend.get_texts(), result["below"].fraction):
        assert f"{fraction:.1%} below 2 Mpixel" in text.get_text()


def test_the_distribution_states_where_its_axis_cuts_the_low_tail(result):
    histogram = result["distribution"]
    assert histogram.below.min() > 0  # the cut hides points: the figure must say so
    figure = distribution_figure(histogram, _fractions(result))
    ax = figure.axes[0]
    legend = figure.legends[0]
    assert "low edge, 0.001 Mpixel" in legend.get_title().get_text()
    assert ax.get_xlim()[0] == pytest.approx(1e-3)
    totals = histogram.counts.sum(axis=1) + histogram.below + histogram.above
    for text, below, total in zip(legend.get_texts(), histogram.below, totals):
        assert f"{below / total:.1%} below 0.001 Mpixel" in text.get_text()
    # Each curve starts at its share below the cut, the value the legend gives.
    curves = [line for line in ax.lines if line.get_linestyle() == "-"]
    np.testing.assert_allclose([c.get_ydata()[0] for c in curves], histogram.below / totals,
                               rtol=1e-15)


def test_the_distribution_names_designs_in_micrometres(result):
    figure = distribution_figure(result["distribution"], _fractions(result))
    texts = [t.get_text() for t in figure.legends[0].get_texts()]
    assert all("µm" in t and " um" not in t for t in texts)


def test_the_threshold_label_touches_no_curve(result):
    figure = distribution_figure(result["distribution"], _fractions(result))
    ax = figure.axes[0]
    label = next(t for t in ax.texts if "threshold" in t.get_text())
    box = label.get_window_extent(_renderer(figure))
    points = line_points([line for line in ax.lines if line.get_linestyle() == "-"])
    inside = ((points[:, 0] > box.x0) & (points[:, 0] < box.x1) & (points[:, 1] > box.y0)
              & (points[:, 1] < box.y1))
    assert not inside.any()
    assert ax.get_window_extent(_renderer(figure)).contains(box.x0, box.y0)


def test_the_bands_have_one_panel_per_design_with_two_shades_and_a_median(result):
    quantiles = result["bands"]
    figure = bands_figure(quantiles, _fractions(result))
    panels = [ax for ax in figure.axes if ax.get_visible()]
    assert [ax.get_title() for ax in panels] == [d.name.replace(" um", " µm")
                                                for d in HIGH_TIER]
    for index, ax in enumerate(panels):
        shades = [c for c in ax.collections]
        assert len(shades) == 2  # q 0.05 to 0.95 and q 0.25 to 0.75
        assert shades[0].get_alpha() < shades[1].get_alpha()  # the inner band is darker
        median = next(line for line in ax.lines if line.get_linewidth() == 2)
        rows = slice(index * 8, index * 8 + 8)  # 8 illuminance bins a design, design first
        np.testing.assert_array_equal(median.get_ydata(), quantiles.estimate[rows, 2] / 1e6)
        threshold = [line for line in ax.lines if line.get_linestyle() == "--"]
        assert len(threshold) == 1 and list(threshold[0].get_ydata()) == [2.0, 2.0]
        assert [t.get_text() for t in ax.texts] == ["2 Mpixel"]
    legend = [t.get_text() for t in figure.legends[0].get_texts()]
    assert legend == ["other groups' q 0.5 (median)", "q 0.05 to 0.95", "q 0.25 to 0.75",
                      "q 0.5 (median)"]


def test_the_bands_label_their_axes_in_words_with_units(result):
    figure = bands_figure(result["bands"], _fractions(result))
    bottom = [ax for ax in figure.axes if ax.get_xlabel()]
    assert len(bottom) == 2 and {ax.get_xlabel() for ax in bottom} == {"Illuminance (lux)"}
    assert figure.get_supylabel() == "EPC (Mpixel)"
    assert "illuminance_lux" not in figure.get_suptitle()


def test_an_odd_number_of_groups_keeps_an_x_axis_under_every_column(result):
    space = scan.Space(design=HIGH_TIER[:3], illuminance_lux=scan.LogUniform(10, 100_000))
    three = scan.run(space, points=6_000, seed=1, threads=1, reductions={
        "bands": scan.Quantiles([0.1, 0.5, 0.9], by=(
            "design", scan.Binned("illuminance_lux", np.geomspace(10, 1e5, 5))))})
    figure = bands_figure(three["bands"])
    visible = [ax for ax in figure.axes if ax.get_visible()]
    assert len(visible) == 3 and len(figure.axes) == 3  # the fourth cell holds no empty panel
    # Panel 1 (top right) has no panel below it: it carries the x label and tick labels.
    assert [bool(ax.get_xlabel()) for ax in visible] == [False, True, True]
    assert all(len(ax.collections) == 1 for ax in visible)  # one pair of quantiles around q 0.5


def test_the_plots_write_pngs(result, tmp_path):
    plot_distributions(result["distribution"], tmp_path / "d.png", _fractions(result))
    plot_bands(result["bands"], tmp_path / "b.png")
    for name in ("d.png", "b.png"):
        assert (tmp_path / name).read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_a_histogram_that_hides_no_point_says_nothing_of_a_cut():
    space = scan.Space(design=HIGH_TIER[:1], illuminance_lux=scan.LogUniform(10, 100_000))
    linear = scan.run(space, points=4_000, seed=3, threads=1, reductions={
        "distribution": scan.Histogram(0.0, 3e6, 30, log=False)})["distribution"]
    assert linear.below.sum() == 0 and linear.above.sum() == 0
    figure = distribution_figure(linear)
    ax = figure.axes[0]
    assert ax.get_xscale() == "linear" and ax.get_xlim() == (0.0, 3.0)
    assert not figure.legends[0].get_title().get_text()
    assert [t.get_text() for t in figure.legends[0].get_texts()] == ["all"]


def _conditioned_figures(result):
    bands = result["bands"]
    return {
        "distribution": distribution_figure(result["distribution"], _fractions(result),
                                            conditions=scan_conditions(result)),
        "bands": bands_figure(bands, _fractions(result),
                              conditions=scan_conditions(result, skip=("illuminance_lux",)),
                              pixel_counts=scan_pixel_counts(result.space)),
    }


def test_each_scan_figure_carries_its_designs_snr_target_scene_points_seed_and_build(result):
    import epc_fast
    from epc_fast import _core
    from helpers.figures import figure_text

    for name, figure in _conditioned_figures(result).items():
        text = figure_text(figure)
        assert "Designs: " + ", ".join(f'1/3.2" {pitch} µm'
                                       for pitch in ("2.8", "2.2", "1.75", "1.4")) in text
        assert "SNR target: 30 dB at corner (27.03 deg, default)" in text
        assert "shake_deg_per_s LogNormal(median=4.39, sigma=0.5)" in text
        assert f"{POINTS:,} points, seed 7" in text
        assert f"epc_fast {epc_fast.__version__}, core {_core.isa}" in text
    # the bands' x axis is the binned illuminance: the scene names only what is not drawn
    assert "illuminance_lux LogUniform" in figure_text(_conditioned_figures(result)[
        "distribution"])
    assert "illuminance_lux LogUniform" not in figure_text(_conditioned_figures(result)["bands"])


def test_no_text_of_a_scan_figure_overlaps_another_or_leaves_the_figure(result):
    from helpers.figures import boxes_outside, overlapping_pairs, text_boxes

    for name, figure in _conditioned_figures(result).items():
        boxes = text_boxes(figure)
        assert any(where.startswith("figure text") for where in boxes)
        assert overlapping_pairs(boxes) == [], name
        assert boxes_outside(boxes, figure) == [], name


def test_the_conditions_sit_under_the_legend_and_the_axes(result):
    from helpers.figures import legend_boxes

    for name, figure in _conditioned_figures(result).items():
        renderer = _renderer(figure)
        conditions = figure.texts[-1].get_window_extent(renderer)
        lowest = min([box.y0 for box in legend_boxes(figure)]
                     + [ax.get_tightbbox(renderer).y0 for ax in figure.axes])
        assert conditions.y1 < lowest, name


def test_the_bands_name_the_other_groups_grey_lines_in_the_legend(result):
    figure = bands_figure(result["bands"], _fractions(result))
    entries = dict(zip([t.get_text() for t in figure.legends[0].get_texts()],
                       figure.legends[0].legend_handles))
    grey = entries["other groups' q 0.5 (median)"]
    assert grey.get_color() == "0.6"
    assert sum(line.get_color() == "0.6" for line in figure.axes[0].lines) == len(HIGH_TIER) - 1


def test_the_bands_draw_each_designs_physical_pixel_count_as_a_dotted_line(result):
    counts = scan_pixel_counts(result.space)
    # area / pitch²: the 1/3.2" sensor (15.6751 mm²) in pixels of 2.8 µm
    assert counts['1/3.2" 2.8 um'] == pytest.approx(15.6751e6 / 2.8 ** 2)
    figure = _conditioned_figures(result)["bands"]
    for ax, design in zip(figure.axes, HIGH_TIER):
        dotted = [line for line in ax.lines if line.get_linestyle() == ":"]
        assert len(dotted) == 1
        assert dotted[0].get_ydata()[0] == pytest.approx(counts[design.name] / 1e6)
        assert f"{counts[design.name] / 1e6:.2f} Mpixel" in [t.get_text() for t in ax.texts]
    legend = [t.get_text() for t in figure.legends[0].get_texts()]
    assert "physical pixel count" in legend


def test_the_bands_of_an_output_other_than_epc_draw_no_pixel_count():
    space = scan.Space(design=HIGH_TIER[:2], illuminance_lux=scan.LogUniform(10, 100_000))
    f50 = scan.run(space, points=4_000, seed=2, threads=1, reductions={
        "bands": scan.Quantiles([0.1, 0.5, 0.9], of="f50_cyc_per_mm", by=(
            "design", scan.Binned("illuminance_lux", np.geomspace(10, 1e5, 5))))})
    figure = bands_figure(f50["bands"], pixel_counts=scan_pixel_counts(space))
    assert not [line for ax in figure.axes for line in ax.lines if line.get_linestyle() == ":"]


def test_log_y_draws_the_bands_output_on_a_log_axis(result):
    assert {ax.get_yscale() for ax in bands_figure(result["bands"]).axes} == {"linear"}
    figure = bands_figure(result["bands"], log_y=True)
    assert {ax.get_yscale() for ax in figure.axes} == {"log"}


def test_the_output_table_log_y_key_asks_for_log_bands_and_must_be_a_boolean():
    from epc_fast.scan.config import parse_config
    from epc_fast.jobs.errors import ConfigError

    base = ('[scan]\npoints = 100\n[design]\npresets = ["HIGH_TIER"]\n'
            '[parameters]\nilluminance_lux = 100\n')
    assert parse_config(base).log_y is False
    assert parse_config(base + "[output]\nlog_y = true\n").log_y is True
    with pytest.raises(ConfigError, match=r"output.*log_y.*'yes'.*true or false"):
        parse_config(base + "[output]\nlog_y = \"yes\"\n")


def test_the_scan_command_draws_its_bands_with_conditions_pixel_counts_and_log_y(
        tmp_path, monkeypatch, capsys):
    from epc_fast import scan as scan_package  # noqa: F401  (epc_fast.scan.plot loaded)
    from epc_fast.__main__ import main
    import epc_fast.scan.plot as plots

    drawn = {}
    original = plots.bands_figure

    def recording(*args, **kwargs):
        drawn.update(kwargs)
        figure = original(*args, **kwargs)
        drawn["figure"] = figure
        return figure

    monkeypatch.setattr(plots, "bands_figure", recording)
    config = tmp_path / "scan.toml"
    config.write_text('[scan]\npoints = 3000\nseed = 4\n[design]\npresets = ["HIGH_TIER"]\n'
                      '[parameters]\nilluminance_lux = { distribution = "log_uniform", '
                      'low = 10, high = 100_000 }\n[reductions.bands]\nkind = "quantiles"\n'
                      'q = [0.1, 0.5, 0.9]\nby = ["design", { parameter = "illuminance_lux", '
                      'log_bins = [10, 100_000, 4] }]\n[output]\nlog_y = true\n')
    assert main(["scan", str(config), "--out", str(tmp_path / "out"), "--no-progress"]) == 0
    assert (tmp_path / "out" / "bands.png").is_file()
    assert drawn["log_y"] is True
    assert set(drawn["pixel_counts"]) == {d.name for d in HIGH_TIER}
    assert "3,000 points, seed 4" in drawn["conditions"]
    assert {ax.get_yscale() for ax in drawn["figure"].axes} == {"log"}
