"""The paper's statements (docs/model.md, "The paper's systems") held against the preset.

Each statement is computed once per backend through epc_fast.paper (the inverse solvers for
crossings and light levels, epc_fast.evaluate for kept fractions; the ``table`` fixture of
conftest.py), and the crossings are checked a second time through epc_fast.evaluate alone.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import epc_fast
from epc_fast.paper import CLAIMS, KINDS, PAPER_LUX_RANGE, VGA_PIXELS
from epc_fast.presets import HIGH_TIER

CROSSOVERS = {"crossover_1.4_1.75": (HIGH_TIER[3], HIGH_TIER[2], 7500.0),
              "crossover_1.4_2.2": (HIGH_TIER[3], HIGH_TIER[1], 5500.0),
              "crossover_1.4_2.8": (HIGH_TIER[3], HIGH_TIER[0], 4000.0)}
SECTION_9 = ("rayleigh_f2.8", "rayleigh_f4.9", *CROSSOVERS, "fraction_1.4_100klux", "vga_1.4")


@pytest.mark.parametrize("statement_id", SECTION_9)
def test_every_statement_of_model_md_section_9_holds_for_the_preset(table, statement_id):
    s = table[statement_id]
    assert s.kind == "paper"
    assert s.holds, f"{s.text}: preset {s.preset_value:.6g}, paper {s.paper_value:g}"


@pytest.mark.parametrize("statement_id", list(CROSSOVERS))
def test_the_crossovers_hold_through_evaluate_alone(statement_id):
    # "Below about L_paper, within 10%": at 0.9 L_paper the 1.4 um design is behind, at 1.1
    # L_paper ahead.
    small, big, paper_lux = CROSSOVERS[statement_id]
    lux = np.array([0.9, 1.1]) * paper_lux
    small_epc = epc_fast.evaluate(lux, **small.evaluate_kwargs()).epc
    big_epc = epc_fast.evaluate(lux, **big.evaluate_kwargs()).epc
    assert small_epc[0] < big_epc[0] and small_epc[1] > big_epc[1]


def test_below_1000_lux_the_1_4_um_design_is_under_vga_through_evaluate_alone():
    lux = np.geomspace(PAPER_LUX_RANGE[0], 1000.0, 50)
    assert (epc_fast.evaluate(lux, **HIGH_TIER[3].evaluate_kwargs()).epc < VGA_PIXELS).all()


def test_the_crossings_found_are_where_the_two_designs_have_equal_epc(table):
    for statement_id, (small, big, _) in CROSSOVERS.items():
        lux = table[statement_id].preset_value
        pair = [epc_fast.evaluate(lux, **d.evaluate_kwargs()).epc for d in (small, big)]
        # Both solvers resolve ln L to ~1e-13, and EPC moves ~1x as fast as L there.
        assert pair[0] == pytest.approx(pair[1], rel=1e-10), statement_id


@pytest.mark.parametrize("reading", ["on_axis_30db_value", "on_axis_33db_value"])
def test_the_literal_readings_miss_every_crossover_by_about_30_percent(table, reading):
    # docs/model.md, "The paper's systems": "every crossover comes out about 30% off" (30 dB on
    # axis: ~35% low, 33 dB: ~30% high). 25-40% is "about 30%".
    for statement_id in CROSSOVERS:
        deviation = getattr(table[statement_id], reading) / table[statement_id].paper_value - 1
        assert 0.25 <= abs(deviation) <= 0.40, (statement_id, deviation)


def test_the_2_8_um_design_keeps_about_76_percent_a_known_limit(table):
    # docs/model.md: the paper says more than 93%, "this model gives about 76% of N = S/p²"
    # (79% of its 1600 x 1200 array).
    s = table["fraction_2.8_100klux"]
    assert s.kind == "known limit"
    assert s.preset_value == pytest.approx(0.758, abs=0.0005)
    assert s.preset_value * HIGH_TIER[0].pixel_count / (1600 * 1200) == pytest.approx(
        0.789, abs=0.0005)
    assert s.holds is False


def test_a_kept_fraction_is_epc_over_the_physical_pixel_count_area_over_pitch_squared(table):
    # One rule (docs/model.md, "EPC"): the paper's kept fractions divide by N = S / p², the
    # count the figures draw, not by the array's columns x rows (0.3808 for 1.4 um with it).
    from epc_fast.sensor import physical_pixel_count

    for sid, design in (("fraction_1.4_100klux", HIGH_TIER[3]),
                        ("fraction_2.8_100klux", HIGH_TIER[0])):
        epc = epc_fast.evaluate(1e5, **design.evaluate_kwargs()).epc
        count = physical_pixel_count(design.sensor_area_mm2, design.pixel_pitch_um)
        assert table[sid].preset_value == pytest.approx(epc / count, rel=1e-9), sid
    s = table["fraction_1.4_100klux"]
    assert s.preset_value == pytest.approx(0.3657, abs=5e-5) and s.holds is True


def test_image_stabilisation_is_worth_exactly_its_factor_in_light(table):
    s = table["is_4x_light"]
    assert s.holds and s.preset_value == pytest.approx(4.0, rel=1e-9)


def test_the_preset_reproduces_table_1s_fields_of_view(table):
    assert table["fov_normal"].holds and table["fov_zoom"].holds


def test_every_claim_has_a_known_kind_and_model_only_claims_have_no_paper_value(table):
    for s in table.values():
        assert s.kind in KINDS
        assert math.isnan(s.paper_value) == (s.kind == "model only"), s.id
        assert (s.holds is None) == (s.kind == "model only"), s.id
    assert len(table) == len(CLAIMS) == len({c.id for c in CLAIMS})


def test_every_model_only_value_exists_under_every_reading(table):
    for s in table.values():
        values = (s.preset_value, s.on_axis_30db_value, s.on_axis_33db_value)
        assert all(math.isfinite(v) and v > 0 for v in values), s.id
