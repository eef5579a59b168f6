"""The model against the simulator: a design's f50 and target SNR from ``evaluate`` beside the
MTF50 (ISO 12233 e-SFR with bin-width correction) and the SNR measured on its simulated
captures, repeated over seeds. The e-SFR here divides out its own bins' average
(``bin_correction=True``, :mod:`epc_fast.simulate.edge_sfr`), a bias of the method: it measures
the camera's own MTF, which the model's f50 is; a lab's e-SFR (the default) lies 0.3-2 % lower.

The edge chart is sized to the blur: the e-SFR must see the whole line spread, or the
measurement, not the model, sets the answer. Two edges are captured: a near-vertical one
(:data:`EDGE_ANGLE_DEG`), whose normal the motion along the rows crosses, for the MTF along the
motion beside evaluate's f50, and a near-horizontal one (:data:`ACROSS_EDGE_ANGLE_DEG`) with
the motion turned parallel to it (:data:`ACROSS_MOTION_ANGLE_DEG`), so that its normal sees
none of the motion, for the MTF across the motion beside evaluate's f50_across. Both normals
lie 5 degrees off the pixel grid, so both see the pixel's aperture alike. Two MTF50s are measured: the noise-free
capture's, which holds the model's MTF (the physics of the image) to the e-SFR's own accuracy,
and the noisy captures', which is what a camera test at T_MPE would find: each capture's MTF50
scatters, and the first crossing of a noisy MTF curve lies early, so the noisy figure is the
e-SFR of the seeds' pooled images (their mean, whose noise is 1/sqrt(n) of one capture's), with
its standard error from the captures' own scatter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import api
from ..outputs import OUTPUT_DTYPES
from ..status import Status
from .camera import capture, picked_mode
from .charts import flat, slanted_edge
from .edge_sfr import esfr
from .flat_patch import snr

__all__ = ["Agreement", "agreement", "edge_chart", "across_edge_chart", "every_term_design",
           "longest_wavelength_um", "model_result", "EDGE_ROWS", "LONG_BLUR_ROWS", "FLAT_PX",
           "MIN_EDGE_SPAN", "DIFFRACTION_SPAN", "MAX_EDGE_COLUMNS", "EDGE_ANGLE_DEG",
           "ACROSS_EDGE_ANGLE_DEG", "ACROSS_MOTION_ANGLE_DEG"]

#: Rows of the edge chart: at 5 degrees the edge crosses 33 pixels over them, and each of the
#: e-SFR's quarter-pixel bins averages 96 rows' samples.
EDGE_ROWS = 384
#: Rows of the edge chart when the blur is long (the span over MIN_EDGE_SPAN): half as many
#: keep the fine grid within memory; a wide line spread needs fewer rows for the same noise.
LONG_BLUR_ROWS = 192
#: Pixels a side of the flat patch: the SNR of 16,384 pixels has a relative scatter of
#: 1/sqrt(2 n) = 0.55% (0.048 dB).
FLAT_PX = 128
#: Pixels along the edge's normal that every row holds, when the blur is short, and at least
#: DIFFRACTION_SPAN lambda F: they hold the line spread of diffraction and the pixel with its
#: tails, and ISO's Hamming window over them leaves a noise-free edge's MTF50 within 0.35% of
#: the infinite edge's (over 58 lambda F it bends it by 0.8%). A longer blur b (pixels) gets
#: 2 b + the span and no window: the box of the motion then lies whole inside the span, which
#: the window would bend by 0.76 (b / span)^2.
MIN_EDGE_SPAN = 128
DIFFRACTION_SPAN = 120.0
#: The widest edge chart: a longer blur is reported as not measured (NaN).
MAX_EDGE_COLUMNS = 16384
#: Degrees, the edge's slant (ISO 12233's about 5).
EDGE_ANGLE_DEG = 5.0
#: Degrees from the vertical, the near-horizontal edge that measures the MTF across the
#: motion: slanted 5 degrees off the horizontal, as the near-vertical edge is off the vertical.
ACROSS_EDGE_ANGLE_DEG = 90.0 - EDGE_ANGLE_DEG
#: Degrees from the rows, the motion's direction in the near-horizontal edge's capture:
#: parallel to that edge (:func:`epc_fast.simulate.capture`'s ``motion_angle_deg``), so the
#: motion moves the edge along itself and its normal, across the motion, sees none of it.
ACROSS_MOTION_ANGLE_DEG = 90.0 - ACROSS_EDGE_ANGLE_DEG


@dataclass(frozen=True)
class Agreement:
    """One design at one light level, the model beside the simulator.

    Attributes
    ----------
    illuminance_lux : lux.
    status : the model's :class:`Status` at this point.
    f50_model_cyc_per_mm : cycles/mm, evaluate's f50 (the MTF along the rows).
    f50_normal_cyc_per_mm : cycles/mm, evaluate's f50 with the motion the edge's normal sees
        (the shake times the cosine of the edge's slant): what the e-SFR, which measures across
        the edge, should find.
    f50_noiseless_cyc_per_mm : the e-SFR's MTF50 of the noise-free capture (of the seeds'
        noise-free captures' mean for a burst with alignment errors, which each seed draws).
    f50_sim_cyc_per_mm : the e-SFR's MTF50 of the seeds' pooled noisy captures.
    f50_sim_std : cycles/mm, the standard deviation of one noisy capture's MTF50.
    snr_db_model : dB, the target SNR evaluate meets at T_MPE.
    snr_db_sim, snr_db_std : dB, the SNR measured on the flat patch's captures, mean and
        standard deviation over the seeds.
    seeds : the number of captures.
    edge_shape : (rows, columns) of the edge chart; window: the e-SFR's window.
    epc_model : pixels, evaluate's EPC (as the design's ``epc_axes`` counts it); epc_sim:
        the same count of the simulated MTF50s on the same sensor area, 4 S f50_sim^2
        (``epc_axes="both"``: 4 S f50_sim f50_across_sim).
    f50_across_model_cyc_per_mm : cycles/mm, evaluate's f50_across (the MTF without the
        motion blur).
    f50_across_noiseless_cyc_per_mm, f50_across_sim_cyc_per_mm, f50_across_sim_std : the
        near-horizontal edge's MTF50s, measured as the near-vertical one's are (noise-free;
        the seeds' pooled noisy captures; one noisy capture's standard deviation).
    """

    illuminance_lux: float
    status: Status
    f50_model_cyc_per_mm: float
    f50_normal_cyc_per_mm: float
    f50_noiseless_cyc_per_mm: float
    f50_sim_cyc_per_mm: float
    f50_sim_std: float
    snr_db_model: float
    snr_db_sim: float
    snr_db_std: float
    seeds: int
    edge_shape: tuple
    window: str | None
    epc_model: float
    epc_sim: float
    f50_across_model_cyc_per_mm: float = math.nan
    f50_across_noiseless_cyc_per_mm: float = math.nan
    f50_across_sim_cyc_per_mm: float = math.nan
    f50_across_sim_std: float = math.nan

    @property
    def f50_sem(self) -> float:
        """cycles/mm, the standard error of the pooled MTF50: one capture's scatter over
        sqrt(seeds)."""
        return self.f50_sim_std / math.sqrt(self.seeds)

    @property
    def f50_across_sem(self) -> float:
        """cycles/mm, the standard error of the pooled MTF50 across the motion."""
        return self.f50_across_sim_std / math.sqrt(self.seeds)

    @property
    def snr_db_sem(self) -> float:
        """dB, the standard error of the simulated mean SNR."""
        return self.snr_db_std / math.sqrt(self.seeds)


def edge_chart(blur_mm: float, pitch_um: float, lambda_f_um: float, rows: int | None = None):
    """The slanted edge an e-SFR of this blur needs, and the window to measure it with:
    ((rows, columns), window); ``lambda_f_um`` the longest wavelength times the f-number,
    ``rows`` the chart's rows (default EDGE_ROWS, or LONG_BLUR_ROWS for a long blur)."""
    blur_px = blur_mm / (pitch_um * 1e-3)
    slope = math.tan(math.radians(EDGE_ANGLE_DEG))
    least = max(MIN_EDGE_SPAN, DIFFRACTION_SPAN * lambda_f_um / pitch_um)
    if 24.0 * blur_px <= least:
        default, span, window = EDGE_ROWS, least, "hamming"
    else:
        default, span, window = LONG_BLUR_ROWS, 2.0 * blur_px + least, None
    rows = default if rows is None else rows
    columns = int(math.ceil((rows * slope + span) / 2.0)) * 2
    return (rows, columns), window


def across_edge_chart(blur_mm: float, pitch_um: float, lambda_f_um: float,
                      run: int | None = None):
    """The near-horizontal edge (:data:`ACROSS_EDGE_ANGLE_DEG`) that measures the MTF across
    the motion, and the window to measure it with: ((rows, columns), window). The motion runs
    along the edge, so its normal sees only the lens, the pixel and jitter: the rows hold the
    span :func:`edge_chart` gives a design without motion, its columns are the edge's run,
    ``run`` (default EDGE_ROWS, or LONG_BLUR_ROWS for a blur :func:`edge_chart` calls long:
    the capture's grid reaches the blur's length beyond the chart either way)."""
    blur_px = blur_mm / (pitch_um * 1e-3)
    least = max(MIN_EDGE_SPAN, DIFFRACTION_SPAN * lambda_f_um / pitch_um)
    if run is None:
        run = EDGE_ROWS if 24.0 * blur_px <= least else LONG_BLUR_ROWS
    slope = math.tan(math.radians(EDGE_ANGLE_DEG))
    return (int(math.ceil((run * slope + least) / 2.0)) * 2, run), "hamming"


def model_result(illuminance_lux, invalid="raise", **design):
    """evaluate's :class:`~epc_fast.Result` for one design (``invalid`` as evaluate takes it),
    with f50_across beside its default outputs."""
    return api.evaluate(illuminance_lux, **design, invalid=invalid,
                        outputs=(*OUTPUT_DTYPES, "f50_across_cyc_per_mm"))


def every_term_design(rng: np.random.Generator, spectrum=None) -> tuple[dict, float]:
    """A random design with every term of docs/model.md's ideal sensor and lens on, and a light
    level for it: (design keywords, lux). ``spectrum`` (e.g. ``diffraction_spectrum(8)``)
    replaces the single wavelength. The agreement's tests and tools/simulate_agreement.py
    compare these."""
    design = dict(
        pixel_pitch_um=rng.uniform(0.8, 3.0), f_number=rng.uniform(1.8, 4.0),
        focal_length_mm=rng.uniform(4, 6), sensor_area_mm2=20.0,
        field_angle_deg=rng.uniform(0, 30), fill_factor=rng.uniform(0.5, 1.0),
        read_noise_e=rng.uniform(0, 3), dark_current_e_per_s=rng.uniform(0, 50),
        prnu=rng.uniform(0, 0.01), full_well_e=rng.uniform(8000, 20000),
        jitter_um=rng.uniform(0, 1.0), stabilization=rng.uniform(1, 4),
        lens_transmittance=rng.uniform(0.7, 1), reflectance=rng.uniform(0.2, 0.6),
        snr_db=rng.uniform(25, 35))
    design = {k: float(v) for k, v in design.items()}
    if spectrum is not None:
        design["spectrum"] = spectrum
    return design, float(10 ** rng.uniform(1.7, 4.7))


def longest_wavelength_um(design) -> float:
    """µm, the longest wavelength a design's keywords image (its spectrum's or wavelength_nm)."""
    spectrum = design.get("spectrum")
    if spectrum is None:
        return float(design.get("wavelength_nm", 550.0)) * 1e-3
    wavelengths = getattr(spectrum, "wavelengths_nm", None)
    return float(np.max(spectrum[0] if wavelengths is None else wavelengths)) * 1e-3


def agreement(illuminance_lux: float, *, seeds: int = 16, seed: int = 0, across: bool = True,
              **design) -> Agreement:
    """Compare the model with simulated captures of one design at one light level.

    Parameters
    ----------
    illuminance_lux : lux.
    seeds : int, >= 2: the noisy captures (the noise drawn anew each time, the expected image
        computed once).
    seed : int, the first seed; the captures use seed, seed + 1, ...
    across : bool, whether to capture and measure the edge across the motion too (its
        figures NaN without it); a design with ``epc_axes="both"`` always does, its
        ``epc_sim`` counts it.
    **design : the design's keywords of :func:`epc_fast.evaluate` (scalars). A design with
        ``modes`` is captured, and its edge sized and measured, in the mode the model picks.

    Returns
    -------
    Agreement
        The simulated figures are NaN where the model's status is not OK (there is no T_MPE
        to capture at) or the blur needs an edge chart wider than :data:`MAX_EDGE_COLUMNS`.
    """
    if isinstance(seeds, bool) or not isinstance(seeds, (int, np.integer)) or seeds < 2:
        raise ValueError(f"seeds: an integer >= 2 (the scatter needs two), got {seeds!r}")
    if not isinstance(across, (bool, np.bool_)):
        raise TypeError(f"across: True or False, got {across!r}")
    model = model_result(illuminance_lux, **design)
    status = Status(int(np.asarray(model.status)))
    shake = design.get("shake_deg_per_s", 4.39)
    normal = api.evaluate(illuminance_lux, **{
        **design, "shake_deg_per_s": shake * math.cos(math.radians(EDGE_ANGLE_DEG))})
    snr_target = float(design.get("snr_db", 30.0))
    f50_model, epc_model = float(model.f50_cyc_per_mm), float(model.epc)
    f50_across = float(model.f50_across_cyc_per_mm)
    both = design.get("epc_axes", "motion") == "both"
    counted = f50_model * (f50_across if both else f50_model)
    area_mm2 = epc_model / (4.0 * counted) if counted > 0 else math.nan
    shape, window = ((0, 0), None)
    if status == Status.OK:
        read = picked_mode(design, model)  # with modes: the mode the model picks
        output_pitch = float(read["pixel_pitch_um"]) * int(read.get("binning", 1))
        lambda_f = longest_wavelength_um(design) * float(design["f_number"])
        shape, window = edge_chart(float(model.blur_mm), output_pitch, lambda_f)
        across_shape, across_window = across_edge_chart(float(model.blur_mm), output_pitch,
                                                        lambda_f)
    if status != Status.OK or shape[1] > MAX_EDGE_COLUMNS:
        nan = math.nan
        return Agreement(float(illuminance_lux), status, f50_model,
                         float(normal.f50_cyc_per_mm), nan, nan, nan, snr_target, nan, nan,
                         int(seeds), shape, window, epc_model, nan, f50_across)
    edge = capture(slanted_edge(shape, EDGE_ANGLE_DEG), illuminance_lux=illuminance_lux,
                   seed=seed, **design)
    patch = capture(flat(FLAT_PX, design.get("reflectance", 0.4)),
                    illuminance_lux=illuminance_lux, seed=seed, **design)
    noiseless, pooled, std = _measured(edge, seed, seeds, window)
    across_noiseless = across_pooled = across_std = math.nan
    if across or both:
        edge_across = capture(slanted_edge(across_shape, ACROSS_EDGE_ANGLE_DEG),
                              illuminance_lux=illuminance_lux, seed=seed,
                              motion_angle_deg=ACROSS_MOTION_ANGLE_DEG, **design)
        across_noiseless, across_pooled, across_std = _measured(edge_across, seed, seeds,
                                                                across_window)
    snrs = [snr(patch.redraw(seed + i).image_e).snr_db for i in range(seeds)]
    counted_sim = pooled * (across_pooled if both else pooled)
    return Agreement(float(illuminance_lux), status, f50_model, float(normal.f50_cyc_per_mm),
                     noiseless, pooled, std, snr_target,
                     float(np.mean(snrs)), float(np.std(snrs, ddof=1)), int(seeds), shape,
                     window, epc_model, 4.0 * area_mm2 * counted_sim, f50_across,
                     across_noiseless, across_pooled, across_std)


def _measured(edge, seed: int, seeds: int, window) -> tuple:
    """cycles/mm: (the noise-free MTF50, the seeds' pooled noisy captures' MTF50, one noisy
    capture's standard deviation) of an edge's capture redrawn from seed, seed + 1, ..."""
    pitch = edge.pitch_um
    captures = [edge.redraw(seed + i) for i in range(seeds)]
    each = [esfr(c.image_e, pitch, window=window, bin_correction=True).mtf50_cyc_per_mm
            for c in captures]
    pooled = esfr(np.mean([c.image_e for c in captures], axis=0), pitch,
                  window=window, bin_correction=True).mtf50_cyc_per_mm
    # A burst's alignment errors are drawn with its noise: the noise-free image is then their
    # captures' mean expected image, the expectation over the alignment the model describes.
    expected = np.mean([c.expected_e for c in captures], axis=0)
    noiseless = esfr(expected, pitch, window=window, bin_correction=True).mtf50_cyc_per_mm
    return float(noiseless), float(pooled), float(np.std(each, ddof=1))
