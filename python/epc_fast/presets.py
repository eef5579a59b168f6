"""The paper's camera systems (docs/model.md, "The paper's systems") as plain data a user can
copy and change.

The preset reads the paper as docs/model.md, "The paper's systems" documents: the 30 dB target
met at the image corner (cos^4 falloff at half the diagonal field of view) and EPC taken over
the nominal sensor area of the format. This is a reading of the paper, not a fitted model; the
paper's literal 30 dB and 33 dB targets on the optical axis are the other :data:`READINGS`, one
``design.read_as("on_axis_33db")`` away. A design of your own is a :class:`Design` made from
its sensor's data sheet (docs/sensor.md); ``snr_at`` chooses where it meets the target.

>>> from epc_fast.presets import HIGH_TIER, evaluate_over_illuminance
>>> r = evaluate_over_illuminance(HIGH_TIER[3], [100.0, 1000.0, 10000.0])
>>> r.epc.shape
(3,)
"""

from __future__ import annotations

import numpy as np

from .api import Result, evaluate
from .design import (IS_FACTOR, PRESET_READING, READINGS, Design, Reading,  # noqa: F401
                     corner_field_angle_deg)

__all__ = [
    "Reading", "READINGS", "PRESET_READING", "Design", "IS_FACTOR", "HIGH_TIER", "LOW_TIER",
    "ZOOM_3X", "FIGURE_3", "PAPER_DESIGNS", "corner_field_angle_deg", "stack",
    "evaluate_over_illuminance",
]


def stack(designs) -> dict:
    """Keyword arguments for :func:`epc_fast.evaluate` holding several designs at once.

    Each value is a float64 array of shape (len(designs),), so the designs broadcast against
    anything shaped (..., len(designs)); add an axis (``[:, None]``) to put them on rows.
    """
    kwargs = [d.evaluate_kwargs() for d in designs]
    return {name: np.array([k[name] for k in kwargs], dtype=np.float64) for name in kwargs[0]}


def evaluate_over_illuminance(design, illuminance_lux, **options) -> Result:
    """EPC and its intermediates of one design, or several, over illuminance.

    Parameters
    ----------
    design : Design, sequence of Design, or dict
        A preset, several (one row each), or :func:`epc_fast.evaluate` keywords without the
        illuminance.
    illuminance_lux : array_like
        lux, 1-D or scalar.
    **options
        Further :func:`epc_fast.evaluate` keywords (``backend``, ``threads``, a parameter to
        override, ...).

    Returns
    -------
    Result
        Shaped like ``illuminance_lux`` for one design, (len(designs), len(illuminance_lux))
        for several.
    """
    lux = np.asarray(illuminance_lux, dtype=np.float64)
    if isinstance(design, Design):
        kwargs = design.evaluate_kwargs()
    elif isinstance(design, dict):
        kwargs = dict(design)
    else:
        kwargs = {name: v[:, None] for name, v in stack(design).items()}
        lux = lux.reshape(1, -1)
    return evaluate(lux, **{**kwargs, **options})


def _format(name, width_mm, height_mm, focal_mm, f_number, arrays):
    return tuple(Design(f'{name} {pitch} um', pitch, cols, rows, width_mm, height_mm, f_number,
                        focal_mm) for pitch, (cols, rows) in arrays)


#: 1/3.2" high tier: 4.57 x 3.43 mm, f = 5.6 mm, F/2.8.
HIGH_TIER = _format('1/3.2"', 4.57, 3.43, 5.6, 2.8, [
    (2.8, (1600, 1200)), (2.2, (2048, 1536)), (1.75, (2592, 1944)), (1.4, (3200, 2400))])
#: 1/8" low tier: 1.792 x 1.344 mm (640 x 480 at 2.8 um), f = 2.24 mm, F/2.8.
LOW_TIER = _format('1/8"', 1.792, 1.344, 2.24, 2.8, [
    (2.8, (640, 480)), (2.2, (800, 600)), (1.75, (1024, 768)), (1.4, (1280, 960))])
#: 3x zoom at its telephoto end: 1.75 um on the 1/3.2" format, f = 16.8 mm, F/4.9.
ZOOM_3X = Design('3x zoom 1.75 um', 1.75, 2592, 1944, 4.57, 3.43, 4.9, 16.8)
#: The paper's Figure 3: the 1/3.2" 1.75 um design normal, with 4x IS, zoomed, zoomed with IS.
FIGURE_3 = (HIGH_TIER[2], HIGH_TIER[2].stabilized(), ZOOM_3X, ZOOM_3X.stabilized())

PAPER_DESIGNS = HIGH_TIER + LOW_TIER + (ZOOM_3X,)
