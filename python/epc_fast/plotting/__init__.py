"""Figures of the model: EPC over illuminance for a few designs, and what limits each of them.

The rooms: :mod:`~epc_fast.plotting.epc` (EPC over illuminance),
:mod:`~epc_fast.plotting.limits` (each MTF factor's share of the loss at f50),
:mod:`~epc_fast.plotting.layout` (labels placed where nothing else is drawn),
:mod:`~epc_fast.plotting.text` (units and axis labels from names) and
:mod:`~epc_fast.plotting.common` (matplotlib's Figure or which extra to install; the atomic
save), which the scan's, the optimiser's and the trade-off's figures share too. matplotlib (the
``plot`` extra) is imported only inside the functions that draw.
"""

from __future__ import annotations

from .common import figure_class, save_figure
from .epc import plot_epc_over_illuminance
from .limits import FACTORS, SHARE_LABEL, plot_limits_over_illuminance

__all__ = ["plot_epc_over_illuminance", "plot_limits_over_illuminance", "save_figure",
           "figure_class", "FACTORS", "SHARE_LABEL"]
