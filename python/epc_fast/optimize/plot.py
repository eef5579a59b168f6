"""The objective's curve of an optimisation (the ``plot`` extra): the objective against each
optimised parameter, the others at the optimum, with its Monte Carlo band and the optimum
marked. matplotlib is imported here only.

The band is the objective's value +- 2 standard errors at each candidate: where the objective
lies over the scene's distribution. The candidates share their draws, so the curve's shape
(where its maximum is) is known far better than the band's width suggests; the optimum's own
uncertainty is drawn as a horizontal bar of +- 2 of its standard errors (the legend gives
one).
"""

from __future__ import annotations

import math

from .checks import unit_of
from .result import Optimum
from ..plotting import common
from ..plotting.common import add_conditions, conditions_lines, save_figure
from ..plotting.layout import freeze_layout
from ..plotting.text import output_scale, quantity_label, quantity_unit, unit_text

__all__ = ["figure_class", "curve_figure", "plot_curves", "BAND_ERRORS"]

#: Standard errors either side of the objective's band and of the optimum's bar.
BAND_ERRORS = 2.0


def _objective_axis(optimum: Optimum) -> tuple[float, str]:
    """(divisor, axis label) of the objective: EPC in Mpixel, a probability as it is."""
    label = optimum.objective.label
    if optimum.unit == "pixels":
        return output_scale("epc"), f"{label[:1].upper()}{label[1:]} ({quantity_unit('epc')})"
    return 1.0, label


def figure_class():
    """matplotlib's Figure, or an ImportError that says which extra to install."""
    return common.figure_class("the optimiser's curve plot", without="--no-plot on the command line")


def curve_figure(curves, optimum: Optimum, *, conditions=None):
    """A matplotlib Figure: one panel per :class:`~epc_fast.optimize.Curve` in ``curves``.

    ``conditions`` (lines, :func:`epc_fast.plotting.common.space_conditions` of the problem's
    space) are written under the panels; by default the draws, their seed, the version and
    the build."""
    figure = figure_class()(figsize=(7.5, 4.8 * len(curves) + 0.6), layout="constrained")
    scale, ylabel = _objective_axis(optimum)
    for axes, curve in zip(figure.subplots(len(curves), 1, squeeze=False)[:, 0], curves):
        y = curve.objective / scale
        band = BAND_ERRORS * curve.standard_error / scale
        axes.fill_between(curve.values, y - band, y + band, color="C0", alpha=0.25, lw=0,
                          label=f"± {BAND_ERRORS:g} standard errors")
        axes.plot(curve.values, y, color="C0", marker=".", label=optimum.objective.label)
        x = optimum.x[curve.parameter]
        error = optimum.x_standard_error[curve.parameter]
        unit = unit_text(unit_of(curve.parameter))
        spread = "" if math.isnan(error) else f" ± {error:.2g}"
        axes.errorbar([x], [optimum.value / scale],
                      xerr=None if math.isnan(error) else [BAND_ERRORS * error],
                      yerr=[BAND_ERRORS * optimum.value_standard_error / scale], color="C3",
                      marker="o", capsize=4, label=f"optimum {x:.4g}{spread} {unit}")
        axes.set_xlabel(quantity_label(curve.parameter))
        axes.set_ylabel(ylabel)
        others = ", ".join(f"{k} = {v:.4g}" for k, v in curve.at.items())
        axes.set_title(f"{optimum.points:,} draws, seed {optimum.seed}"
                       + (f"; {others}" if others else ""), fontsize=10)
        axes.grid(alpha=0.3)
        axes.legend(loc="best", fontsize=9)
    add_conditions(figure, conditions_lines(points=optimum.points, seed=optimum.seed)
                   if conditions is None else conditions)
    freeze_layout(figure)
    return figure


def plot_curves(curves, optimum: Optimum, path, *, conditions=None) -> None:
    """Write :func:`curve_figure` as a PNG to ``path``, atomically."""
    save_figure(curve_figure(curves, optimum, conditions=conditions), path, dpi=120)
