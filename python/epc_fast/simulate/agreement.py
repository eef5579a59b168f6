"""The model against the simulator: a design's f50 and target SNR from ``evaluate`` beside the
MTF50 (ISO 12233 e-SFR) and the SNR measured on its simulated captures, repeated over seeds.

The edge chart is sized to the blur: the e-SFR's window and the chart's width must hold the
line spread many times over, or the measurement, not the model, sets the answer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import api
from ..status import Status
from .camera import capture
from .charts import flat, slanted_edge
from .edge_sfr import esfr
from .flat_patch import snr

__all__ = ["Agreement", "agreement", "EDGE_ROWS", "FLAT_PX", "EDGE_SPAN", "MAX_EDGE_COLUMNS",
           "EDGE_ANGLE_DEG", "MIN_EDGE_SPAN"]

#: Rows of the edge chart: at 5 degrees the edge crosses 33 pixels over them, and each of the
#: e-SFR's quarter-pixel bins averages 96 rows' samples, which keeps one capture's MTF50
#: scatter near 1.5% at the target SNR of 30 dB (its noise, not the model, sets that).
EDGE_ROWS = 384
#: Pixels a side of the flat patch: the SNR of 16,384 pixels has a relative scatter of
#: 1/sqrt(2 n) = 0.55% (0.048 dB).
FLAT_PX = 128
#: The span along the edge's normal that every row holds, in pixels of blur, at least
#: MIN_EDGE_SPAN: the e-SFR's Hamming window as wide as the span then leaves the box of the
#: motion within 0.2% of its MTF50. The chart has that many columns more than the edge
#: crosses over its rows.
EDGE_SPAN = 24
#: Pixels, the narrowest span: 64 hold the line spread of diffraction and the pixel (every
#: column adds noise to the e-SFR, so no more than the spread needs).
MIN_EDGE_SPAN = 64
#: The widest edge chart: a longer blur is reported as not measured (NaN).
MAX_EDGE_COLUMNS = 16384
#: Degrees, the edge's slant (ISO 12233's about 5).
EDGE_ANGLE_DEG = 5.0


@dataclass(frozen=True)
class Agreement:
    """One design at one light level, the model beside the simulator.

    Attributes
    ----------
    illuminance_lux : lux.
    status : the model's :class:`Status` at this point.
    f50_model_cyc_per_mm : cycles/mm, evaluate's f50 (MTF along the rows).
    f50_normal_cyc_per_mm : cycles/mm, evaluate's f50 with the motion the edge's normal sees
        (the shake times cos of the edge's slant): what the e-SFR, which measures across the
        edge, should find.
    f50_sim_cyc_per_mm, f50_sim_std : the e-SFR's MTF50 over the seeds' captures, their mean
        and standard deviation.
    f50_noiseless_cyc_per_mm : the e-SFR's MTF50 of the expected (noise-free) capture.
    snr_db_model : dB, the target SNR evaluate meets at T_MPE.
    snr_db_sim, snr_db_std : dB, the SNR measured on the flat patch's captures, mean and
        standard deviation over the seeds.
    seeds : the number of captures each mean is over.
    edge_columns : the edge chart's width, pixels.
    """

    illuminance_lux: float
    status: Status
    f50_model_cyc_per_mm: float
    f50_normal_cyc_per_mm: float
    f50_sim_cyc_per_mm: float
    f50_sim_std: float
    f50_noiseless_cyc_per_mm: float
    snr_db_model: float
    snr_db_sim: float
    snr_db_std: float
    seeds: int
    edge_columns: int

    @property
    def f50_sem(self) -> float:
        """cycles/mm, the standard error of the simulated mean MTF50."""
        return self.f50_sim_std / math.sqrt(self.seeds)

    @property
    def snr_db_sem(self) -> float:
        """dB, the standard error of the simulated mean SNR."""
        return self.snr_db_std / math.sqrt(self.seeds)


def _edge_columns(blur_mm: float, pitch_um: float) -> int:
    blur_px = blur_mm / (pitch_um * 1e-3)
    crossed = EDGE_ROWS * math.tan(math.radians(EDGE_ANGLE_DEG))
    span = max(MIN_EDGE_SPAN, EDGE_SPAN * blur_px)
    return int(math.ceil((crossed + span) / 2.0)) * 2


def agreement(illuminance_lux: float, *, seeds: int = 8, seed: int = 0, **design) -> Agreement:
    """Compare the model with simulated captures of one design at one light level.

    Parameters
    ----------
    illuminance_lux : lux.
    seeds : int, the captures each simulated figure is the mean of (the noise drawn anew,
        the expected image computed once).
    seed : int, the first seed; the captures use seed, seed + 1, ...
    **design : the design's keywords of :func:`epc_fast.evaluate` (scalars).

    Returns
    -------
    Agreement
        The simulated figures are NaN where the model's status is not OK (there is no T_MPE
        to capture at) or the blur needs an edge chart wider than :data:`MAX_EDGE_COLUMNS`.
    """
    if isinstance(seeds, bool) or not isinstance(seeds, (int, np.integer)) or seeds < 2:
        raise ValueError(f"seeds: an integer >= 2 (the scatter needs two), got {seeds!r}")
    model = api.evaluate(illuminance_lux, **design)
    status = Status(int(np.asarray(model.status)))
    shake = design.get("shake_deg_per_s", 4.39)
    normal = api.evaluate(illuminance_lux, **{
        **design, "shake_deg_per_s": shake * math.cos(math.radians(EDGE_ANGLE_DEG))})
    snr_target = float(design.get("snr_db", 30.0))
    nan = math.nan
    columns = (_edge_columns(float(model.blur_mm), float(design["pixel_pitch_um"]))
               if status == Status.OK else 0)
    if status != Status.OK or columns > MAX_EDGE_COLUMNS:
        return Agreement(float(illuminance_lux), status, float(model.f50_cyc_per_mm),
                         float(normal.f50_cyc_per_mm), nan, nan, nan, snr_target, nan, nan,
                         int(seeds), columns)
    edge = capture(slanted_edge((EDGE_ROWS, columns), EDGE_ANGLE_DEG),
                   illuminance_lux=illuminance_lux, seed=seed, **design)
    patch = capture(flat(FLAT_PX, design.get("reflectance", 0.4)),
                    illuminance_lux=illuminance_lux, seed=seed, **design)
    pitch = edge.pitch_um
    f50s = [esfr(edge.redraw(seed + i).image_e, pitch).mtf50_cyc_per_mm for i in range(seeds)]
    snrs = [snr(patch.redraw(seed + i).image_e).snr_db for i in range(seeds)]
    noiseless = esfr(edge.expected_e, pitch).mtf50_cyc_per_mm
    return Agreement(float(illuminance_lux), status, float(model.f50_cyc_per_mm),
                     float(normal.f50_cyc_per_mm), float(np.mean(f50s)),
                     float(np.std(f50s, ddof=1)), float(noiseless), snr_target,
                     float(np.mean(snrs)), float(np.std(snrs, ddof=1)), int(seeds), columns)
