"""Plots of a scan's results (the ``plot`` extra): cumulative distributions per group, and
quantile bands against a binned parameter, one panel per group.

Axis labels come from the output's and the parameter's names, with units
(:func:`epc_fast.plotting.text.quantity_label`). A threshold of a ``fraction_below`` reduction of
the same output is drawn and labelled on both plots, and the distribution marks each group's
fraction below it. The distribution's axis starts at the histogram's low edge; the figure says
so and gives each group's share of points below it.

Names from users (designs, parameters) are shown as plain text: a ``$`` is escaped so that
matplotlib never parses them as mathtext (an unbalanced ``$\\frac`` would stop the plot), and
a leading ``_`` (which hides a legend entry) is kept visible. Each plot is written whole to a
temporary file and renamed into place.
"""

from __future__ import annotations

import math

import numpy as np

from ..plotting.common import (add_conditions, conditions_lines, figure_class,
                               physical_pixel_count, save_figure, space_conditions)
from ..plotting.layout import freeze_layout, place_line_labels, place_vertical_line_label
from ..plotting.text import output_scale, quantity_label, quantity_unit, unit_text
from .reductions.histograms import HistogramResult, QuantilesResult

__all__ = ["plot_distributions", "plot_bands", "distribution_figure", "bands_figure",
           "bands_parameter", "bands_parameter_of", "plain_text", "scan_conditions",
           "scan_pixel_counts"]

#: The colour of threshold lines and their labels.
THRESHOLD_COLOR = "0.15"


def plain_text(text) -> str:
    """``text`` as matplotlib shows it literally, units as a reader writes them (``µm``):
    ``$`` escaped, a leading ``_`` spaced."""
    text = unit_text(text).replace("$", r"\$")
    return " " + text if text.startswith("_") else text


def _save(figure, path) -> None:
    save_figure(figure, path, dpi=120, file_format="png")  # path may be a temporary name


def _figure(size=(7.5, 5.4)):
    return figure_class("the scan's plots", without="--no-plots on the command line")(
        figsize=size, layout="constrained")


def _group_names(labels: dict, skip=()) -> list[str]:
    """Each group's name: its design, and "name value" for every other label column."""
    names = [k for k in labels if k not in skip]
    count = len(next(iter(labels.values()))) if labels else 1
    return [plain_text(", ".join(str(labels[k][i]) if k == "design"
                                 else f"{quantity_label(k)} {labels[k][i]}" for k in names)
                       or "all")
            for i in range(count)]


def _value_text(value: float, of: str) -> str:
    """A value of output ``of`` as drawn, with its unit: ``2e6`` EPC -> ``"2 Mpixel"``."""
    unit = quantity_unit(of)
    return f"{value / output_scale(of):g}" + (f" {unit}" if unit else "")


def _thresholds(fractions_below, of: str) -> list[float]:
    """The distinct thresholds of the fraction_below results of output ``of``."""
    return sorted({float(r.threshold) for r in fractions_below if r.of == of})


def _in_sentence(label: str) -> str:
    """A label as it reads mid-sentence: "Illuminance (lux)" -> "illuminance (lux)", an
    acronym kept ("EPC")."""
    return label[:1].lower() + label[1:] if label[1:2].islower() else label


def _same_groups(a: dict, b: dict) -> bool:
    """Whether two results' group labels are the same columns with the same values."""
    return list(a) == list(b) and all(list(a[k]) == list(b[k]) for k in a)


def _share(count: int, total: int) -> str:
    share = count / total if total else math.nan
    return "0%" if count == 0 else (f"{share:.2%}" if share < 0.001 else f"{share:.1%}")


def scan_conditions(result, skip=()) -> list[str]:
    """The conditions a scan's figure carries (:func:`epc_fast.plotting.common.add_conditions`)
    of ``result`` (ScanResult): its designs, where each meets its SNR target, the other
    parameters (``skip`` left out), the points reduced and the seed."""
    return space_conditions(result.space, points=result.points, seed=result.seed, skip=skip)


def plot_distributions(histogram: HistogramResult, path, fractions_below=(), partial="", *,
                       conditions=()) -> None:
    """Write :func:`distribution_figure` to ``path`` (PNG)."""
    _save(distribution_figure(histogram, fractions_below, partial, conditions=conditions), path)


def distribution_figure(histogram: HistogramResult, fractions_below=(), partial="", *,
                        conditions=()):
    """One curve per group: the fraction of its finite points whose output is below x (log x).

    The x axis spans the histogram's bins: each curve starts at its group's share of points
    below the low edge, which the legend gives and a note under the axes explains. Each
    threshold of ``fractions_below`` (FractionBelowResult, those of the same output) is a
    labelled vertical line; where such a result has the histogram's groups, each group's
    fraction below the threshold is a dot on the line and a number in the legend. The
    ``conditions`` (lines, :func:`scan_conditions`) are written under the legend, with the
    version and build.

    Returns
    -------
    matplotlib.figure.Figure, its layout fixed.
    """
    divisor, of = output_scale(histogram.of), histogram.of
    figure = _figure()
    axes = figure.add_subplot()
    totals = histogram.counts.sum(axis=1) + histogram.below + histogram.above
    names = _group_names(histogram.labels)
    same_groups = [r for r in fractions_below
                   if r.of == of and _same_groups(r.labels, histogram.labels)]
    cut = bool(histogram.below.any())  # points left of the axis: the figure says how many
    curves = []
    for g, (counts, below, total, name) in enumerate(zip(histogram.counts, histogram.below,
                                                          totals, names)):
        cumulative = np.concatenate(([below], below + np.cumsum(counts))) / max(total, 1)
        parts = [f"{_share(below, total)} below {_value_text(histogram.edges[0], of)}"] \
            if cut else []
        parts += [f"{r.fraction[g]:.1%} below {_value_text(r.threshold, of)}"
                  for r in same_groups]
        label = f"{name}: {', '.join(parts)}" if parts else name
        curve, = axes.step(histogram.edges / divisor, cumulative, where="post", label=label,
                           color=f"C{g % 10}")
        curves.append(curve)
        for r in same_groups:
            axes.plot([r.threshold / divisor], [r.fraction[g]], "o", ms=6, mfc=curve.get_color(),
                      mec="white", mew=1.0, zorder=5)
    thresholds = _thresholds(fractions_below, of)
    for threshold in thresholds:
        axes.axvline(threshold / divisor, color=THRESHOLD_COLOR, ls="--", lw=1.2)
    if histogram.edges[0] > 0:  # bins from a positive edge are drawn on a log axis
        axes.set_xscale("log")
    axes.set_xlim(histogram.edges[0] / divisor, histogram.edges[-1] / divisor)
    axes.set_xlabel(quantity_label(of))
    axes.set_ylabel("Fraction of points below x")
    axes.set_ylim(0.0, 1.02)
    axes.grid(True, alpha=0.3)
    axes.set_title(f"Cumulative distribution of {quantity_label(of)} per group"
                   + _partial_line(partial))
    notes = []
    if cut:
        notes.append(f"The x axis starts at the histogram's low edge, "
                     f"{_value_text(histogram.edges[0], of)}:\neach curve starts at its "
                     f"group's share of points below it.")
    if histogram.above.any():
        notes.append(f"Points at or above {_value_text(histogram.edges[-1], of)} lie right "
                     f"of the axis.")
    if histogram.nonfinite.any():
        notes.append("Points whose value is not finite are not counted.")
    figure.legend(loc="outside lower center", ncols=1, fontsize="small", frameon=False,
                  title="\n".join(notes) or None, title_fontsize="small")
    add_conditions(figure, conditions or conditions_lines())
    renderer = freeze_layout(figure)
    for threshold in thresholds:
        place_vertical_line_label(axes, threshold / divisor,
                                  f"threshold {_value_text(threshold, of)}",
                                  renderer=renderer, fontsize=9, color=THRESHOLD_COLOR,
                                  lines=curves)
    return figure


def bands_parameter(quantiles: QuantilesResult) -> str | None:
    """The binned parameter of a quantiles result grouped by ``(..., Binned(parameter))``."""
    return bands_parameter_of(quantiles.labels)


def bands_parameter_of(labels) -> str | None:
    """The binned parameter among a result's group label columns, if any."""
    for name in labels:
        if name.endswith(" low") and name[:-4] + " high" in labels:
            return name[:-4]
    return None


def plot_bands(quantiles: QuantilesResult, path, fractions_below=(), partial="", *,
               conditions=(), pixel_counts=None, log_y=False) -> None:
    """Write :func:`bands_figure` to ``path`` (PNG)."""
    _save(bands_figure(quantiles, fractions_below, partial, conditions=conditions,
                       pixel_counts=pixel_counts, log_y=log_y), path)


def scan_pixel_counts(space) -> dict:
    """{design name: physical pixel count} of ``space``'s designs whose sensor area and pixel
    pitch are their own (not a scanned parameter): area / pitch²
    (:func:`epc_fast.plotting.common.physical_pixel_count`, as the paper's figures)."""
    table = space.design_table
    if not space.design_names or any(name in space.axes or name not in table
                                     for name in ("sensor_area_mm2", "pixel_pitch_um")):
        return {}
    counts = physical_pixel_count(table["sensor_area_mm2"], table["pixel_pitch_um"])
    return {name: float(count) for name, count in zip(space.design_names, counts)
            if np.isfinite(count)}


def _partial_line(partial: str) -> str:
    """A figure title's second line saying its results are partial (``partial``: what
    :func:`epc_fast.scan.tables.partial_note` says), or nothing."""
    return f"\n{plain_text(partial)}" if partial else ""


def bands_figure(quantiles: QuantilesResult, fractions_below=(), partial="", *, conditions=(),
                 pixel_counts=None, log_y=False):
    """The quantiles against the binned parameter (log axis, bin centres), one panel per other
    group: the middle quantile a line, shaded between the outermost quantiles and, lighter
    outside darker, the next pair in; the other groups' middle quantiles thin and grey for
    comparison, a legend entry saying so. Each threshold of ``fractions_below``
    (FractionBelowResult, those of the same output) is a labelled horizontal line in every
    panel. Panels beyond the groups are removed.

    Parameters
    ----------
    conditions : sequence of str, lines written under the legend (:func:`scan_conditions`),
        with the version and build.
    pixel_counts : {design name: pixels}, optional (:func:`scan_pixel_counts`): where the
        output is EPC, each panel's design has a dotted line at its physical pixel count.
    log_y : bool, a log output axis (EPC spans decades over illuminance) when a quantile is
        positive; a linear one when none is (a scan stopped before its first point).

    Returns
    -------
    matplotlib.figure.Figure, its layout fixed.
    """
    parameter = bands_parameter(quantiles)
    of = quantiles.of
    low = np.asarray(quantiles.labels[f"{parameter} low"], dtype=float)
    high = np.asarray(quantiles.labels[f"{parameter} high"], dtype=float)
    centres = np.sqrt(low * high)
    names = np.asarray(_group_names(quantiles.labels,
                                    skip=(f"{parameter} low", f"{parameter} high")))
    values = quantiles.estimate / output_scale(of)
    q = list(quantiles.q)
    middle = len(q) // 2
    groups = list(dict.fromkeys(names))
    columns = 1 if len(groups) == 1 else (2 if len(groups) <= 6 else 3)
    rows = math.ceil(len(groups) / columns)
    size = (7.5, 5.0) if len(groups) == 1 else (4.0 * columns + 0.6, 2.5 * rows + 1.6)
    figure = _figure(size)
    panels = figure.subplots(rows, columns, sharex=True, sharey=True, squeeze=False).ravel()
    thresholds = _thresholds(fractions_below, of)
    designs = list(quantiles.labels.get("design", ()))
    counts = pixel_counts if of == "epc" and pixel_counts else {}
    drawn = bool(np.any(values > 0))  # none at 0 points: nothing sets the axes' limits
    count_levels = {}
    for index, (axes, group) in enumerate(zip(panels, groups)):
        color = f"C{index % 10}"
        others = [other for other in groups if other != group]
        for k, other in enumerate(others):
            rows_of = names == other
            axes.plot(centres[rows_of], values[rows_of, middle], color="0.6", lw=0.8,
                      label=f"other groups' q {q[middle]:g}"
                      + (" (median)" if q[middle] == 0.5 else "")
                      if index == 0 and k == 0 else None)
        rows_of = names == group
        design = designs[int(np.flatnonzero(rows_of)[0])] if designs else None
        if design in counts:
            level = counts[design] / output_scale(of)
            axes.axhline(level, color=color, ls=":", lw=1.2,
                         label="physical pixel count" if not count_levels else None)
            count_levels[index] = level
        for outer in range(min(2, middle)):
            axes.fill_between(centres[rows_of], values[rows_of, outer],
                              values[rows_of, -1 - outer], color=color, linewidth=0,
                              alpha=0.18 + 0.17 * outer,
                              label=f"q {q[outer]:g} to {q[-1 - outer]:g}" if index == 0
                              else None)
        axes.plot(centres[rows_of], values[rows_of, middle], color=color, lw=2,
                  label=f"q {q[middle]:g}" + (" (median)" if q[middle] == 0.5 else "")
                  if index == 0 else None)
        for threshold in thresholds:
            axes.axhline(threshold / output_scale(of), color=THRESHOLD_COLOR, ls="--", lw=1.0)
        axes.set_title(group, fontsize=9)
        axes.set_xscale("log")
        if not drawn:  # no value to set the limits: the bins' range
            axes.set_xlim(float(np.min(low)), float(np.max(high)))
        elif log_y:
            axes.set_yscale("log")
        axes.grid(True, alpha=0.3)
        if index + columns >= len(groups):  # no panel below: this one carries the x axis
            axes.set_xlabel(quantity_label(parameter))
            axes.xaxis.set_tick_params(labelbottom=True)
    for axes in panels[len(groups):]:
        axes.remove()
    figure.supylabel(quantity_label(of), fontsize=10)
    figure.suptitle(f"{quantity_label(of)} against {_in_sentence(quantity_label(parameter))}: "
                    f"quantiles per bin" + (", one panel per group" if len(groups) > 1 else "")
                    + _partial_line(partial), fontsize=11)
    figure.legend(loc="outside lower center", ncols=3, fontsize="small", frameon=False)
    add_conditions(figure, conditions or conditions_lines())
    renderer = freeze_layout(figure)
    for index, axes in enumerate(panels[:len(groups)]):
        levels = [t / output_scale(of) for t in thresholds]
        texts = [_value_text(t, of) for t in thresholds]
        colors = [THRESHOLD_COLOR] * len(levels)
        if index in count_levels:
            levels.append(count_levels[index])
            texts.append(f"{count_levels[index]:.2f} Mpixel")
            colors.append(f"C{index % 10}")
        place_line_labels(axes, levels, texts, renderer=renderer, fontsize=8, colors=colors,
                          lines=[line for line in axes.lines if line.get_linestyle() == "-"])
    return figure
