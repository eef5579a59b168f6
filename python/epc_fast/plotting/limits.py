"""What limits each design over illuminance: each MTF factor's share of the loss at f50 as a
stacked band, one panel per design (docs/limits.md). The companion of
:func:`epc_fast.plotting.plot_epc_over_illuminance`, over the same illuminance grid. Needs
matplotlib (the ``plot`` extra), imported inside the functions it calls.
"""

from __future__ import annotations

import math

from ..presets import READINGS, evaluate_over_illuminance
from .common import (add_conditions, designs_conditions, figure_class, illuminance_lux,
                     shared_reading)
from .layout import freeze_layout
from .text import quantity_label, unit_text

__all__ = ["plot_limits_over_illuminance", "FACTORS", "SHARE_LABEL"]

#: Each factor's share output, its name on the figure and its colour, bottom band first.
#: Jitter has no band: a Design has no jitter, so evaluate's default (none) gives it a share of
#: 0 and the three bands sum to 1.
FACTORS = (
    ("share_diffraction", "diffraction", "C0"),
    ("share_pixel", "pixel aperture", "C2"),
    ("share_motion", "motion blur (hand shake)", "C3"),
)
#: The y axis's label: the shares are pure numbers, ln MTF_i(f50) / ln c.
SHARE_LABEL = "Share of the MTF loss at f50"
#: Panels side by side.
COLUMNS = 2
#: inches: the figure's width, each row of panels' height, and the room for titles and legend.
WIDTH_IN, ROW_HEIGHT_IN, MARGINS_IN = 7.0, 2.4, 1.4


def plot_limits_over_illuminance(designs, *, title="", lux_range=(100.0, 100000.0),
                                 backend="core", threads=None, conditions=None):
    """A figure of what limits each design: the shares of diffraction, the pixel aperture and
    motion blur in the loss at f50 (ln MTF_i(f50) / ln c, which sum to 1; a design has no
    jitter), stacked over illuminance, one panel per design.

    The x axes are illuminance in lux on a log scale, the y axes the share, 0 to 1; every panel
    shares both. A point whose status is not OK has no shares (NaN) and leaves a gap. The
    legend sits below the panels. The figure's layout is fixed when it is returned: add
    nothing that needs room.

    Parameters
    ----------
    designs : sequence of presets.Design
        All with the same reading (:data:`epc_fast.presets.READINGS`), named in the subtitle.
    title : str
    lux_range : (float, float)
        lux, the x axes.
    backend, threads
        Passed to :func:`epc_fast.evaluate`.
    conditions : sequence of str, optional
        The lines written under the legend; by default the designs, their SNR targets, the
        scene, the points, the version and the build
        (:func:`epc_fast.plotting.common.designs_conditions`).

    Returns
    -------
    matplotlib.figure.Figure
        Its axes in the order of ``designs``, each titled with its design's name.
    """
    reading = shared_reading(designs)
    lux = illuminance_lux(lux_range)
    outputs = [output for output, _, _ in FACTORS]
    result = evaluate_over_illuminance(designs, lux, outputs=outputs, backend=backend,
                                       threads=threads)
    rows = math.ceil(len(designs) / COLUMNS)
    columns = min(COLUMNS, len(designs))
    figure = figure_class()(figsize=(WIDTH_IN, rows * ROW_HEIGHT_IN + MARGINS_IN),
                             layout="constrained")
    axes = figure.subplots(rows, columns, sharex=True, sharey=True, squeeze=False)
    for index, (design, ax) in enumerate(zip(designs, axes.flat)):
        ax.stackplot(lux, *[getattr(result, output)[index] for output in outputs],
                     colors=[color for _, _, color in FACTORS], alpha=0.85, lw=0.0,
                     labels=[label for _, label, _ in FACTORS] if index == 0 else ())
        ax.set_title(unit_text(design.name), fontsize=9)
        ax.grid(which="major", alpha=0.4)
        ax.grid(which="minor", alpha=0.15)
        if index % columns == 0:
            ax.set_ylabel(SHARE_LABEL)
        if index + columns >= len(designs):
            ax.set_xlabel(quantity_label("illuminance_lux"))
            ax.xaxis.set_tick_params(labelbottom=True)
    for ax in axes.flat[len(designs):]:
        ax.remove()
    axes[0, 0].set_xscale("log")
    axes[0, 0].set_xlim(*lux_range)
    axes[0, 0].set_ylim(0.0, 1.0)
    figure.suptitle(unit_text(f"{title}\n{READINGS[reading].meaning}"), fontsize=10)
    figure.legend(loc="outside lower center", ncols=len(FACTORS), fontsize=9, frameon=False)
    add_conditions(figure, designs_conditions(designs, lux) if conditions is None
                   else conditions)
    freeze_layout(figure)
    return figure
