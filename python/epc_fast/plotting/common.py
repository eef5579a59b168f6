"""What every figure of the package shares: matplotlib's Figure, or an error that says which
extra to install, and an atomic save.

Figures are built on :class:`matplotlib.figure.Figure` directly, not through pyplot: no global
state, no GUI backend, safe in threads and on headless machines. matplotlib (the ``plot``
extra) is imported only inside these functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

# The one physical pixel count, N = S / p² (docs/model.md, "EPC"), kept importable
# from here, where the figures took it first.
from ..sensor import physical_pixel_count

__all__ = ["figure_class", "save_figure", "shared_reading", "illuminance_lux", "PLOT_EXTRA",
           "POINTS_PER_DECADE", "build_text", "conditions_lines", "add_conditions",
           "space_conditions", "designs_conditions", "physical_pixel_count",
           "CONDITIONS_FONTSIZE", "CONDITIONS_WIDTH"]

#: The install command that brings matplotlib.
PLOT_EXTRA = "pip install 'epc-fast[plot]'"
#: Curves per decade of illuminance: smooth at any zoom the paper's figures need.
POINTS_PER_DECADE = 80
#: pt: the size of a figure's conditions under its axes.
CONDITIONS_FONTSIZE = 7
#: characters: a conditions line longer than this is wrapped.
CONDITIONS_WIDTH = 120


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
    """Write ``figure`` to ``path`` whole or not at all (:func:`epc_fast.jobs.atomic.atomic_write`);
    in ``file_format`` ("png", "pdf", "svg", ...), by default the path's suffix, PNG without one.
    Returns the path."""
    from ..jobs.atomic import atomic_write

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


def build_text() -> str:
    """The package's version and the core's build the figure was drawn with:
    ``"epc_fast 1.2.0, core x86-64-v3"``."""
    from .. import __version__

    try:
        from .. import _core
        isa = _core.isa
    except ImportError:
        isa = "not loaded"
    return f"epc_fast {__version__}, core {isa}"


def conditions_lines(*, designs=(), snr_target=(), scene="", points=None, seed=None,
                     extra=()) -> list[str]:
    """The lines of a figure's conditions (:func:`add_conditions`), from what it shows.

    Parameters
    ----------
    designs : sequence of str, the designs' names.
    snr_target : sequence of str, the SNR target and where it is met (one for all, or one per
        design: ``"30 dB at corner (27.03 deg, default)"``); equal ones are said once.
    scene : str, the scene in one line (what varies and how it is drawn).
    points : int, the points (draws) behind the figure; seed : int, their seed.
    extra : sequence of str, lines of the figure's own.

    Returns
    -------
    list of str: designs, SNR target, scene, points and seed, the extra lines, and the
    version and build (:func:`build_text`), each line present only when given.
    """
    from .text import unit_text

    lines = []
    if designs:
        lines.append("Designs: " + ", ".join(str(d) for d in designs))
    targets = list(dict.fromkeys(str(t) for t in snr_target))
    if len(targets) == 1:
        lines.append(f"SNR target: {targets[0]}")
    elif targets:
        lines.append("SNR target: " + "; ".join(
            f"{name}: {target}" for name, target in zip(designs, snr_target)))
    if scene:
        lines.append(f"Scene: {scene}")
    counted = [f"{points:,} points" if points is not None else "",
               f"seed {seed}" if seed is not None else ""]
    if any(counted):
        lines.append(", ".join(part for part in counted if part))
    lines.extend(extra)
    lines.append(build_text())
    return [unit_text(line) for line in lines]


def space_conditions(space, *, points=None, seed=None, skip=(), extra=()) -> list[str]:
    """:func:`conditions_lines` of a scan's or an optimisation's space
    (:class:`epc_fast.scan.Space`): its designs, where each meets its SNR target, its other
    parameters (``skip`` left out: the axes the figure draws) as the scene, and every term
    it turns on beside them (:func:`epc_fast.terms.terms_on`: a colour filter, lens
    tables, the designs' stabilisation, read noise, ...)."""
    from ..terms import terms_on

    scene = "; ".join(f"{name} {axis!r}" for name, axis in space.axes.items()
                      if name != "design" and name not in skip)
    on = terms_on(space)
    return conditions_lines(designs=space.design_names, snr_target=space.snr_target_text(),
                            scene=scene, points=points, seed=seed,
                            extra=([f"Terms on: {'; '.join(on)}"] if on else []) + list(extra))


def designs_conditions(designs, lux) -> list[str]:
    """:func:`conditions_lines` of a figure of presets' ``designs`` (:class:`epc_fast.presets.
    Design`) over the illuminances ``lux``: their names, SNR targets, the scene (illuminance
    the x axis, every other parameter the design's own or evaluate's default), the points, and
    every term the designs turn on (:func:`epc_fast.terms.designs_terms`)."""
    from ..terms import default_values, designs_terms, readout_terms

    targets = [f"{design.evaluate_kwargs()['snr_db']:g} dB at {design.snr_at_text}"
               for design in designs]
    scene = (f"illuminance {lux[0]:g} to {lux[-1]:g} lux (the x axis); the designs' own "
             f"parameters, evaluate's defaults for the rest")
    names = [design.name for design in designs]
    defaults = default_values()
    kwargs = [design.evaluate_kwargs() for design in designs]
    table = {name: [k.get(name, default) for k in kwargs] for name, default in defaults.items()}
    on = designs_terms(names, table) + readout_terms(
        names, [design.binning_readout for design in designs],
        [design.modes for design in designs])
    return conditions_lines(designs=names, snr_target=targets, scene=scene,
                            points=len(lux) * len(designs),
                            extra=[f"Terms on: {'; '.join(on)}"] if on else [])


def add_conditions(figure, lines, fontsize: float = CONDITIONS_FONTSIZE):
    """Write ``lines`` (:func:`conditions_lines`) in small grey text along the bottom of
    ``figure``, under everything else. The figure's constrained layout is confined to the
    room above them, and :func:`epc_fast.plotting.layout.freeze_layout` moves a legend placed
    outside the axes ("outside lower center") into that room: call this before the layout is
    frozen. A ``$`` is shown as itself. Returns the Text."""
    import textwrap

    from .layout import renderer_of

    wrapped = [textwrap.fill(line, CONDITIONS_WIDTH, subsequent_indent="  ",
                             break_on_hyphens=False) for line in lines]
    pad_in = 0.06
    text = figure.text(0.5, pad_in / figure.get_figheight(),
                       "\n".join(wrapped).replace("$", r"\$"), fontsize=fontsize,
                       color="0.35", linespacing=1.25, ha="center", va="bottom")
    text.set_in_layout(False)
    height = text.get_window_extent(renderer_of(figure)).height / figure.bbox.height
    room = height + 2 * pad_in / figure.get_figheight()
    engine = figure.get_layout_engine()
    if engine is not None and "rect" in engine.get():
        left, bottom, width, top = engine.get()["rect"]
        engine.set(rect=(left, max(bottom, room), width, top - max(bottom, room) + bottom))
    return text
