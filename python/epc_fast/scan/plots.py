"""Plots of a scan's results (the ``plot`` extra): cumulative distributions per group, and
quantile bands against a binned parameter.

Names from users (designs, parameters) are shown as plain text: a ``$`` is escaped so that
matplotlib never parses them as mathtext (an unbalanced ``$\\frac`` would stop the plot), and
a leading ``_`` (which hides a legend entry) is kept visible. Each plot is written whole to a
temporary file and renamed into place.
"""

from __future__ import annotations

import numpy as np

from .histograms import HistogramResult, QuantilesResult

__all__ = ["plot_distributions", "plot_bands", "bands_parameter", "bands_parameter_of",
           "plain_text"]


def plain_text(text) -> str:
    """``text`` as matplotlib shows it literally: ``$`` escaped, a leading ``_`` spaced."""
    text = str(text).replace("$", r"\$")
    return " " + text if text.startswith("_") else text


def _save(figure, path) -> None:
    from .atomic import atomic_write

    atomic_write(path, lambda temporary: figure.savefig(temporary, dpi=120, format="png"))


def _figure():
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise ImportError("plots need matplotlib: pip install 'epc-fast[plot]'") from None
    return Figure(figsize=(7.5, 4.8), layout="constrained")


def _axis_label(of: str) -> tuple[float, str]:
    """(divisor, label) for an output's axis: EPC in megapixels, others as they are."""
    return (1e6, "EPC (Mpixel)") if of == "epc" else (1.0, of)


def _group_names(labels: dict, skip=()) -> list[str]:
    names = [k for k in labels if k not in skip]
    count = len(next(iter(labels.values()))) if labels else 1
    return [plain_text(", ".join(str(labels[k][i]) for k in names) or "all")
            for i in range(count)]


def plot_distributions(histogram: HistogramResult, path) -> None:
    """One curve per group: the fraction of its points whose output is below x (log x)."""
    figure = _figure()
    axes = figure.add_subplot()
    divisor, label = _axis_label(histogram.of)
    axes.set_xlabel(plain_text(label))
    totals = histogram.counts.sum(axis=1) + histogram.below + histogram.above
    names = _group_names(histogram.labels)
    for counts, below, total, name in zip(histogram.counts, histogram.below, totals, names):
        cumulative = np.concatenate(([below], below + np.cumsum(counts))) / max(total, 1)
        axes.step(histogram.edges / divisor, cumulative, where="post", label=name)
    axes.set_xscale("log")
    axes.set_ylabel("fraction of points below")
    axes.set_ylim(0.0, 1.0)
    axes.grid(True, alpha=0.3)
    axes.set_title(f"Distribution of {plain_text(label)} per group (cumulative)")
    axes.legend(fontsize="small")
    _save(figure, path)


def bands_parameter(quantiles: QuantilesResult) -> str | None:
    """The binned parameter of a quantiles result grouped by ``(..., Binned(parameter))``."""
    return bands_parameter_of(quantiles.labels)


def bands_parameter_of(labels) -> str | None:
    """The binned parameter among a result's group label columns, if any."""
    for name in labels:
        if name.endswith(" low") and name[:-4] + " high" in labels:
            return name[:-4]
    return None


def plot_bands(quantiles: QuantilesResult, path) -> None:
    """The middle quantile against the binned parameter (log axis, bin centres), one line per
    other group, shaded between the outermost quantiles (and the next pair in, if any)."""
    parameter = bands_parameter(quantiles)
    low = np.asarray(quantiles.labels[f"{parameter} low"], dtype=float)
    high = np.asarray(quantiles.labels[f"{parameter} high"], dtype=float)
    centres = np.sqrt(low * high)
    names = np.asarray(_group_names(quantiles.labels,
                                    skip=(f"{parameter} low", f"{parameter} high")))
    divisor, label = _axis_label(quantiles.of)
    values = quantiles.estimate / divisor
    middle = len(quantiles.q) // 2
    figure = _figure()
    axes = figure.add_subplot()
    for name in dict.fromkeys(names):
        rows = names == name
        line, = axes.plot(centres[rows], values[rows, middle], label=name)
        for outer in range(min(2, middle)):
            axes.fill_between(centres[rows], values[rows, outer], values[rows, -1 - outer],
                              color=line.get_color(), alpha=0.15, linewidth=0)
    axes.set_xscale("log")
    axes.set_xlabel(plain_text(parameter))
    axes.set_ylabel(plain_text(label))
    shown = ", ".join(f"{q:g}" for q in quantiles.q)
    axes.set_title(plain_text(f"{label} against {parameter}: quantiles {shown}"))
    axes.legend(fontsize="small")
    _save(figure, path)
