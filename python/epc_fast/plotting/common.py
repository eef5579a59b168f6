"""What every figure of the package shares: matplotlib's Figure, or an error that says which
extra to install, and an atomic save.

Figures are built on :class:`matplotlib.figure.Figure` directly, not through pyplot: no global
state, no GUI backend, safe in threads and on headless machines. matplotlib (the ``plot``
extra) is imported only inside these functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["figure_class", "save_figure", "shared_reading", "illuminance_lux", "PLOT_EXTRA",
           "POINTS_PER_DECADE"]

#: The install command that brings matplotlib.
PLOT_EXTRA = "pip install 'epc-fast[plot]'"
#: Curves per decade of illuminance: smooth at any zoom the paper's figures need.
POINTS_PER_DECADE = 80


def figure_class(what: str = "plotting", without: str = ""):
    """:class:`matplotlib.figure.Figure`, or an ImportError that says which extra to install.

    Parameters
    ----------
    what : str
        What needs matplotlib, as the message names it ("the optimiser's curve plot").
    without : str
        How to do without the figure, added to the message ("--no-plot on the command line").
    """
    try:
        from matplotlib.figure import Figure
    except ImportError:
        alternative = f" (or {without})" if without else ""
        raise ImportError(f"matplotlib is needed for {what}: {PLOT_EXTRA}{alternative}") from None
    return Figure


def save_figure(figure, path, dpi: int = 110, file_format: str | None = None) -> Path:
    """Write ``figure`` to ``path`` whole or not at all (:func:`epc_fast.scan.atomic.atomic_write`);
    in ``file_format`` ("png", "pdf", "svg", ...), by default the path's suffix, PNG without one.
    Returns the path."""
    from ..scan.atomic import atomic_write

    path = Path(path)
    file_format = file_format or path.suffix.lstrip(".").lower() or "png"
    return atomic_write(path, lambda temporary: figure.savefig(temporary, dpi=dpi,
                                                                format=file_format))


def shared_reading(designs) -> str:
    """The reading (:data:`epc_fast.presets.READINGS`) all ``designs`` share; a ValueError
    when they do not, since a figure names one in its title."""
    readings = {d.reading for d in designs}
    if len(readings) != 1:
        raise ValueError(f"the designs of one figure share one reading, got {sorted(readings)}")
    return readings.pop()


def illuminance_lux(lux_range) -> np.ndarray:
    """lux: :data:`POINTS_PER_DECADE` log-spaced points a decade over ``lux_range`` (lux),
    both ends included."""
    lo, hi = np.log10(lux_range[0]), np.log10(lux_range[1])
    return np.logspace(lo, hi, int(round((hi - lo) * POINTS_PER_DECADE)) + 1)
