"""The paper's camera systems (MODEL.md section 9) as plain data a user can copy and change.

The preset reads the paper as MODEL.md section 9 documents: the 30 dB target met at the image
corner (cos^4 falloff at half the diagonal field of view) and EPC taken over the nominal sensor
area of the format. This is a reading of the paper, not a fitted model.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

__all__ = ["Design", "HIGH_TIER", "LOW_TIER", "ZOOM_3X", "PAPER_DESIGNS", "corner_field_angle_deg"]


def corner_field_angle_deg(width_mm: float, height_mm: float, focal_length_mm: float) -> float:
    """degree: half the diagonal field of view, atan(half-diagonal / focal length)."""
    return math.degrees(math.atan(math.hypot(width_mm, height_mm) / 2.0 / focal_length_mm))


@dataclass(frozen=True)
class Design:
    """A camera design: everything :func:`epc_fast.evaluate` needs except the illuminance.

    Attributes
    ----------
    name : str
    pixel_pitch_um : um, pixel pitch.
    columns, rows : pixels, the array.
    sensor_width_mm, sensor_height_mm : mm, the nominal format.
    f_number : 1.
    focal_length_mm : mm.
    stabilization : 1, image stabilisation factor k.
    """

    name: str
    pixel_pitch_um: float
    columns: int
    rows: int
    sensor_width_mm: float
    sensor_height_mm: float
    f_number: float
    focal_length_mm: float
    stabilization: float = 1.0

    @property
    def pixel_count(self) -> int:
        """pixels: columns x rows."""
        return self.columns * self.rows

    @property
    def sensor_area_mm2(self) -> float:
        """mm^2: the format's nominal area."""
        return self.sensor_width_mm * self.sensor_height_mm

    @property
    def field_angle_deg(self) -> float:
        """degree: the image corner, where the preset requires the SNR target."""
        return corner_field_angle_deg(self.sensor_width_mm, self.sensor_height_mm,
                                      self.focal_length_mm)

    def evaluate_kwargs(self) -> dict:
        """Keyword arguments for :func:`epc_fast.evaluate` (all but the illuminance)."""
        return {
            "pixel_pitch_um": self.pixel_pitch_um, "f_number": self.f_number,
            "focal_length_mm": self.focal_length_mm, "sensor_area_mm2": self.sensor_area_mm2,
            "field_angle_deg": self.field_angle_deg, "stabilization": self.stabilization,
        }

    def with_(self, **changes) -> "Design":
        """A copy with some fields changed."""
        return replace(self, **changes)

    def as_dict(self) -> dict:
        return asdict(self)


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

PAPER_DESIGNS = HIGH_TIER + LOW_TIER + (ZOOM_3X,)
