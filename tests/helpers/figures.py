"""What the figure tests measure: the boxes the renderer gives each label, and whether they
touch each other, a curve or a marker."""

from __future__ import annotations

import itertools

import numpy as np
from matplotlib.text import Text

from epc_fast.plotting.layout import line_points


def label_boxes(figure, ax) -> dict:
    """{text: display box} of each annotation in ``ax``: the text alone, without its leader."""
    renderer = figure.canvas.get_renderer()
    boxes = {}
    for text in ax.texts:
        if hasattr(text, "update_positions"):  # an Annotation: its text placed from its xy
            text.update_positions(renderer)
        boxes[text.get_text()] = Text.get_window_extent(text, renderer)
    return boxes


def overlapping_pairs(boxes: dict) -> list:
    """Pairs of labels whose boxes share any area."""
    return [(a, b) for (a, box_a), (b, box_b) in itertools.combinations(boxes.items(), 2)
            if box_a.x0 < box_b.x1 and box_b.x0 < box_a.x1 and box_a.y0 < box_b.y1
            and box_b.y0 < box_a.y1]


def labels_on_lines(boxes: dict, lines) -> list:
    """Labels a drawn line passes through (points along it 1 px apart)."""
    points = line_points(lines)
    return [name for name, box in boxes.items()
            if np.any((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
                      & (points[:, 1] > box.y0) & (points[:, 1] < box.y1))]


def labels_outside(boxes: dict, figure, ax) -> list:
    """Labels not wholly inside the axes."""
    frame = ax.get_window_extent(figure.canvas.get_renderer())
    return [name for name, box in boxes.items()
            if box.x0 < frame.x0 or box.x1 > frame.x1 or box.y0 < frame.y0
            or box.y1 > frame.y1]


def text_boxes(figure) -> dict:
    """{where: display box} of every text drawn on ``figure``: its title, each axes' title,
    axis labels and the tick labels inside its view, the legends' entries and the figure's own
    texts (its conditions)."""
    renderer = figure.canvas.get_renderer()
    texts = {"suptitle": figure._suptitle} if figure._suptitle is not None else {}
    for n, ax in enumerate(figure.axes):
        texts[f"axes {n} title"] = ax.title
        for axis in (ax.xaxis, ax.yaxis):
            texts[f"axes {n} {axis.axis_name} label"] = axis.label
            lo, hi = sorted(axis.get_view_interval())
            span = hi - lo
            for tick in axis.get_major_ticks():
                if lo - 1e-9 * span <= tick.get_loc() <= hi + 1e-9 * span:
                    texts[f"axes {n} {axis.axis_name} tick {tick.get_loc():g}"] = tick.label1
    for n, legend in enumerate(figure.legends):
        for text in legend.get_texts():
            texts[f"legend {n} {text.get_text()}"] = text
    titles = (figure._suptitle, figure._supxlabel, figure._supylabel)
    for n, text in enumerate(t for t in figure.texts if not any(t is s for s in titles)):
        texts[f"figure text {n}"] = text
    return {where: text.get_window_extent(renderer) for where, text in texts.items()
            if text.get_visible() and text.get_text()}


def boxes_outside(boxes: dict, figure) -> list:
    """Texts not wholly inside ``figure``."""
    frame = figure.bbox
    return [name for name, box in boxes.items()
            if box.x0 < frame.x0 or box.x1 > frame.x1 or box.y0 < frame.y0
            or box.y1 > frame.y1]


def figure_text(figure) -> str:
    """Every text drawn on ``figure`` and its axes, one a line: titles, labels, legends, the
    figure's own texts (its conditions) and the axes' annotations."""
    parts = [text.get_text() for text in figure.findobj(Text) if text.get_visible()]
    return "\n".join(part for part in parts if part)


def legend_boxes(figure) -> list:
    """The display box of each of ``figure``'s legends."""
    renderer = figure.canvas.get_renderer()
    return [legend.get_window_extent(renderer) for legend in figure.legends]
