"""The plot of speed against accuracy: zero errors at the floor, every setting labelled once
where no label touches another, a marker or the front, the legend below the axes."""

import pytest

from epc_fast.tradeoff import ZERO_ERROR_FLOOR, front_of
from helpers.tradeoff import measurement


def test_plot_draws_zero_errors_at_the_floor():
    pytest.importorskip("matplotlib")
    from epc_fast.tradeoff import plot_tradeoff

    rows = [measurement("default", 0.0, 2e6), measurement("fast", 1e-7, 4e6)]
    figure = plot_tradeoff(rows, front_of(rows))
    ax = figure.axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert any("exactly 0" in label for label in labels)
    zero = next(line for line in ax.get_lines() if "exactly 0" in line.get_label())
    assert list(zero.get_xdata()) == [ZERO_ERROR_FLOOR]
    front = next(line for line in ax.get_lines() if line.get_label().startswith("Pareto"))
    assert list(front.get_xdata()) == [ZERO_ERROR_FLOOR, 1e-7]


#: (name, max relative error, M points/s on 2 threads, spectrum samples) of a full run: the
#: settings crowd at 1e-14 and at 1e-7, where labels collide unless they are placed.
CROWDED_RUN = [
    ("default", 8.3e-15, 51.3, None), ("halley rtol=1e-14", 8.3e-15, 57.1, None),
    ("halley rtol=1e-10", 8.3e-15, 56.4, None), ("halley rtol=1e-6", 4.2e-08, 74.8, None),
    ("newton rtol=1e-14", 8.4e-15, 43.0, None), ("newton rtol=1e-10", 8.6e-15, 49.3, None),
    ("newton rtol=1e-6", 4.2e-08, 75.4, None), ("bisection rtol=1e-14", 6.9e-15, 6.32, None),
    ("bisection rtol=1e-10", 5.0e-11, 8.39, None), ("bisection rtol=1e-6", 4.9e-07, 12.4, None),
    ("brent rtol=1e-14", 8.4e-15, 6.26, None), ("brent rtol=1e-10", 2.5e-11, 8.2, None),
    ("brent rtol=1e-6", 2.5e-07, 9.45, None), ("T_MPE brent", 3.9e-13, 5.98, None),
    ("float32", 9.9e-08, 76.7, None), ("float32 rtol=1e-6", 9.9e-08, 82.0, None),
    ("poly 1", 8.3e-15, 55.7, 1), ("poly 4", 8.6e-15, 38.2, 4), ("poly 16", 8.8e-15, 20.5, 16),
    ("poly 64", 8.6e-15, 7.73, 64),
]


def crowded_plot():
    from epc_fast.tradeoff import plot_tradeoff

    rows = [measurement(name, error, speed * 1e6, samples)
            for name, error, speed, samples in CROWDED_RUN]
    return plot_tradeoff(rows, front_of(rows))


def test_plot_labels_each_setting_once_and_no_label_touches_another():
    pytest.importorskip("matplotlib")
    from helpers.figures import label_boxes, labels_outside, overlapping_pairs

    figure = crowded_plot()
    ax = figure.axes[0]
    boxes = label_boxes(figure, ax)
    assert sorted(boxes) == sorted(name for name, *_ in CROWDED_RUN)
    assert overlapping_pairs(boxes) == []
    assert labels_outside(boxes, figure, ax) == []


def test_plot_labels_cover_no_marker_and_not_the_front():
    pytest.importorskip("matplotlib")
    from helpers.figures import label_boxes, labels_on_lines

    figure = crowded_plot()
    ax = figure.axes[0]
    boxes = label_boxes(figure, ax)
    front = next(line for line in ax.get_lines() if line.get_label().startswith("Pareto"))
    assert labels_on_lines(boxes, [front]) == []
    centres = ax.transData.transform([(error, speed) for _, error, speed, _ in CROWDED_RUN])
    for name, box in boxes.items():
        covered = [(x, y) for x, y in centres
                   if box.x0 < x < box.x1 and box.y0 < y < box.y1]
        assert covered == [], name


def test_plot_legend_sits_below_the_axes_and_ticks_are_plain_numbers():
    pytest.importorskip("matplotlib")
    figure = crowded_plot()
    renderer = figure.canvas.get_renderer()
    ax = figure.axes[0]
    assert figure.legends[0].get_window_extent(renderer).y1 <= ax.get_tightbbox(renderer).y0
    figure.canvas.draw()
    ticks = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
    assert ticks and all("times" not in t and "^" not in t for t in ticks)
    assert ax.get_ylabel() == "Throughput (M points/s, 2 threads)"


def test_the_plot_carries_its_conditions_under_the_legend_clear_of_every_text():
    pytest.importorskip("matplotlib")
    import epc_fast
    from epc_fast import _core
    from epc_fast.plotting.common import conditions_lines
    from epc_fast.tradeoff import plot_tradeoff
    from helpers.figures import (boxes_outside, figure_text, legend_boxes, overlapping_pairs,
                                 text_boxes)

    rows = [measurement(name, error, speed * 1e6, samples)
            for name, error, speed, samples in CROWDED_RUN]
    default = figure_text(plot_tradeoff(rows, front_of(rows)))
    assert f"{len(rows)} settings drawn" in default
    assert f"epc_fast {epc_fast.__version__}, core {_core.isa}" in default
    figure = plot_tradeoff(rows, front_of(rows), conditions=conditions_lines(
        scene="random designs: f50 error on 2,000, speed on 100,000", seed=11))
    text = figure_text(figure)
    assert "Scene: random designs: f50 error on 2,000, speed on 100,000" in text
    assert "seed 11" in text
    boxes = text_boxes(figure)
    assert overlapping_pairs(boxes) == []
    assert not boxes_outside({"conditions": boxes["figure text 0"]}, figure)
    assert boxes["figure text 0"].y1 < legend_boxes(figure)[0].y0
