"""A design review's captures: each design at each light level captures a Siemens star of one
physical width, two slanted edges (their e-SFR MTF50s along and across the motion) and a flat
patch (its SNR), beside the model's EPC, f50, f50_across and SNR target. :mod:`~epc_fast.simulate.plot` draws them; ``epc-fast simulate``
writes them. Every e-SFR here is the e-SFR with bin-width correction
(``bin_correction=True``, :mod:`~epc_fast.simulate.edge_sfr`): its bins' average divided out,
the camera's own MTF, as the model's is; a lab's e-SFR lies 0.3-2 % lower in MTF50.

Every chart is laid out, and every MTF50 measured, in the design's output pixels: the sensor's
pitch times its binning, and for a design with ``modes`` the binning of the mode the model
picks at that light level (:func:`~epc_fast.simulate.camera.picked_mode`), in which it is
captured. The edge chart is sized to the blur as :mod:`~epc_fast.simulate.agreement` sizes it
(:func:`~epc_fast.simulate.agreement.edge_chart`: the line spread whole inside its columns,
beside the edge's run over the rows), up to ``max_edge_columns``: a longer blur's MTF50 is not
measured, and the cell says why. A blur longer than ``max_blur_px`` is not captured at all (no
picture, no SNR), and the cell says so. The edge across the motion is near horizontal with the
motion run along it (:data:`~epc_fast.simulate.agreement.ACROSS_MOTION_ANGLE_DEG`), sized by
:func:`~epc_fast.simulate.agreement.across_edge_chart` with ``edge_rows`` for its run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .agreement import (ACROSS_EDGE_ANGLE_DEG, ACROSS_MOTION_ANGLE_DEG, EDGE_ANGLE_DEG,
                        across_edge_chart, edge_chart, longest_wavelength_um, model_result)
from .camera import capture, mode_text, picked_mode
from .charts import MIN_EDGE_PX, flat, slanted_edge
from .edge_sfr import esfr
from .flat_patch import snr
from .star import siemens_star

__all__ = ["Cell", "Review", "review", "DEFAULTS"]

#: The review's charts and seed, as ``[simulate]`` gives them: the star's width (µm of the
#: scene: 256 pixels of a 1.4 µm design) and spokes, the edge's rows, its widest chart
#: (pixels), the flat patch's side (pixels) and the longest blur captured (pixels: a capture's
#: grid reaches a blur's length beyond the chart on either side, so its time and memory grow
#: with the blur; 1,500 pixels take a few seconds).
DEFAULTS = {"seed": 0, "star_width_um": 358.4, "spokes": 36, "edge_rows": 128,
            "max_edge_columns": 4096, "flat_px": 128, "max_blur_px": 1500}
#: The noise streams of a cell's three captures, spawned from the seed.
_STREAMS = {"star": 0, "edge": 1, "flat": 2, "edge_across": 3}


@dataclass(frozen=True, eq=False)
class Cell:
    """One design at one light level.

    Attributes
    ----------
    design : str, the design's name.
    illuminance_lux : lux.
    result : evaluate's :class:`~epc_fast.Result` here (epc, f50_cyc_per_mm,
        f50_across_cyc_per_mm, blur_mm, status).
    star : :class:`~epc_fast.simulate.Capture` of the star, or None (no image: ``why``).
    white_e : e-, the star's lightest reflectance without noise: the picture's white.
    sfr : :class:`~epc_fast.simulate.EdgeSFR` of the edge's capture, or None (``mtf_why``).
    sfr_noiseless : :class:`~epc_fast.simulate.EdgeSFR` of the same capture without its noise
        (its expected electrons), or None: the curve the noise scatters round.
    snr_db : dB, measured on the flat patch's capture (NaN without an image).
    snr_target_db : dB, the design's SNR target.
    why : str, why there is no image ("" when there is one).
    mtf_why : str, why the MTF50 is not measured ("" when it is).
    pitch_um : µm, the output pixel's pitch the charts are laid out and measured in: the
        sensor's pitch times the binning (of the picked mode, for a design with ``modes``).
    kwargs : dict, the design's keywords of :func:`epc_fast.evaluate` as captured here: a
        design with ``modes`` read as the mode evaluate picks (``result.mode``).
    mode_text : str, that mode for people ("" for a design without modes).
    sfr_across, sfr_across_noiseless : :class:`~epc_fast.simulate.EdgeSFR` of the edge
        across the motion, noisy and without its noise, or None (``mtf_across_why``).
    mtf_across_why : str, why the MTF50 across the motion is not measured ("" when it is).
    """

    design: str
    illuminance_lux: float
    result: object
    star: object = None
    white_e: float = math.nan
    sfr: object = None
    sfr_noiseless: object = None
    snr_db: float = math.nan
    snr_target_db: float = math.nan
    why: str = ""
    mtf_why: str = ""
    pitch_um: float = math.nan
    kwargs: dict = None
    mode_text: str = ""
    sfr_across: object = None
    sfr_across_noiseless: object = None
    mtf_across_why: str = ""

    @property
    def epc(self) -> float:
        """pixels, the model's EPC."""
        return float(self.result.epc)

    @property
    def f50_model_cyc_per_mm(self) -> float:
        """cycles/mm, the model's f50."""
        return float(self.result.f50_cyc_per_mm)

    @property
    def mtf50_cyc_per_mm(self) -> float:
        """cycles/mm, the simulated edge's MTF50 (NaN when not measured)."""
        return math.nan if self.sfr is None else float(self.sfr.mtf50_cyc_per_mm)

    @property
    def mtf50_fraction(self) -> float:
        """1, the simulated MTF50 over the model's f50 (NaN where either is not positive)."""
        f50 = self.f50_model_cyc_per_mm
        return self.mtf50_cyc_per_mm / f50 if f50 > 0 else math.nan

    @property
    def f50_across_model_cyc_per_mm(self) -> float:
        """cycles/mm, the model's f50 across the motion (f50_across)."""
        value = self.result.f50_across_cyc_per_mm
        return math.nan if value is None else float(value)

    @property
    def mtf50_across_cyc_per_mm(self) -> float:
        """cycles/mm, the simulated MTF50 across the motion (NaN when not measured)."""
        return math.nan if self.sfr_across is None else float(self.sfr_across.mtf50_cyc_per_mm)

    @property
    def mtf50_across_fraction(self) -> float:
        """1, the simulated MTF50 across the motion over the model's f50_across."""
        f50 = self.f50_across_model_cyc_per_mm
        return self.mtf50_across_cyc_per_mm / f50 if f50 > 0 else math.nan


@dataclass(frozen=True, eq=False)
class Review:
    """Every design at every light level.

    Attributes
    ----------
    designs : tuple of str, the designs' names (rows).
    kwargs : tuple of dict, each design's keywords of :func:`epc_fast.evaluate`.
    snr_target : tuple of str, each design's SNR target and where it is met, for people.
    illuminance_lux : tuple of float (columns).
    cells : tuple of tuples of :class:`Cell`, ``cells[design][light]``.
    settings : dict, the charts and seed (:data:`DEFAULTS`' keys).
    terms : tuple of str, the model terms the designs turn on, for people (a config's
        :func:`epc_fast.terms.terms_on`; empty: none said).
    """

    designs: tuple
    kwargs: tuple
    snr_target: tuple
    illuminance_lux: tuple
    cells: tuple
    settings: dict
    terms: tuple = ()

    def scene_text(self) -> str:
        """The scene in one line, for a figure's conditions."""
        s = self.settings
        lux = ", ".join(f"{x:g}" for x in self.illuminance_lux)
        return (f"{lux} lux; Siemens star of {s['spokes']} sine spokes, {s['star_width_um']:g} "
                f"um wide, reflectance 0.1 to 0.4; slanted edge {EDGE_ANGLE_DEG:g} deg, 0.1 to "
                f"0.4, {s['edge_rows']} rows; flat patch {s['flat_px']} px at the design's "
                "reflectance; captured at T_MPE, the chart at the field angle where the SNR "
                "target is met")

    def across_text(self) -> str:
        """The edge across the motion in one line, for its figure's conditions."""
        return (f"Across the motion: slanted edge {ACROSS_EDGE_ANGLE_DEG:g} deg from the "
                f"vertical, 0.1 to 0.4, {self.settings['edge_rows']} columns, the image moving "
                f"along it ({ACROSS_MOTION_ANGLE_DEG:g} deg from the rows) as far as along "
                "the motion's edge")

    @property
    def epc_axes(self) -> str:
        """How the designs' EPC counts the resolution: "both" when any design's
        ``epc_axes`` is, else "motion"."""
        return "both" if any(k.get("epc_axes") == "both" for k in self.kwargs) else "motion"


def _seed(seed: int, design: int, light: int, chart: str) -> np.random.SeedSequence:
    return np.random.SeedSequence(seed, spawn_key=(design, light, _STREAMS[chart]))


def _cell(name, kwargs, lux, indices, s) -> Cell:
    target = float(kwargs.get("snr_db", 30.0))
    result = model_result(lux, **{"invalid": "status", **kwargs})
    readout = {"mode_text": mode_text(kwargs, result)}
    kwargs = readout["kwargs"] = picked_mode(kwargs, result)  # as the camera reads it here
    # the output pixel's pitch: the charts' pixels, the e-SFR's and the blur's unit
    pitch = readout["pitch_um"] = (float(kwargs["pixel_pitch_um"])
                                   * float(kwargs.get("binning", 1.0)))
    blur_px = float(result.blur_mm) / (pitch * 1e-3)
    if math.isfinite(blur_px) and blur_px > s["max_blur_px"]:
        return Cell(name, lux, result, snr_target_db=target, mtf_why="no image",
                    mtf_across_why="no image", why=f"the image moves {blur_px:,.0f} px during T_MPE, more than "
                        f"max_blur_px {s['max_blur_px']:,}", **readout)
    star_chart = siemens_star(spokes=s["spokes"], width_um=s["star_width_um"], pitch_um=pitch)
    try:
        star = capture(star_chart, illuminance_lux=lux,
                       seed=_seed(s["seed"], *indices, "star"), **kwargs)
    except ValueError as error:
        return Cell(name, lux, result, snr_target_db=target, why=str(error),
                    mtf_why="no image", mtf_across_why="no image", **readout)
    reflectance = float(kwargs.get("reflectance", 0.4))
    patch = capture(flat(s["flat_px"], reflectance), illuminance_lux=lux,
                    seed=_seed(s["seed"], *indices, "flat"), **kwargs)
    white = float(np.mean(patch.expected_e)) * float(star_chart.values.max()) / reflectance
    lambda_f = longest_wavelength_um(kwargs) * float(kwargs["f_number"])
    (rows, columns), window = edge_chart(star.blur_mm, pitch, lambda_f, rows=s["edge_rows"])
    columns = max(MIN_EDGE_PX, columns)
    sfr, noiseless, mtf_why = None, None, ""
    if columns > s["max_edge_columns"]:
        mtf_why = (f"blur {star.blur_mm / (pitch * 1e-3):.0f} px needs a {columns}-column edge "
                   f"(max_edge_columns {s['max_edge_columns']})")
    else:
        edge = capture(slanted_edge((rows, columns), EDGE_ANGLE_DEG), illuminance_lux=lux,
                       seed=_seed(s["seed"], *indices, "edge"), **kwargs)
        try:
            sfr = esfr(edge.image_e, pitch, window=window, bin_correction=True)
            noiseless = esfr(edge.expected_e, pitch, window=window, bin_correction=True)
        except ValueError as error:
            mtf_why = str(error)
    across = _across(kwargs, lux, star.blur_mm, pitch, lambda_f, s,
                     _seed(s["seed"], *indices, "edge_across"))
    return Cell(name, lux, result, star=star, white_e=white, sfr=sfr, sfr_noiseless=noiseless,
                snr_db=float(snr(patch.image_e).snr_db), snr_target_db=target,
                mtf_why=mtf_why, **readout, **across)


def _across(kwargs, lux, blur_mm, pitch, lambda_f, s, seed) -> dict:
    """The cell's fields of the edge across the motion: its e-SFR noisy and without noise, or
    why it is not measured."""
    shape, window = across_edge_chart(blur_mm, pitch, lambda_f, run=s["edge_rows"])
    edge = capture(slanted_edge(shape, ACROSS_EDGE_ANGLE_DEG), illuminance_lux=lux, seed=seed,
                   motion_angle_deg=ACROSS_MOTION_ANGLE_DEG, **kwargs)
    try:
        return {"sfr_across": esfr(edge.image_e, pitch, window=window, bin_correction=True),
                "sfr_across_noiseless": esfr(edge.expected_e, pitch, window=window,
                                             bin_correction=True)}
    except ValueError as error:
        return {"mtf_across_why": str(error)}


def review(designs, illuminance_lux, *, snr_target=None, terms=(), **settings) -> Review:
    """Capture every design at every light level.

    Parameters
    ----------
    designs : sequence of (name, kwargs): each design's name and its keywords of
        :func:`epc_fast.evaluate` (scalars), e.g. ``(d.name, d.evaluate_kwargs())``.
    illuminance_lux : sequence of lux, the light levels.
    snr_target : sequence of str, optional: each design's SNR target and where it is met,
        for the figures (default: the target alone).
    terms : sequence of str, optional: the model terms the designs turn on, for the figures'
        conditions.
    **settings : the charts and seed, :data:`DEFAULTS`' keys (checked by the caller's config).

    Returns
    -------
    Review
    """
    unknown = sorted(set(settings) - set(DEFAULTS))
    if unknown:
        raise TypeError(f"review() got unknown setting(s) {', '.join(unknown)}; the settings "
                        f"are {', '.join(DEFAULTS)}")
    s = {**DEFAULTS, **settings}
    names = tuple(str(name) for name, _ in designs)
    kwargs = tuple(dict(k) for _, k in designs)
    lux = tuple(float(x) for x in illuminance_lux)
    if snr_target is None:
        snr_target = tuple(f"{float(k.get('snr_db', 30.0)):g} dB" for k in kwargs)
    cells = tuple(tuple(_cell(name, k, x, (i, j), s) for j, x in enumerate(lux))
                  for i, (name, k) in enumerate(zip(names, kwargs)))
    return Review(names, kwargs, tuple(snr_target), lux, cells, s, tuple(terms))
