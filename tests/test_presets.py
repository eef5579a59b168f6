"""The paper's designs as data (MODEL.md section 9)."""

import json
import math
from pathlib import Path

import pytest

from epc_fast.presets import HIGH_TIER, LOW_TIER, PAPER_DESIGNS, ZOOM_3X

GOLDEN = json.loads((Path(__file__).parent / "data" / "golden_public.json").read_text())


def _golden_angle(point_id):
    point = next(p for p in GOLDEN["points"] if p["id"] == point_id)
    return float(point["inputs"]["field_angle_deg"])


@pytest.mark.parametrize("design, point_id", [(HIGH_TIER[3], "P01"), (LOW_TIER[2], "P09"),
                                              (ZOOM_3X, "P11")])
def test_corner_field_angle_matches_the_golden_inputs(design, point_id):
    # The golden angles are atan(half-diagonal / focal) written to 30 digits; float64 atan
    # and hypot are good to a few ulp.
    assert design.field_angle_deg == pytest.approx(_golden_angle(point_id), rel=1e-14)


def test_paper_half_diagonal_field_of_view_is_54_and_19_3_degrees():
    # MODEL.md section 9: "54 deg normal, 19.3 deg zoom" (the paper's Table 1, full diagonal).
    assert 2 * HIGH_TIER[0].field_angle_deg == pytest.approx(54.0, abs=0.1)
    assert 2 * ZOOM_3X.field_angle_deg == pytest.approx(19.3, abs=0.05)


def test_arrays_fill_their_formats():
    for design in PAPER_DESIGNS:
        width = design.columns * design.pixel_pitch_um * 1e-3
        # The paper's arrays fill the nominal format to within 2%.
        assert width == pytest.approx(design.sensor_width_mm, rel=0.02), design.name


def test_designs_are_plain_data_that_can_be_changed():
    stabilised = ZOOM_3X.with_(stabilization=4.0)
    assert stabilised.stabilization == 4.0 and ZOOM_3X.stabilization == 1.0
    assert stabilised.evaluate_kwargs()["stabilization"] == 4.0
    assert math.isclose(HIGH_TIER[0].sensor_area_mm2, 15.6751)
