"""Plots of EPC over illuminance (:mod:`epc_fast.plotting.common`: matplotlib imported inside
functions)."""

from __future__ import annotations

from .common import (add_conditions, designs_conditions, figure_class, illuminance_lux,
                     shared_reading)
from .layout import freeze_layout, place_line_labels
from .text import quantity_label, unit_text
from ..presets import READINGS, evaluate_over_illuminance

__all__ = ["plot_epc_over_illuminance"]

def plot_epc_over_illuminance(designs, *, title="", lux_range=(100.0, 100000.0), backend="core",
                              threads=None, conditions=None):
    """A figure of EPC against illuminance, one curve per design.

    The x axis is illuminance in lux on a log scale, the y axis EPC in megapixels; each design's
    physical pixel count (its sensor's area over its pitch squared) is marked by a dotted line
    in its curve's colour, labelled where no curve passes
    (:func:`epc_fast.plotting.layout.place_line_labels`). The legend sits below the axes, clear
    of the curves. The figure's layout is fixed when it is returned: add nothing that needs
    room.

    Parameters
    ----------
    designs : sequence of presets.Design
        All with the same reading (:data:`epc_fast.presets.READINGS`), named in the subtitle.
    title : str
    lux_range : (float, float)
        lux, the x axis.
    backend, threads
        Passed to :func:`epc_fast.evaluate`.
    conditions : sequence of str, optional
        The lines written under the legend; by default the designs, their SNR targets, the
        scene, the points, the version and the build
        (:func:`epc_fast.plotting.common.designs_conditions`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    reading = shared_reading(designs)
    figure = figure_class()(figsize=(7.0, 5.2), layout="constrained")
    ax = figure.subplots()
    lux = illuminance_lux(lux_range)
    result = evaluate_over_illuminance(designs, lux, backend=backend, threads=threads)
    curves = [ax.plot(lux, epc / 1e6, color=f"C{index}", lw=2, label=unit_text(design.name))[0]
              for index, (design, epc) in enumerate(zip(designs, result.epc))]
    levels, colors = _pixel_count_lines(ax, designs)
    ax.set_xscale("log")
    ax.set_xlim(*lux_range)
    ax.set_ylim(0.0, 1.08 * max(_pixel_count(d) for d in designs) / 1e6)
    ax.set_xlabel(quantity_label("illuminance_lux"))
    ax.set_ylabel("Effective pixel count, EPC (Mpixel)")
    ax.set_title(unit_text(f"{title}\n{READINGS[reading].meaning}"), fontsize=10)
    ax.grid(which="major", alpha=0.4)
    ax.grid(which="minor", alpha=0.15)
    figure.legend(loc="outside lower center", ncols=3, fontsize=9, frameon=False)
    add_conditions(figure, designs_conditions(designs, lux) if conditions is None
                   else conditions)
    renderer = freeze_layout(figure)
    place_line_labels(ax, levels, [f"{level:.2f} Mpixel" for level in levels],
                      renderer=renderer, fontsize=8, colors=colors, lines=curves)
    return figure


def _pixel_count(design) -> float:
    """pixels: ``design``'s physical pixel count, its sensor's area over its pitch squared
    (:attr:`epc_fast.presets.Design.pixel_count`, :func:`epc_fast.sensor.physical_pixel_count`,
    as a scan's plots)."""
    return design.pixel_count


def _pixel_count_lines(ax, designs) -> tuple[list, list]:
    """A dotted line at each physical pixel count, in the colour of its design's curve, or
    grey where several designs share it; a legend entry says what the dotted lines are.

    Returns
    -------
    levels : list of float, Mpixel, one per distinct count.
    colors : list, the colour of each line.
    """
    counts = [_pixel_count(d) for d in designs]
    levels, colors = [], []
    for index, count in enumerate(counts):
        if counts.index(count) != index:
            continue
        color = f"C{index}" if counts.count(count) == 1 else "0.4"
        ax.axhline(count / 1e6, color=color, ls=":", lw=1.2)
        levels.append(count / 1e6)
        colors.append(color)
    ax.plot([], [], color="0.4", ls=":", lw=1.2, label="physical pixel count")
    return levels, colors
