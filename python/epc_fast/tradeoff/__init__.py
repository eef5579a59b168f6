"""Speed against accuracy: the engine's knobs, each measured for error and throughput.

A :class:`Setting` is a name and the keyword arguments it passes to :func:`epc_fast.evaluate`
(the f50 solver and its tolerance, the T_MPE solver, the arithmetic precision, spectral samples
for polychromatic diffraction). For each setting :mod:`epc_fast.tradeoff.measurements` measures

- **error**: the relative error of f50 against the NumPy reference (``backend="reference"``,
  which bisects f50 to adjacent floats) on the same random designs, over the points where both
  give status OK; polychromatic settings against the reference with the same spectrum. Status
  mismatches are counted (there should be none: the knobs change how f50 is solved, not which
  points have one);
- **throughput**: points/s on 1 and 2 threads, the median of a few timed rounds after one
  warm-up.

:func:`pareto_front` picks the settings that no other setting beats on both at once.
``epc-fast bench`` (:mod:`epc_fast.commands.bench`) is the command line. Settings whose knob
the installed :func:`evaluate` does not take are skipped (:func:`split_by_knobs`), so the list
may name knobs a build lacks.

The rooms: :mod:`~epc_fast.tradeoff.measurements` measures (it never imports matplotlib),
:mod:`~epc_fast.tradeoff.tables` makes the table columns, :mod:`~epc_fast.tradeoff.plot` the
figure (matplotlib, the ``plot`` extra, imported when it is drawn). Their public names are
importable from here (``from epc_fast.tradeoff import plot_tradeoff``).
"""
from __future__ import annotations

from .measurements import (BASELINE, F50_RTOLS, F50_SOLVERS, IMPLICIT_KNOB_VALUES, PROBE_DESIGN,
                      SPECTRUM_SAMPLES, THREADS, Accuracy, Measurement, Setting, call_time_s,
                      default_settings, evaluate_parameters, f50_accuracy, front_of, knob_value,
                      measure, pareto_front, points_per_s, rejection, rtol_text, speedups,
                      split_by_knobs)
from .plot import LABEL_FONTSIZE, ZERO_ERROR_FLOOR, plot_tradeoff
from .tables import csv_columns, markdown_columns

__all__ = [
    "Setting", "Accuracy", "Measurement", "default_settings", "split_by_knobs", "rejection",
    "evaluate_parameters", "knob_value", "f50_accuracy", "call_time_s", "points_per_s",
    "measure", "speedups", "pareto_front", "front_of", "rtol_text", "markdown_columns",
    "csv_columns", "plot_tradeoff", "THREADS", "F50_SOLVERS", "F50_RTOLS", "SPECTRUM_SAMPLES",
    "BASELINE", "IMPLICIT_KNOB_VALUES", "PROBE_DESIGN", "ZERO_ERROR_FLOOR", "LABEL_FONTSIZE",
]
