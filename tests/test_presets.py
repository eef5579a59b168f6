"""The paper's designs as data (docs/model.md, "The paper's systems")."""

import json
from pathlib import Path

import numpy as np
import pytest

import epc_fast
from epc_fast.presets import (FIGURE_3, HIGH_TIER, LOW_TIER, PAPER_DESIGNS, READINGS, ZOOM_3X,
                              evaluate_over_illuminance, stack)

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
    # docs/model.md, "The paper's systems": "54 deg normal, 19.3 deg zoom" (the paper's Table 1, full diagonal).
    assert 2 * HIGH_TIER[0].field_angle_deg == pytest.approx(54.0, abs=0.1)
    assert 2 * ZOOM_3X.field_angle_deg == pytest.approx(19.3, abs=0.05)


def test_arrays_fill_their_formats():
    for design in PAPER_DESIGNS:
        width = design.columns * design.pixel_pitch_um * 1e-3
        # The paper's arrays fill the nominal format to within 2%.
        assert width == pytest.approx(design.sensor_width_mm, rel=0.02), design.name


def test_a_designs_pixel_count_is_the_physical_one_the_figures_and_the_scans_draw():
    # One rule (docs/model.md, "EPC"): N = S / p^2, the sensor's area over the pitch squared,
    # for every preset: the same function and the same bits as the paper's figures and a
    # scan's bands. Columns x rows (1.92 Mpixel for the 2.8 um design) is the array, not N.
    from epc_fast import scan, sensor
    from epc_fast.plotting import common
    from epc_fast.scan.plot import scan_pixel_counts

    assert common.physical_pixel_count is sensor.physical_pixel_count
    designs = PAPER_DESIGNS + FIGURE_3[1::2]  # and the stabilised ones
    in_scan = scan_pixel_counts(scan.Space(design=list(designs),
                                           illuminance_lux=scan.LogUniform(10, 1e5)))
    for design in designs:
        count = sensor.physical_pixel_count(design.sensor_area_mm2, design.pixel_pitch_um)
        assert design.pixel_count == count == in_scan[design.name], design.name
        assert type(design.pixel_count) is float, design.name
    assert HIGH_TIER[0].pixel_count == pytest.approx(1_999_375.0, rel=1e-15)
    assert (HIGH_TIER[0].columns, HIGH_TIER[0].rows) == (1600, 1200)


def test_the_preset_reads_30_db_at_the_corner_and_the_literal_readings_on_axis():
    design = HIGH_TIER[3]
    assert (design.snr_db, design.field_angle_deg > 26.9) == (30.0, True)
    assert design.read_as("on_axis_30db").evaluate_kwargs()["field_angle_deg"] == 0.0
    assert design.read_as("on_axis_33db").evaluate_kwargs()["snr_db"] == 33.0
    assert set(READINGS) == {"corner_30db", "on_axis_30db", "on_axis_33db"}
    with pytest.raises(ValueError, match="reading"):
        design.read_as("at_the_centre")


def test_figure_3_is_the_1_75_um_design_normal_stabilised_zoomed_and_both():
    assert [d.name for d in FIGURE_3] == ['1/3.2" 1.75 um', '1/3.2" 1.75 um 4x IS',
                                          "3x zoom 1.75 um", "3x zoom 1.75 um 4x IS"]
    assert [d.stabilization for d in FIGURE_3] == [1.0, 4.0, 1.0, 4.0]
    assert len({d.pixel_count for d in FIGURE_3}) == 1


def test_evaluate_over_illuminance_gives_one_row_per_design():
    lux = np.array([100.0, 1000.0, 1e5])
    rows = evaluate_over_illuminance(HIGH_TIER, lux)
    assert rows.epc.shape == (4, 3)
    for design, row in zip(HIGH_TIER, rows.epc):
        # The same points, broadcast differently: the core is bit-identical across layouts.
        np.testing.assert_array_equal(row, evaluate_over_illuminance(design, lux).epc)
    as_dict = evaluate_over_illuminance(HIGH_TIER[0].evaluate_kwargs(), lux, backend="reference")
    np.testing.assert_allclose(as_dict.epc, rows.epc[0], rtol=1e-12)


def test_stacked_designs_are_evaluate_keywords_with_one_entry_per_design():
    kwargs = stack(HIGH_TIER)
    np.testing.assert_array_equal(kwargs["pixel_pitch_um"], [2.8, 2.2, 1.75, 1.4])
    assert epc_fast.evaluate(1000.0, **kwargs).epc.shape == (4,)
