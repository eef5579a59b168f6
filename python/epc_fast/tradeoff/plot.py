"""The speed/accuracy plot of ``epc-fast bench`` (trade.png): each setting a labelled point,
the Pareto front a line. Needs matplotlib (the ``plot`` extra), imported inside the function.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..plotting.common import add_conditions, conditions_lines, figure_class
from ..plotting.layout import freeze_layout, marker_boxes, place_point_labels
from .measurements import THREADS, Measurement

__all__ = ["plot_tradeoff", "ZERO_ERROR_FLOOR", "LABEL_FONTSIZE"]

#: 1, where a relative error of exactly 0 is drawn on the plot's log axis.
ZERO_ERROR_FLOOR = 1e-17
#: pt, the size of the settings' labels.
LABEL_FONTSIZE = 7.5
#: pt, the size of the markers.
MARKER_SIZE = 6.0
#: decades of room added left and right of the points, and below and above them, for labels.
X_ROOM_DECADES = (0.35, 0.9)
Y_ROOM_DECADES = (0.12, 0.1)


def plot_tradeoff(measurements: Sequence[Measurement], front: Sequence[int], *, title="",
                  threads: int = THREADS[-1], conditions=None):
    """Points/s on ``threads`` threads (y, log) against max relative error of f50 (x, log),
    each setting a labelled point, the Pareto front ``front`` (indices, by error) a line.

    Polychromatic settings are squares. Errors of exactly 0 are drawn at
    :data:`ZERO_ERROR_FLOOR`, as hollow markers. Each label sits where it touches no other
    label, marker or the front (:func:`epc_fast.plotting.layout.place_point_labels`), joined to
    its point by a thin line when it had to move away; the legend is below the axes. The
    figure's layout is fixed when it is returned. Needs matplotlib (ImportError otherwise).
    ``conditions`` (lines) are written under the legend, by default the settings drawn, the
    version and the build (:func:`epc_fast.plotting.common.conditions_lines`).

    Returns
    -------
    matplotlib.figure.Figure
    """

    figure = figure_class("the trade-off plot")(figsize=(8.5, 6.4), layout="constrained")
    ax = figure.subplots()
    shown = [i for i, m in enumerate(measurements) if not math.isnan(m.accuracy.max_rel_error)]
    x = {i: max(measurements[i].accuracy.max_rel_error, ZERO_ERROR_FLOOR) for i in shown}
    y = {i: measurements[i].points_per_s[threads] / 1e6 for i in shown}
    for group, marker, color, label in (
            (False, "o", "C0", "monochromatic"),
            (True, "s", "C2", "polychromatic (against the reference with its spectrum)")):
        members = [i for i in shown
                   if (measurements[i].setting.spectrum_samples is not None) == group]
        zero = [i for i in members if measurements[i].accuracy.max_rel_error == 0]
        nonzero = [i for i in members if i not in zero]
        if nonzero:
            ax.plot([x[i] for i in nonzero], [y[i] for i in nonzero], marker, color=color,
                    ms=MARKER_SIZE, label=label)
        if zero:
            ax.plot([x[i] for i in zero], [y[i] for i in zero], marker, mfc="none",
                    color=color, ms=MARKER_SIZE, label=f"{label}, error exactly 0 (drawn at "
                    f"{ZERO_ERROR_FLOOR:g})")
    line = [i for i in front if i in x]
    front_line, = ax.plot([x[i] for i in line], [y[i] for i in line], "-", color="C3", lw=1.5,
                          zorder=0, label="Pareto front (monochromatic)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    if shown:
        _make_room(ax, [x[i] for i in shown], [y[i] for i in shown])
    else:  # nothing measured: empty axes over a typical range, not a log axis without data
        ax.set_xlim(1e-16, 1e-6)
        ax.set_ylim(1.0, 100.0)
    _plain_numbers(ax.yaxis)
    ax.set_xlabel("Max relative error of f50 against the NumPy reference")
    ax.set_ylabel(f"Throughput (M points/s, {threads} thread{'s' if threads > 1 else ''})")
    ax.set_title(title or "epc_fast: speed against accuracy", fontsize=10)
    ax.grid(which="major", alpha=0.4)
    ax.grid(which="minor", alpha=0.15)
    figure.legend(loc="outside lower center", ncols=2, fontsize=8, frameon=False)
    add_conditions(figure, conditions_lines(extra=[f"{len(shown)} settings drawn"])
                   if conditions is None else conditions)
    renderer = freeze_layout(figure)
    anchors = [(x[i], y[i]) for i in shown]
    place_point_labels(ax, anchors, [measurements[i].setting.name for i in shown],
                       renderer=renderer, fontsize=LABEL_FONTSIZE,
                       obstacles=marker_boxes(ax.transData.transform(anchors), MARKER_SIZE + 1,
                                              figure.dpi) if anchors else (),
                       lines=[front_line])
    return figure


def _make_room(ax, xs, ys) -> None:
    """Log limits around the points with room for their labels on either side."""
    x_lo, x_hi = math.log10(min(xs)), math.log10(max(xs))
    y_lo, y_hi = math.log10(min(ys)), math.log10(max(ys))
    ax.set_xlim(10 ** (x_lo - X_ROOM_DECADES[0]), 10 ** (x_hi + X_ROOM_DECADES[1]))
    ax.set_ylim(10 ** (y_lo - Y_ROOM_DECADES[0]), 10 ** (y_hi + Y_ROOM_DECADES[1]))


def _plain_numbers(axis) -> None:
    """Ticks of a log axis at 1, 2 and 5 times powers of ten, written as plain numbers."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())
