"""Labels placed where nothing else is drawn.

Each label has a list of candidate positions, tried in order. A candidate is taken when the
label's box there, as the renderer measures the text, lies inside the axes and touches no
label placed before it, no obstacle box (markers) and no drawn line (curves, leader lines).
Labels in crowded places are placed first, while the most room is left. The figure's layout
is run once and then frozen before anything is measured, so that the positions measured are
the positions saved.

matplotlib objects are passed in; matplotlib itself is imported only inside functions.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["freeze_layout", "line_points", "marker_boxes", "place_point_labels",
           "place_line_labels", "place_vertical_line_label", "POINT_OFFSETS"]

#: pt: distances from a point to its label's near end, nearest first.
_RADII_PT = (4, 10, 18, 28, 40, 54, 70, 88, 108)
#: degrees: directions from a point to its label, in order of preference (right first).
_ANGLES_DEG = (0, 25, -25, 50, -50, 180, 155, -155, 130, -130, 75, -75, 105, -105, 90, -90)
#: pt: candidate offsets (dx, dy) of a point's label, nearest first. A label with dx >= 0
#: starts at the offset, one with dx < 0 ends there; it is centred on dy.
POINT_OFFSETS = tuple((round(r * math.cos(math.radians(a)), 1),
                       round(r * math.sin(math.radians(a)), 1))
                      for r in _RADII_PT for a in _ANGLES_DEG)
#: pt: clearance kept around every label's box.
_PAD_PT = 1.5
#: pt: a label farther than this from its point gets a leader line.
_LEADER_FROM_PT = 7.0


def renderer_of(figure):
    """``figure``'s renderer, an Agg canvas given to a figure without one."""
    if not hasattr(figure.canvas, "get_renderer"):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(figure)
    return figure.canvas.get_renderer()


def freeze_layout(figure):
    """Run ``figure``'s layout once, keep the positions it gives, and return a renderer whose
    measures are those of the saved figure. A constrained layout confined to part of the
    figure (its ``rect``: room left below for the conditions,
    :func:`epc_fast.plotting.common.add_conditions`) has its legends placed outside the axes
    moved into that part, into the margin the layout made for them."""
    renderer_of(figure)
    engine = figure.get_layout_engine()
    rect = engine.get().get("rect") if engine is not None else None
    figure.draw_without_rendering()
    figure.set_layout_engine("none")
    if rect is not None and tuple(rect) != (0, 0, 1, 1):
        for legend in figure.legends:
            if getattr(legend, "_outside_loc", None) and legend._bbox_to_anchor is None:
                legend.set_bbox_to_anchor(tuple(rect), transform=figure.transFigure)
        figure.draw_without_rendering()  # the legends' texts where they are drawn
    return figure.canvas.get_renderer()


def line_points(lines, spacing_px: float = 1.0) -> np.ndarray:
    """(n, 2) display points along each of ``lines`` (Line2D), no farther apart than
    ``spacing_px``: a line crosses a box when one of them lies in it."""
    chunks = [np.empty((0, 2))]
    for line in lines:
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=float))
        chunks.append(_densify(xy[np.all(np.isfinite(xy), axis=1)], spacing_px))
    return np.concatenate(chunks)


def _densify(xy: np.ndarray, spacing_px: float) -> np.ndarray:
    if len(xy) < 2:
        return xy
    pieces = []
    for a, b in zip(xy[:-1], xy[1:]):
        steps = max(1, int(math.ceil(np.hypot(*(b - a)) / spacing_px)))
        pieces.append(a + np.linspace(0.0, 1.0, steps + 1)[:, None] * (b - a))
    return np.concatenate(pieces)


def marker_boxes(points_px, size_pt: float, dpi: float) -> list[tuple]:
    """Display boxes (x0, y0, x1, y1) of markers ``size_pt`` wide centred on ``points_px``
    (display coordinates), at ``dpi`` pixels per inch."""
    half = size_pt * dpi / 72.0 / 2.0
    return [(x - half, y - half, x + half, y + half) for x, y in points_px]


def _overlaps(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _inside(box, bounds) -> bool:
    return (box[0] >= bounds[0] and box[1] >= bounds[1] and box[2] <= bounds[2]
            and box[3] <= bounds[3])


def _hits_points(box, points: np.ndarray) -> bool:
    if not len(points):
        return False
    x, y = points[:, 0], points[:, 1]
    return bool(np.any((x > box[0]) & (x < box[2]) & (y > box[1]) & (y < box[3])))


def _overlap_area(box, boxes) -> float:
    return sum(max(0.0, min(box[2], b[2]) - max(box[0], b[0]))
               * max(0.0, min(box[3], b[3]) - max(box[1], b[1])) for b in boxes)


def _text_sizes_px(ax, texts, fontsize, renderer) -> list[tuple]:
    """(width, height) in pixels of each of ``texts`` drawn at ``fontsize``."""
    sizes = []
    for text in texts:
        probe = ax.text(0.0, 0.0, text, fontsize=fontsize, transform=ax.transAxes)
        box = probe.get_window_extent(renderer)
        sizes.append((box.width, box.height))
        probe.remove()
    return sizes


class _Placer:
    """The free space of one axes: label boxes taken, obstacle boxes, points of lines."""

    def __init__(self, ax, renderer, obstacles=(), lines=()):
        self.px_per_pt = ax.figure.dpi / 72.0
        self.pad = _PAD_PT * self.px_per_pt
        bounds = ax.get_window_extent(renderer)
        self.bounds = (bounds.x0 + 1, bounds.y0 + 1, bounds.x1 - 1, bounds.y1 - 1)
        self.taken: list[tuple] = []
        self.obstacles = list(obstacles)
        self.points = line_points(lines)

    def padded(self, box) -> tuple:
        return (box[0] - self.pad, box[1] - self.pad, box[2] + self.pad, box[3] + self.pad)

    def free(self, box, leader=None) -> bool:
        padded = self.padded(box)
        if not _inside(box, self.bounds) or _hits_points(padded, self.points):
            return False
        if any(_overlaps(padded, b) for b in self.taken + self.obstacles):
            return False
        return leader is None or not any(_hits_points(b, leader) for b in self.taken)

    def cost(self, box) -> float:
        """How badly a box that is not free collides: the area it shares with labels and
        obstacles, and the points of lines inside it."""
        padded = self.padded(box)
        inside = 0.0 if _inside(box, self.bounds) else 1e6
        return inside + _overlap_area(padded, self.taken + self.obstacles) + 10.0 * float(
            _hits_points(padded, self.points))

    def choose(self, options, box_of, leader_of=lambda option: None):
        """The first option whose box (``box_of(option)``) and leader are free, else the one
        whose box collides least."""
        chosen = next((o for o in options if self.free(box_of(o), leader_of(o))), None)
        return chosen if chosen is not None else min(options, key=lambda o: self.cost(box_of(o)))

    def take(self, box, leader=None) -> None:
        self.taken.append(box)
        if leader is not None and len(leader):
            self.points = np.concatenate([self.points, leader])


def _leader(anchor, box, spacing_px=1.0) -> np.ndarray:
    """Display points of a straight leader from ``anchor`` to the nearest point of ``box``."""
    end = (min(max(anchor[0], box[0]), box[2]), min(max(anchor[1], box[1]), box[3]))
    return _densify(np.array([anchor, end], dtype=float), spacing_px)[1:-1]


def place_point_labels(ax, anchors, texts, *, renderer, fontsize, obstacles=(), lines=(),
                       offsets=POINT_OFFSETS, leader_color="0.55") -> list:
    """Annotate each of ``anchors`` (data coordinates) with its text, placed by
    :data:`POINT_OFFSETS`; a label away from its point gets a thin leader line.

    Parameters
    ----------
    ax : matplotlib Axes, its layout frozen (:func:`freeze_layout`).
    anchors : sequence of (x, y), data.
    texts : sequence of str.
    renderer : from :func:`freeze_layout`.
    fontsize : pt.
    obstacles : boxes (x0, y0, x1, y1), display, no label may touch (the markers).
    lines : Line2D no label may cross.
    offsets : pt, candidate offsets (dx, dy), in order of preference.

    Returns
    -------
    list of matplotlib.text.Annotation, in the order of ``texts``.
    """
    anchors_px = ax.transData.transform(np.asarray(anchors, dtype=float).reshape(-1, 2))
    sizes = _text_sizes_px(ax, texts, fontsize, renderer)
    placer = _Placer(ax, renderer, obstacles, lines)
    to_px = placer.px_per_pt

    def box_at(i, dx, dy):
        (x, y), (w, h) = anchors_px[i], sizes[i]
        x0 = x + dx * to_px if dx >= 0 else x + dx * to_px - w
        return (x0, y + dy * to_px - h / 2, x0 + w, y + dy * to_px + h / 2)

    crowding = [-int(np.count_nonzero(np.hypot(*(anchors_px - a).T) < 60 * to_px))
                for a in anchors_px]
    labels = [None] * len(texts)
    for i in sorted(range(len(texts)), key=lambda i: (crowding[i], -anchors_px[i][1])):
        options = []
        for dx, dy in offsets:
            box = box_at(i, dx, dy)
            far = math.hypot(dx, dy) > _LEADER_FROM_PT
            options.append(((dx, dy), box, _leader(anchors_px[i], box) if far else None))
        (dx, dy), box, leader = placer.choose(options, lambda o: o[1], lambda o: o[2])
        placer.take(box, leader)
        side = 0.0 if dx >= 0 else 1.0
        labels[i] = ax.annotate(
            texts[i], anchors[i], xytext=(dx, dy), textcoords="offset points",
            fontsize=fontsize, ha="left" if dx >= 0 else "right", va="center",
            arrowprops=None if leader is None else dict(
                arrowstyle="-", color=leader_color, lw=0.6, shrinkA=1, shrinkB=2,
                relpos=(side, 0.5)))
    return labels


def place_line_labels(ax, levels, texts, *, renderer, fontsize, colors, lines=(),
                      obstacles=(), x_fractions=(0.99, 0.01, 0.75, 0.5, 0.25)) -> list:
    """Label horizontal lines at ``levels`` (data y) with ``texts``, each just above or just
    below its line at the first of ``x_fractions`` (of the axes width) where nothing is.

    Returns
    -------
    list of matplotlib.text.Annotation, in the order of ``texts``.
    """
    gap_pt = 2.0
    sizes = _text_sizes_px(ax, texts, fontsize, renderer)
    placer = _Placer(ax, renderer, obstacles, lines)
    left, width = placer.bounds[0], placer.bounds[2] - placer.bounds[0]
    labels = []
    for i, text in enumerate(texts):
        y = ax.transData.transform((1.0, levels[i]))[1]
        w, h = sizes[i]
        gap = gap_pt * placer.px_per_pt
        options = []
        for fraction in x_fractions:
            x = left + fraction * width
            x0 = x - w if fraction > 0.5 else x
            for above in (True, False):
                y0 = y + gap if above else y - gap - h
                options.append((fraction, above, (x0, y0, x0 + w, y0 + h)))
        fraction, above, box = placer.choose(options, lambda o: o[2])
        placer.take(box)
        labels.append(ax.annotate(
            text, (fraction, levels[i]), xycoords=("axes fraction", "data"),
            xytext=(0.0, gap_pt if above else -gap_pt), textcoords="offset points",
            fontsize=fontsize, color=colors[i], ha="right" if fraction > 0.5 else "left",
            va="bottom" if above else "top"))
    return labels


def place_vertical_line_label(ax, x, text, *, renderer, fontsize, color, lines=(),
                              obstacles=(), y_fractions=(0.02, 0.98, 0.5, 0.25, 0.75)):
    """Label a vertical line at ``x`` (data) with ``text``, written upwards just right or
    just left of the line at the first of ``y_fractions`` (of the axes height) where nothing
    is.

    Returns
    -------
    matplotlib.text.Annotation
    """
    gap_pt = 2.0
    w, h = _text_sizes_px(ax, [text], fontsize, renderer)[0]
    placer = _Placer(ax, renderer, obstacles, lines)
    gap = gap_pt * placer.px_per_pt
    line_x = ax.transData.transform((x, 1.0))[0]
    bottom, height = placer.bounds[1], placer.bounds[3] - placer.bounds[1]
    options = []
    for fraction in y_fractions:
        y = bottom + fraction * height
        y0 = y - w if fraction > 0.5 else (y - w / 2 if fraction == 0.5 else y)
        for right in (True, False):
            x0 = line_x + gap if right else line_x - gap - h
            options.append((fraction, right, (x0, y0, x0 + h, y0 + w)))
    fraction, right, _ = placer.choose(options, lambda o: o[2])
    va = "top" if fraction > 0.5 else ("center" if fraction == 0.5 else "bottom")
    return ax.annotate(text, (x, fraction), xycoords=("data", "axes fraction"),
                       xytext=(gap_pt if right else -gap_pt, 0.0), textcoords="offset points",
                       rotation=90, rotation_mode="default", fontsize=fontsize, color=color,
                       ha="left" if right else "right", va=va)
