"""The design review's figures of a :class:`~epc_fast.simulate.review.Review`: the contact
sheet (the Siemens star as each design captures it at each light level, captioned with the
model's EPC, the edge's measured MTF50 and the flat patch's SNR) and the edges' e-SFR MTF
against the model's system MTF, along the motion and across it. Both carry their conditions
(:func:`epc_fast.plotting.common.add_conditions`); matplotlib is imported only here, inside the
functions.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np

from ..plotting import common
from ..plotting.common import CONDITIONS_FONTSIZE, add_conditions, conditions_lines
from ..plotting.layout import renderer_of, freeze_layout
from ..plotting.text import unit_text

__all__ = ["contact_sheet_figure", "mtf_figure", "conditions", "figure_class", "model_mtf"]

#: Inches: the side of one picture of the contact sheet.
CELL_IN = 2.3
#: Characters a line of a cell's "no image" text holds.
WHY_WIDTH = 30
#: Points of the model's MTF curve over 0 to twice Nyquist.
CURVE_POINTS = 400
#: Inches: the room a figure's title and conditions leave on either side.
SIDE_IN = 0.1
#: Points: the contact sheet's title.
TITLE_FONTSIZE = 10


def figure_class():
    """matplotlib's Figure, or an ImportError that says which extra to install."""
    return common.figure_class("the simulator's figures", without="--no-plots on the command "
                               "line")


def conditions(review, extra=()) -> list[str]:
    """The conditions of a review's figures: its designs, their SNR targets and where they
    are met, the scene in one line, the seed, the terms the designs turn on, ``extra``, the
    version and the build."""
    terms = [f"Terms on: {'; '.join(review.terms)}"] if review.terms else []
    if review.epc_axes == "both" and not any("both directions" in t for t in review.terms):
        terms.append('EPC counted in both directions, 4 S f50 f50_across (epc_axes="both")')
    return conditions_lines(designs=review.designs, snr_target=review.snr_target,
                            scene=review.scene_text(), seed=review.settings["seed"],
                            extra=[*terms, *extra])


def fitted_lines(figure, lines, fontsize: float) -> list[str]:
    """``lines``, each broken at spaces (its continuations indented) into lines that render
    within ``figure``'s width less :data:`SIDE_IN` a side at ``fontsize`` points."""
    from matplotlib.font_manager import FontProperties

    renderer = renderer_of(figure)
    prop = FontProperties(size=fontsize)
    room = (figure.get_figwidth() - 2.0 * SIDE_IN) * figure.dpi

    def fits(parts) -> bool:
        return all(renderer.get_text_width_height_descent(part, prop, ismath=False)[0] <= room
                   for part in parts)

    out = []
    for line in lines:
        width, parts = len(line), [line]
        while not fits(parts) and width > 8:
            width -= max(1, width // 20)
            parts = textwrap.wrap(line, width, subsequent_indent="  ", break_on_hyphens=False)
        out.extend(parts)
    return out


def _caption(cell) -> str:
    if cell.why:
        return "no image" + (f"\nmode {cell.mode_text}" if cell.mode_text else "")
    model = "model, both axes" if (cell.kwargs or {}).get("epc_axes") == "both" else "model"
    epc = (f"EPC {cell.epc / 1e6:.3g} Mpx ({model})" if cell.epc >= 1e5
           else f"EPC {cell.epc:,.0f} pixels ({model})")
    if math.isnan(cell.mtf50_cyc_per_mm):
        mtf = "MTF50 not measured"
    else:
        mtf = (f"MTF50 {cell.mtf50_cyc_per_mm:.3g} cyc/mm = {cell.mtf50_fraction:.2f} f50")
    mode = f"\nmode {cell.mode_text}" if cell.mode_text else ""
    return f"{epc}\n{mtf}\nSNR {cell.snr_db:.1f} dB (target {cell.snr_target_db:g}){mode}"


def contact_sheet_figure(review, *, conditions_text=None):
    """A matplotlib Figure: rows the designs, columns the light levels, each picture the
    star's noisy capture in electrons, linear from 0 (black) to the star's lightest
    reflectance without noise (white), pixels drawn as squares, every picture the same patch
    of scene at the same size; under each, the model's EPC, the edge's MTF50 (cycles/mm and a
    fraction of the model's f50) and the flat patch's SNR. A design without an image at a
    light level says why in its place."""
    rows, cols = len(review.designs), len(review.illuminance_lux)
    width_um = review.settings["star_width_um"]
    lines = conditions(review) if conditions_text is None else conditions_text
    caption_in = 0.75 + (0.13 if any(c.mode_text for row in review.cells for c in row) else 0.0)
    width_in = 1.2 + CELL_IN * cols
    figure = figure_class()(figsize=(width_in, 0.9 + (CELL_IN + caption_in) * rows),
                            layout="constrained")
    lines = fitted_lines(figure, lines, CONDITIONS_FONTSIZE)
    title = fitted_lines(figure, unit_text(
        f"The same {width_um:g} um of scene, a Siemens star, as each design captures it at "
        "T_MPE\n(electrons: black 0, white the star's lightest reflectance without "
        "noise)").split("\n"), TITLE_FONTSIZE)
    figure.set_figheight(figure.get_figheight() + 0.16 * len(lines) + 0.17 * (len(title) - 2))
    axes = figure.subplots(rows, cols, squeeze=False)
    for i, name in enumerate(review.designs):
        for j, lux in enumerate(review.illuminance_lux):
            ax, cell = axes[i, j], review.cells[i][j]
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_xlim(0.0, width_um)
            ax.set_ylim(width_um, 0.0)
            ax.set_aspect("equal")
            if cell.why:
                ax.set_facecolor("0.92")
                ax.text(0.5, 0.5, "no image:\n" + textwrap.fill(cell.why, WHY_WIDTH),
                        transform=ax.transAxes, ha="center", va="center", fontsize=7,
                        color="0.2")
            else:
                star = cell.star
                extent = star.image_e.shape[1] * star.pitch_um
                offset = (width_um - extent) / 2.0
                ax.imshow(star.image_e, cmap="gray", vmin=0.0, vmax=cell.white_e,
                          interpolation="nearest",
                          extent=(offset, offset + extent, offset + extent, offset))
            ax.set_xlabel(_caption(cell), fontsize=7.5, linespacing=1.3)
            if i == 0:
                ax.set_title(f"{lux:g} lux", fontsize=10)
            if j == 0:
                ax.set_ylabel(unit_text(name), fontsize=9)
    figure.suptitle("\n".join(title), fontsize=TITLE_FONTSIZE)
    add_conditions(figure, lines)
    freeze_layout(figure)
    return figure


def model_mtf(frequency_cyc_per_mm, kwargs: dict, blur_mm: float) -> np.ndarray:
    """1: the model's system MTF (:func:`epc_fast.reference.model.mtf_system`) of the design
    ``kwargs`` (keywords of :func:`epc_fast.evaluate`, one readout: a design with ``modes``
    read as one of them, :func:`epc_fast.simulate.camera.picked_mode`) with evaluate's
    ``blur_mm`` (mm): its binned pixel, burst alignment, wavefront error or lens table,
    denoising and demosaicker with the rest."""
    from ..design import DESIGN_KEYWORDS, resolve
    from ..reference.model import mtf_system
    from .camera import capture_inputs

    capture_inputs(kwargs)  # the keywords a capture takes
    if kwargs.get("modes") is not None:
        raise ValueError("kwargs: one readout, not modes: give the mode's keywords "
                         "(epc_fast.simulate.camera.picked_mode)")
    d = resolve(0.0, **{k: v for k, v in kwargs.items() if k in DESIGN_KEYWORDS})
    wavelengths, weights = d.wavelengths()
    table = d.lens_table()
    value = {name: float(d.parameter(name)) for name in (
        "f_number", "pixel_pitch_um", "fill_factor", "jitter_um", "binning",
        "alignment_error_um", "frames", "wavefront_rms_waves", "denoise_sigma_px")}
    return mtf_system(np.asarray(frequency_cyc_per_mm, dtype=float), value["f_number"],
                      value["pixel_pitch_um"], value["fill_factor"], float(blur_mm),
                      value["jitter_um"], wavelengths, weights, value["binning"],
                      value["alignment_error_um"], value["frames"],
                      value["wavefront_rms_waves"], value["denoise_sigma_px"], 0.0,
                      None if table is None else [table], d.color.demosaic_table)


def _output_pitch_um(cell, kwargs: dict) -> float:
    """µm, the cell's output pixel pitch (the design's pitch times its binning for a cell
    made without one)."""
    if math.isfinite(cell.pitch_um):
        return cell.pitch_um
    return float(kwargs["pixel_pitch_um"]) * float(kwargs.get("binning", 1.0))


#: A cell's fields of the MTF along the motion and across it: its e-SFRs, their MTF50, the
#: model's f50, and whether the model's curve has the motion's blur.
_DIRECTIONS = {
    "along": ("sfr", "sfr_noiseless", "mtf50_cyc_per_mm", "f50_model_cyc_per_mm", True),
    "across": ("sfr_across", "sfr_across_noiseless", "mtf50_across_cyc_per_mm",
               "f50_across_model_cyc_per_mm", False)}


def _mtf_panel(ax, review, i, direction="along"):
    sfr_name, noiseless_name, mtf50_name, f50_name, blurred = _DIRECTIONS[direction]
    pitches = sorted({_output_pitch_um(c, review.kwargs[i]) for c in review.cells[i]})
    top = 1e3 / pitches[0]  # cycles/mm, twice the finest output pixel's Nyquist
    f = np.linspace(0.0, top, CURVE_POINTS)
    for j, cell in enumerate(review.cells[i]):
        color = f"C{j}"
        lux = f"{cell.illuminance_lux:g} lux"
        if cell.why:
            ax.plot([], [], color=color, label=f"{lux}: no image")
            continue
        ax.plot(f, model_mtf(f, review.kwargs[i] if cell.kwargs is None else cell.kwargs,
                             float(cell.result.blur_mm) if blurred else 0.0),
                color=color, ls="--", lw=1.5, zorder=4)
        f50 = getattr(cell, f50_name)
        ax.plot([f50], [0.5], marker="x", color=color, ms=7, mew=1.5, ls="none", zorder=5)
        if getattr(cell, sfr_name) is None:
            ax.plot([], [], color=color, label=f"{lux}: MTF50 not measured")
            continue
        mtf50 = getattr(cell, mtf50_name)
        for sfr, style in ((getattr(cell, sfr_name), {"lw": 0.7, "alpha": 0.35, "zorder": 1}),
                           (getattr(cell, noiseless_name), {"lw": 1.6, "zorder": 3, "label": (
                               f"{lux}: MTF50 {mtf50:.3g} (model {f50:.3g})")})):
            keep = sfr.frequency_cyc_per_mm <= top
            ax.plot(sfr.frequency_cyc_per_mm[keep], sfr.mtf[keep], color=color, **style)
        ax.plot([mtf50], [0.5], marker="o", color=color, ms=6, mfc="white",
                mew=1.5, ls="none", zorder=5)
    ax.axhline(0.5, color="0.6", lw=0.8, ls=":")
    for pitch in pitches:  # each output pixel's Nyquist frequency (one, without modes)
        nyquist = 1e3 / (2.0 * pitch)
        ax.axvline(nyquist, color="0.6", lw=0.8)
        label = "Nyquist " if len(pitches) == 1 else f"Nyquist {pitch:g} um "
        ax.text(nyquist, 1.02, unit_text(label), fontsize=7, color="0.4", va="bottom",
                ha="right")
    ax.set_xlim(0.0, top)
    ax.set_ylim(0.0, 1.08)
    ax.set_xlabel("Frequency (cycles/mm)", fontsize=8)
    ax.set_ylabel("MTF", fontsize=8)
    ax.set_title(unit_text(review.designs[i]), fontsize=9)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6.5, loc="upper right", title="cycles/mm", title_fontsize=6.5)


def mtf_figure(review, *, conditions_text=None, direction="along"):
    """A matplotlib Figure: one panel per design, a colour per light level; solid the e-SFR MTF
    of the simulated slanted edge without its noise, faint that of the noisy capture (its MTF50
    a circle: beyond the blur's first zeros the noise is most of it), dashed the model's
    system MTF with evaluate's blur there (its f50 a cross), from 0 to twice the design's
    Nyquist frequency. ``direction="across"``: the same across the motion, the near-horizontal
    edge's e-SFR against the model's system MTF without the motion's blur (its f50_across a
    cross)."""
    if direction not in _DIRECTIONS:
        raise ValueError(f"direction: 'along' or 'across', got {direction!r}")
    n = len(review.designs)
    cols = 1 if n == 1 else 2
    rows = -(-n // cols)
    extra = ["Solid: e-SFR (ISO 12233) with bin-width correction of the simulated slanted edge "
             "without its noise; faint: "
             "of the noisy capture, o its MTF50; dashed: the model's system MTF with evaluate's "
             "blur, x its f50"]
    if direction == "across":
        extra = [review.across_text(),
                 "Solid: e-SFR (ISO 12233) with bin-width correction of the simulated edge across "
                 "the motion without its noise; faint: of the noisy capture, o its MTF50; dashed: the model's system "
                 "MTF without the motion's blur, x its f50_across"]
    lines = conditions(review, extra) if conditions_text is None else conditions_text
    figure = figure_class()(figsize=(4.6 * cols + 0.4, 3.4 * rows + 0.7), layout="constrained")
    lines = fitted_lines(figure, lines, CONDITIONS_FONTSIZE)
    figure.set_figheight(figure.get_figheight() + 0.16 * len(lines))
    axes = figure.subplots(rows, cols, squeeze=False)
    for k, ax in enumerate(axes.flat):
        if k < n:
            _mtf_panel(ax, review, k, direction)
        else:
            ax.remove()
    figure.suptitle("MTF of each design: the simulated capture against the model"
                    + (", across the motion" if direction == "across" else ""), fontsize=10)
    add_conditions(figure, lines)
    freeze_layout(figure)
    return figure
