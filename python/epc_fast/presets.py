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

import math
import numbers
from collections.abc import Mapping
from dataclasses import InitVar, asdict, dataclass, replace

import numpy as np

from .api import Result, evaluate
from .sensor import check_snr_at, physical_pixel_count, sensor_shape, snr_at_text
from .sensor import corner_field_angle_deg as _corner_angle

#: How a Design can be given its sensor, for error messages.
SIZE_WAYS_OF_DESIGN = ("sensor_width_mm and sensor_height_mm, or sensor_diagonal_mm and "
                       "aspect, or columns and rows")

__all__ = [
    "Reading", "READINGS", "PRESET_READING", "Design", "IS_FACTOR", "HIGH_TIER", "LOW_TIER",
    "ZOOM_3X", "FIGURE_3", "PAPER_DESIGNS", "corner_field_angle_deg", "stack",
    "evaluate_over_illuminance",
]


@dataclass(frozen=True)
class Reading:
    """How a design reads the paper's SNR target: its level and where it must be met.

    Attributes
    ----------
    name : str
    snr_db : dB, the target SNR.
    at_corner : bool, met at the image corner (cos^4 at half the diagonal field of view) rather
        than on the optical axis.
    meaning : str
    """

    name: str
    snr_db: float
    at_corner: bool
    meaning: str


#: The readings of the paper's SNR target, by name (docs/model.md, "The paper's systems").
READINGS = {r.name: r for r in (
    Reading("corner_30db", 30.0, True,
            "30 dB at the image corner (cos^4 falloff): the preset's reading of the paper"),
    Reading("on_axis_30db", 30.0, False, "30 dB on the optical axis: the paper's text, literally"),
    Reading("on_axis_33db", 33.0, False,
            "33 dB on the optical axis: the paper's Table 1, literally"),
)}
#: The reading the presets use unless told otherwise.
PRESET_READING = "corner_30db"
#: 1, the paper's image stabilisation: "4x IS" divides the motion by 4.
IS_FACTOR = 4.0
#: The sensor's and the readout's fields of a Design and evaluate's defaults for them.
_SENSOR_DEFAULTS = {"read_noise_e": 0.0, "dark_current_e_per_s": 0.0, "prnu": 0.0,
                    "full_well_e": math.inf, "fill_factor": 1.0, "binning": 1,
                    "binning_readout": "digital", "frames": 1, "alignment_error_um": 0.0}


def corner_field_angle_deg(width_mm: float, height_mm: float, focal_length_mm: float) -> float:
    """degree: half the diagonal field of view, atan(half-diagonal / focal length)."""
    return float(_corner_angle(width_mm, height_mm, focal_length_mm))


@dataclass(frozen=True)
class Design:
    """A camera design: everything :func:`epc_fast.evaluate` needs except the illuminance.

    Give the sensor as its data sheet does: ``sensor_width_mm`` and ``sensor_height_mm``, or
    ``sensor_diagonal_mm`` and ``aspect`` (e.g. ``"4:3"``), or the array (``columns`` and
    ``rows``, the sensor then being columns x rows pixels of ``pixel_pitch_um``)::

        Design("50 Mpx 1/1.56-inch", 1.0, sensor_diagonal_mm=10.24, aspect="4:3",
               f_number=1.9, focal_length_mm=5.7)

    EPC uses the sensor's area, width x height (docs/model.md, "EPC"), and so does the physical
    pixel count, :attr:`pixel_count` = area / pitch^2; the array, when not given, is the
    sensor's width and height over the pitch, each rounded to the nearest pixel.

    Attributes
    ----------
    name : str
    pixel_pitch_um : um, pixel pitch.
    columns, rows : pixels, the array (the paper's name for a design: 1600 x 1200); their
        product is not the physical pixel count, :attr:`pixel_count`.
    sensor_width_mm, sensor_height_mm : mm, the sensor's (nominal) format.
    f_number : 1.
    focal_length_mm : mm.
    stabilization : 1, image stabilisation factor k.
    reading : str, a key of :data:`READINGS`: the SNR target and, unless ``snr_at`` says
        otherwise, where it is met.
    snr_at : {"corner", "axis"} or float, optional
        Where the SNR target is met: the image corner, the optical axis, or a field angle in
        degrees. None (the default): where the reading says (the corner for the presets).
    sensor_diagonal_mm, aspect : mm and width:height, the format from its diagonal (used only
        when constructing; the width and height are kept).
    read_noise_e, dark_current_e_per_s, prnu, full_well_e, fill_factor : the sensor, as
        :func:`epc_fast.evaluate` takes them (defaults: the paper's ideal sensor).
    binning, binning_readout, frames, alignment_error_um : how the sensor is read
        (docs/model.md: binning k x k pixels as one, a burst of frames).
    modes : readout modes the camera picks from shot by shot, each a dict of ``binning``,
        ``binning_readout``, ``frames`` and ``alignment_error_um`` (:mod:`epc_fast.modes`);
        kept as tuples of (key, value) pairs so that a Design stays hashable.
    """

    name: str
    pixel_pitch_um: float
    columns: int | None = None
    rows: int | None = None
    sensor_width_mm: float | None = None
    sensor_height_mm: float | None = None
    f_number: float | None = None
    focal_length_mm: float | None = None
    stabilization: float = 1.0
    reading: str = PRESET_READING
    snr_at: str | float | None = None
    sensor_diagonal_mm: InitVar[float | None] = None
    aspect: InitVar[object] = None
    read_noise_e: float = 0.0
    dark_current_e_per_s: float = 0.0
    prnu: float = 0.0
    full_well_e: float = math.inf
    fill_factor: float = 1.0
    binning: int = 1
    binning_readout: str = "digital"
    frames: int = 1
    alignment_error_um: float = 0.0
    modes: tuple | None = None

    def __post_init__(self, sensor_diagonal_mm, aspect):
        if self.reading not in READINGS:
            raise ValueError(f"reading must be one of {', '.join(map(repr, READINGS))}; "
                             f"got {self.reading!r}")
        for name in ("pixel_pitch_um", "f_number", "focal_length_mm"):
            value = getattr(self, name)
            if value is None:
                raise TypeError(f"Design {self.name!r} needs {name}")
            if not (isinstance(value, numbers.Real) and math.isfinite(value) and value > 0):
                raise ValueError(f"Design {self.name!r}: {name}={value!r} must be a positive "
                                 "number")
        if isinstance(self.snr_at, str):
            check_snr_at(self.snr_at)
        elif self.snr_at is not None and not isinstance(self.snr_at, numbers.Real):
            raise ValueError(f"Design {self.name!r}: snr_at={self.snr_at!r}: expected 'corner', "
                             "'axis' or a field angle in degrees")
        self._set_format(sensor_diagonal_mm, aspect)
        if self.modes is not None:
            from .modes import check_modes

            modes = check_modes(self.modes if isinstance(self.modes, Mapping)
                                else [m if isinstance(m, Mapping) else dict(m)
                                      for m in self.modes])
            object.__setattr__(self, "modes", tuple(tuple(m.items()) for m in modes))

    def _set_format(self, sensor_diagonal_mm, aspect):
        """Fills in the format from the diagonal or the array, and the array from the format."""
        pitch_mm = self.pixel_pitch_um * 1e-3
        array = (self.columns, self.rows)
        if (array[0] is None) != (array[1] is None):
            raise TypeError(f"Design {self.name!r}: give both columns and rows, got "
                            f"columns={self.columns!r}, rows={self.rows!r}")
        size = {"sensor_width_mm": self.sensor_width_mm,
                "sensor_height_mm": self.sensor_height_mm,
                "sensor_diagonal_mm": sensor_diagonal_mm, "aspect": aspect}
        if all(v is None for v in size.values()):
            if array[0] is None:
                raise TypeError(f"Design {self.name!r} needs its sensor: {SIZE_WAYS_OF_DESIGN}")
            size = {"sensor_width_mm": self.columns * pitch_mm,
                    "sensor_height_mm": self.rows * pitch_mm}
        try:
            width, height = (float(v) for v in sensor_shape(**size))
        except TypeError as error:
            raise TypeError(f"Design {self.name!r}: {error}") from None
        if not (math.isfinite(width * height) and width > 0 and height > 0):
            raise ValueError(f"Design {self.name!r}: the sensor's width and height must be "
                             f"positive, got {width!r} x {height!r} mm")
        object.__setattr__(self, "sensor_width_mm", width)
        object.__setattr__(self, "sensor_height_mm", height)
        if array[0] is None:
            object.__setattr__(self, "columns", round(width / pitch_mm))
            object.__setattr__(self, "rows", round(height / pitch_mm))

    @property
    def pixel_count(self) -> float:
        """pixels: the physical pixel count N = S / p², the sensor's area over the pitch squared
        (:func:`epc_fast.sensor.physical_pixel_count`, docs/model.md, "EPC"), unrounded: the N
        of EPC = N (f50 / f_Nyq)², the paper's figures' dotted lines and a scan's, and what the
        paper's kept fractions divide by. Not ``columns * rows``: a preset's array is a little
        smaller than its format (1600 x 1200 = 1.92 Mpixel against 2.00 Mpixel for the 1/3.2"
        2.8 um design)."""
        return physical_pixel_count(self.sensor_area_mm2, self.pixel_pitch_um)

    @property
    def sensor_area_mm2(self) -> float:
        """mm^2: the format's nominal area."""
        return self.sensor_width_mm * self.sensor_height_mm

    @property
    def diagonal_field_of_view_deg(self) -> float:
        """degree: the full diagonal field of view, twice the corner's field angle."""
        return 2.0 * corner_field_angle_deg(self.sensor_width_mm, self.sensor_height_mm,
                                            self.focal_length_mm)

    @property
    def where_snr_is_met(self) -> str:
        """"corner", "axis" or "angle": where the SNR target is met."""
        if self.snr_at is None:
            return "corner" if READINGS[self.reading].at_corner else "axis"
        return self.snr_at if isinstance(self.snr_at, str) else "angle"

    @property
    def field_angle_deg(self) -> float:
        """degree: where the SNR target is met: the image corner's field angle, 0 on the axis,
        or the design's ``snr_at`` angle."""
        where = self.where_snr_is_met
        if where == "angle":
            return float(self.snr_at)
        if where == "axis":
            return 0.0
        return corner_field_angle_deg(self.sensor_width_mm, self.sensor_height_mm,
                                      self.focal_length_mm)

    @property
    def snr_at_text(self) -> str:
        """Where the SNR target is met, for people: ``"corner (27.03 deg)"``, ``"axis"``;
        marked "(default)" when it is the preset reading's and nobody chose it."""
        where = self.where_snr_is_met
        default = self.snr_at is None and self.reading == PRESET_READING
        return snr_at_text(None if where == "angle" else where, self.field_angle_deg, default)

    @property
    def snr_db(self) -> float:
        """dB: the target SNR of the design's reading."""
        return READINGS[self.reading].snr_db

    def evaluate_kwargs(self) -> dict:
        """Keyword arguments for :func:`epc_fast.evaluate` (all but the illuminance); the
        sensor's and the readout's only where they differ from evaluate's defaults, and the
        modes as a list of dicts."""
        kwargs = {
            "pixel_pitch_um": self.pixel_pitch_um, "f_number": self.f_number,
            "focal_length_mm": self.focal_length_mm, "sensor_area_mm2": self.sensor_area_mm2,
            "field_angle_deg": self.field_angle_deg, "snr_db": self.snr_db,
            "stabilization": self.stabilization,
        }
        for name, default in _SENSOR_DEFAULTS.items():
            value = getattr(self, name)
            if value != default:
                kwargs[name] = value
        if self.modes is not None:
            kwargs["modes"] = [dict(m) for m in self.modes]
        return kwargs

    def with_(self, **changes) -> "Design":
        """A copy with some fields changed (a new pitch keeps the format and the array)."""
        return replace(self, **changes)

    def read_as(self, reading: str) -> "Design":
        """The same design under another reading of the paper (a key of :data:`READINGS`)."""
        return self.with_(reading=reading)

    def stabilized(self, factor: float = IS_FACTOR) -> "Design":
        """The design with image stabilisation: motion divided by ``factor`` (1)."""
        return self.with_(name=f"{self.name} {factor:g}x IS", stabilization=factor)

    def as_dict(self) -> dict:
        return asdict(self)


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
