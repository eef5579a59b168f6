"""Plots of EPC over illuminance. matplotlib (the ``plot`` extra) is imported inside functions.

Figures are built on :class:`matplotlib.figure.Figure` directly, not through pyplot: no global
state, no GUI backend, safe in threads and on headless machines.
"""

from __future__ import annotations

import numpy as np

from .presets import READINGS, evaluate_over_illuminance

__all__ = ["plot_epc_over_illuminance", "save_figure"]

#: Curves per decade of illuminance: smooth at any zoom the paper's figures need.
POINTS_PER_DECADE = 80


def _figure_class():
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise ImportError("plotting needs matplotlib: install the plot extra, "
                          "pip install 'epc-fast[plot]'") from exc
    return Figure


def plot_epc_over_illuminance(designs, *, title="", lux_range=(100.0, 100000.0), backend="core",
                              threads=None):
    """A figure of EPC against illuminance, one curve per design.

    The x axis is illuminance in lux on a log scale, the y axis EPC in megapixels; each design's
    physical pixel count is marked by a dotted line in its curve's colour.

    Parameters
    ----------
    designs : sequence of presets.Design
        All with the same reading (:data:`epc_fast.presets.READINGS`), named in the subtitle.
    title : str
    lux_range : (float, float)
        lux, the x axis.
    backend, threads
        Passed to :func:`epc_fast.evaluate`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    readings = {d.reading for d in designs}
    if len(readings) != 1:
        raise ValueError(f"the designs of one figure share one reading, got {sorted(readings)}")
    figure = _figure_class()(figsize=(7.0, 4.8), layout="constrained")
    ax = figure.subplots()
    lo, hi = np.log10(lux_range[0]), np.log10(lux_range[1])
    lux = np.logspace(lo, hi, int(round((hi - lo) * POINTS_PER_DECADE)) + 1)
    result = evaluate_over_illuminance(designs, lux, backend=backend, threads=threads)
    for index, (design, epc) in enumerate(zip(designs, result.epc)):
        ax.plot(lux, epc / 1e6, color=f"C{index}", lw=2, label=design.name)
    _mark_pixel_counts(ax, designs)
    ax.set_xscale("log")
    ax.set_xlim(*lux_range)
    ax.set_ylim(0.0, 1.08 * max(d.pixel_count for d in designs) / 1e6)
    ax.set_xlabel("illuminance (lux)")
    ax.set_ylabel("effective pixel count (Mpixel)")
    ax.set_title(f"{title}\n{READINGS[readings.pop()].meaning}", fontsize=10)
    ax.grid(which="major", alpha=0.4)
    ax.grid(which="minor", alpha=0.15)
    ax.legend(loc="upper left", fontsize=9)
    return figure


def _mark_pixel_counts(ax, designs) -> None:
    """A dotted line and a label at each physical pixel count: in the colour of its design's
    curve, or grey where several designs share it."""
    counts = [d.pixel_count for d in designs]
    for index, count in enumerate(counts):
        if counts.index(count) != index:
            continue
        color = f"C{index}" if counts.count(count) == 1 else "0.4"
        ax.axhline(count / 1e6, color=color, ls=":", lw=1.2)
        ax.annotate(f"{count / 1e6:.2f} Mpixel", (1.0, count / 1e6), xycoords=("axes fraction",
                    "data"), xytext=(-4, 2), textcoords="offset points", ha="right",
                    va="bottom", color=color, fontsize=8)
    ax.plot([], [], color="0.4", ls=":", lw=1.2, label="physical pixel count")


def save_figure(figure, path, dpi=110) -> None:
    """Write ``figure`` to ``path`` (the format from its suffix, e.g. PNG)."""
    figure.savefig(path, dpi=dpi)
