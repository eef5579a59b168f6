"""A sensor from its data sheet (width and height, or diagonal and aspect) and where the SNR
target is met (snr_at), in evaluate, Design, the scan's space and its TOML config."""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, evaluate
from epc_fast.presets import HIGH_TIER, ZOOM_3X, Design
from epc_fast.scan import LogUniform, Space
from epc_fast.scan.config import parse_config
from epc_fast.jobs.errors import ConfigError
from epc_fast.sensor import aspect_ratio, corner_field_angle_deg, design_parameters

BACKENDS = ("core", "reference")
LENS = dict(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6)
#: A 50 Mpixel 1/1.56" sensor's data sheet: 8192 x 6144 pixels of 1.0 um, so 8.192 x 6.144 mm.
PHONE = dict(pixel_pitch_um=1.0, f_number=1.88, focal_length_mm=5.7)


@pytest.mark.parametrize("backend", BACKENDS)
def test_width_and_height_are_the_area_they_span(backend):
    lux = np.geomspace(10.0, 1e5, 7)
    by_sides = evaluate(lux, **LENS, sensor_width_mm=4.57, sensor_height_mm=3.43,
                        backend=backend)
    by_area = evaluate(lux, **LENS, sensor_area_mm2=4.57 * 3.43, backend=backend)
    for name, value in by_sides.as_dict().items():
        assert np.array_equal(value, getattr(by_area, name), equal_nan=True), name


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_diagonal_and_an_aspect_ratio_give_the_sides_of_a_3_4_5_triangle(backend):
    by_diagonal = evaluate(1000.0, **PHONE, sensor_diagonal_mm=10.24, aspect="4:3",
                           backend=backend)
    by_sides = evaluate(1000.0, **PHONE, sensor_width_mm=8.192, sensor_height_mm=6.144,
                        backend=backend)
    # 10.24 x 4/5 and x 3/5 round differently from the decimal sides: a few ulps of the area.
    assert by_diagonal.epc == pytest.approx(by_sides.epc, rel=1e-14)


def test_pixel_count_is_the_area_over_the_pitch_squared_unrounded():
    # S = N p^2: a 4.57 x 3.43 mm sensor of 1.4 um pixels holds 7,997,806.1... pixels.
    n = 4.57 * 3.43 / (1.4e-3) ** 2
    by_count = evaluate(1000.0, **LENS, pixel_count=n, backend="reference")
    by_sides = evaluate(1000.0, **LENS, sensor_width_mm=4.57, sensor_height_mm=3.43,
                        backend="reference")
    assert by_count.epc == pytest.approx(by_sides.epc, rel=1e-15)


@pytest.mark.parametrize("text, ratio", [("4:3", 4 / 3), ("16/9", 16 / 9), ((3, 2), 1.5),
                                         (1.25, 1.25), ("1:1", 1.0), ("4x3", 4 / 3)])
def test_aspect_ratios_are_read_in_their_usual_spellings(text, ratio):
    assert aspect_ratio(text) == pytest.approx(ratio, rel=1e-15)


@pytest.mark.parametrize("bad", ["4:0", "wide", "4:3:2", -1.0, 0, (4, 0), None, True])
def test_a_bad_aspect_ratio_names_aspect_and_its_value(bad):
    with pytest.raises(ValueError, match=r"aspect=.*expected width:height"):
        aspect_ratio(bad)


@pytest.mark.parametrize("given", [
    dict(sensor_width_mm=4.57),
    dict(sensor_diagonal_mm=5.71),
    dict(aspect="4:3", sensor_width_mm=4.57),
    dict(sensor_width_mm=4.57, sensor_height_mm=3.43, pixel_count=8e6),
    dict(sensor_width_mm=4.57, sensor_height_mm=3.43, sensor_diagonal_mm=5.71, aspect="4:3"),
    dict(sensor_area_mm2=15.7, sensor_diagonal_mm=5.71, aspect="4:3"),
])
def test_an_incomplete_or_conflicting_sensor_is_one_error_naming_what_was_given(given):
    with pytest.raises(TypeError, match="give the sensor's size one way") as error:
        evaluate(1000.0, **LENS, **given)
    message = str(error.value)
    for name, value in given.items():
        assert f"{name}={value!r}" in message


def test_sensor_lengths_outside_their_domain_are_invalid_points_or_a_named_error():
    widths = np.array([4.57, -4.57, 0.0, np.nan])
    r = evaluate(1000.0, **LENS, sensor_width_mm=widths, sensor_height_mm=-3.43 * np.sign(
        widths + 10))
    assert list(r.status) == [Status.INVALID] * 4  # negative height everywhere
    r = evaluate(1000.0, **LENS, sensor_width_mm=widths, sensor_height_mm=3.43)
    assert list(r.status) == [Status.OK] + [Status.INVALID] * 3
    with pytest.raises(ValueError, match=r"sensor_width_mm=-4\.57.*at index \(1,\)"):
        evaluate(1000.0, **LENS, sensor_width_mm=widths, sensor_height_mm=3.43,
                 invalid="raise")
    with pytest.raises(TypeError, match="sensor_width_mm must be a number"):
        evaluate(1000.0, **LENS, sensor_width_mm="wide", sensor_height_mm=3.43)


def test_the_corner_of_the_papers_1_3_2_inch_designs_is_27_03_degrees():
    # atan(hypot(4.57, 3.43) / 2 / 5.6) = atan(0.51015...) = 27.0297 degrees; the zoom's
    # 16.8 mm focal length gives 9.667 degrees (docs/model.md, "The paper's systems": 54 and 19.3 degree fields).
    assert corner_field_angle_deg(4.57, 3.43, 5.6) == pytest.approx(
        math.degrees(math.atan(math.hypot(4.57, 3.43) / 11.2)), rel=1e-15)
    assert round(corner_field_angle_deg(4.57, 3.43, 5.6), 2) == 27.03
    assert round(2 * corner_field_angle_deg(4.57, 3.43, 16.8), 1) == 19.3
    for design in HIGH_TIER + (ZOOM_3X,):
        assert design.field_angle_deg == corner_field_angle_deg(4.57, 3.43,
                                                                design.focal_length_mm)


@pytest.mark.parametrize("backend", BACKENDS)
def test_snr_at_the_corner_is_what_the_presets_evaluate(backend):
    lux = np.geomspace(10.0, 1e5, 9)
    for design in HIGH_TIER:
        preset = evaluate(lux, **design.evaluate_kwargs(), backend=backend)
        named = evaluate(lux, pixel_pitch_um=design.pixel_pitch_um, f_number=2.8,
                         focal_length_mm=5.6, sensor_width_mm=4.57, sensor_height_mm=3.43,
                         snr_at="corner", backend=backend)
        assert np.array_equal(preset.epc, named.epc)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_corner_needs_one_over_cos4_the_exposure_of_the_axis(backend):
    # Shot noise only: T_MPE = 10^(SNR/10) / r and r is proportional to cos^4(theta).
    sides = dict(sensor_width_mm=4.57, sensor_height_mm=3.43)
    axis = evaluate(1000.0, **LENS, **sides, snr_at="axis", backend=backend)
    corner = evaluate(1000.0, **LENS, **sides, snr_at="corner", backend=backend)
    cos4 = math.cos(math.radians(corner_field_angle_deg(4.57, 3.43, 5.6))) ** 4
    assert corner.t_mpe_s * cos4 == pytest.approx(axis.t_mpe_s, rel=1e-13)
    assert axis.epc == evaluate(1000.0, **LENS, **sides, backend=backend).epc
    assert corner.epc < axis.epc


def test_snr_at_is_checked_and_is_not_given_with_a_field_angle():
    with pytest.raises(TypeError, match=r"snr_at or field_angle_deg.*'corner'.*12\.0"):
        evaluate(1000.0, **LENS, sensor_area_mm2=15.0, snr_at="corner", field_angle_deg=12.0)
    with pytest.raises(ValueError, match=r"snr_at='edge': expected one of 'axis', 'corner'"):
        evaluate(1000.0, **LENS, sensor_area_mm2=15.0, snr_at="edge")
    with pytest.raises(TypeError, match=r"snr_at='corner' needs the sensor's diagonal"):
        evaluate(1000.0, **LENS, sensor_area_mm2=15.0, snr_at="corner")
    assert evaluate(1000.0, **LENS, sensor_area_mm2=15.0, snr_at="axis").epc == evaluate(
        1000.0, **LENS, sensor_area_mm2=15.0).epc


def test_a_design_from_a_data_sheet_fills_in_its_array_and_meets_the_target_at_the_corner():
    d = Design("phone", 1.0, sensor_diagonal_mm=10.24, aspect="4:3", f_number=1.88,
               focal_length_mm=5.7)
    assert (d.columns, d.rows) == (8192, 6144)
    # The physical pixel count is the area over the pitch squared, unrounded (docs/model.md).
    assert d.pixel_count == d.sensor_area_mm2 * 1e6 == pytest.approx(50_331_648, rel=1e-15)
    assert d.sensor_width_mm == pytest.approx(8.192, rel=1e-15)
    assert d.sensor_height_mm == pytest.approx(6.144, rel=1e-15)
    angle = math.degrees(math.atan(5.12 / 5.7))
    assert d.field_angle_deg == pytest.approx(angle, rel=1e-15)
    assert d.snr_at_text == f"corner ({angle:.2f} deg, default)"
    assert d.with_(snr_at="axis").field_angle_deg == 0.0
    assert d.with_(snr_at=20.0).snr_at_text == "field angle 20 deg"
    by_sides = Design("phone", 1.0, sensor_width_mm=8.192, sensor_height_mm=6.144,
                      f_number=1.88, focal_length_mm=5.7)
    assert by_sides.evaluate_kwargs() == pytest.approx(d.evaluate_kwargs(), rel=1e-14)
    # The preset's positional form still works: the array with its nominal format.
    assert Design("x", 2.8, 1600, 1200, 4.57, 3.43, 2.8, 5.6) == HIGH_TIER[0].with_(name="x")


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(sensor_width_mm=4.0), TypeError, "sensor_width_mm=4.0"),
    (dict(), TypeError, "needs its sensor"),
    (dict(columns=100), TypeError, "both columns and rows"),
    (dict(sensor_width_mm=4.0, sensor_height_mm=-3.0), ValueError, "must be positive"),
    (dict(sensor_width_mm=4.0, sensor_height_mm=3.0, snr_at="edge"), ValueError, "snr_at='edge'"),
])
def test_a_design_with_a_bad_sensor_names_the_design_and_the_arguments(kwargs, error, message):
    with pytest.raises(error, match=message):
        Design("mine", 1.0, f_number=2.0, focal_length_mm=4.0, **kwargs)


def test_custom_designs_meet_the_target_at_the_corner_when_their_shape_is_known():
    kwargs, where = design_parameters({**PHONE, "sensor_width_mm": 8.192,
                                       "sensor_height_mm": 6.144})
    assert kwargs["sensor_area_mm2"] == 8.192 * 6.144
    assert where == f"corner ({kwargs['field_angle_deg']:.2f} deg, default)"
    assert design_parameters({**PHONE, "sensor_area_mm2": 50.0}) == (
        {**PHONE, "sensor_area_mm2": 50.0}, "axis (default)")
    assert design_parameters({**PHONE, "sensor_area_mm2": 50.0, "field_angle_deg": 10.0})[1] \
        == "field angle 10 deg"


def test_the_printed_space_names_each_designs_target_and_the_defaults():
    space = Space(design=list(HIGH_TIER[:2]) + [{**PHONE, "name": "phone",
                                                  "sensor_area_mm2": 50.0}],
                  illuminance_lux=LogUniform(10.0, 1e5))
    text = space.describe()
    assert '1/3.2" 2.8 um: SNR target 30 dB at corner (27.03 deg, default)' in text
    assert "phone: SNR target 30 dB at axis (default)" in text
    assert "shake_deg_per_s=4.39" in text and "reflectance=0.4" in text
    assert repr(space).startswith("Space(\n  design: grid over 3:")


TOML = """
[scan]
points = 65536
[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }
[[design.custom]]
name = "phone"
pixel_pitch_um = 1.0
f_number = 1.88
focal_length_mm = 5.7
"""


@pytest.mark.parametrize("sensor", ['sensor_width_mm = 8.192\nsensor_height_mm = 6.144',
                                    'sensor_diagonal_mm = 10.24\naspect = "4:3"'])
def test_a_toml_design_takes_its_sensor_from_the_data_sheet(sensor):
    space = parse_config(TOML + sensor).space
    assert space.design_table["sensor_area_mm2"][0] == pytest.approx(8.192 * 6.144, rel=1e-14)
    angle = math.degrees(math.atan(5.12 / 5.7))
    assert space.design_table["field_angle_deg"][0] == pytest.approx(angle, rel=1e-14)
    axis = parse_config(TOML + sensor + '\nsnr_at = "axis"').space
    assert axis.design_table["field_angle_deg"][0] == 0.0
    assert axis.snr_target_text() == ["30 dB at axis"]


@pytest.mark.parametrize("extra, message", [
    ("sensor_width_mm = 8.192",
     r"\[design.custom\[0\]\] 'phone': give the sensor's size one way"),
    ("sensor_width_mm = 8.192\nsensor_height_mm = 6.144\nsensor_area_mm2 = 50",
     "got sensor_width_mm=8.192, sensor_height_mm=6.144, sensor_area_mm2=50"),
    ("sensor_heigth_mm = 6.1", r"unknown key 'sensor_heigth_mm'"),
    ('sensor_diagonal_mm = 10.24\naspect = "wide"', r"aspect='wide'"),
    ('sensor_area_mm2 = 50\nsnr_at = "corner"', r"snr_at='corner' needs"),
])
def test_a_toml_design_with_a_bad_sensor_is_one_config_error(extra, message):
    with pytest.raises(ConfigError, match=message):
        parse_config(TOML + extra)


def test_the_cli_prints_a_bad_sensor_as_one_line(tmp_path, capsys):
    from epc_fast.__main__ import main

    config = tmp_path / "c.toml"
    config.write_text(TOML + "sensor_width_mm = 8.192\n")
    assert main(["scan", str(config), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("epc-fast scan: error: scan config [design.")


def test_parameters_print_as_a_table_naming_evaluates_keywords():
    text = str(epc_fast.PARAMETERS)
    lines = text.splitlines()
    assert len(lines) == 1 + len(epc_fast.PARAMETERS)
    assert lines[0].split() == ["keyword", "unit", "default", "domain", "meaning"]
    assert repr(epc_fast.PARAMETERS) == text
    assert not any(line.startswith("size ") for line in lines)
    assert any(line.startswith("pixel_count | sensor_area_mm2") for line in lines)
    shake = next(line for line in lines if line.startswith("shake_deg_per_s"))
    assert shake.split()[1:4] == ["degree/s", "4.39", "[0,"]


def test_sensor_sides_that_do_not_broadcast_are_named():
    with pytest.raises(ValueError, match=r"illuminance_lux\(4,\).*sensor_width_mm x "
                                         r"sensor_height_mm\(3,\)"):
        evaluate(np.ones(4), **LENS, sensor_width_mm=np.ones(3), sensor_height_mm=1.0)


def test_a_space_without_designs_or_with_a_field_angle_of_its_own_says_where():
    bare = Space(illuminance_lux=LogUniform(10.0, 1e5), sensor_area_mm2=15.0, **LENS)
    assert "SNR target: 30 dB at axis (default)" in bare.describe()
    tilted = Space(design=HIGH_TIER, illuminance_lux=100.0, field_angle_deg=12.0, snr_db=33.0)
    assert tilted.snr_target_text() == ["33 dB at field angle 12 deg"] * 4
    assert "snr_db" not in tilted.defaults() and "shake_deg_per_s" in tilted.defaults()


WAYS = ("pixel_count, or sensor_area_mm2, or sensor_width_mm and sensor_height_mm, or "
        "sensor_diagonal_mm and aspect")
CORNER = ('snr_at = "corner" (the default of a design that gives its shape and focal length) '
          "needs sensor_width_mm and sensor_height_mm, or sensor_diagonal_mm and aspect")


def test_a_forgotten_sensor_size_is_asked_for_in_the_designs_own_table():
    # The message said to add sensor_area_mm2 to [parameters], which moved the SNR target
    # from the image corner to the axis without a word.
    with pytest.raises(ConfigError) as error:
        parse_config(TOML)
    message = str(error.value)
    assert message.startswith("scan config [design.custom[0]] 'phone': no sensor size: give "
                              f"it in this table, one of four ways: {WAYS}; {CORNER}"), message


def test_a_forgotten_sensor_size_names_the_design_and_the_four_ways_in_python():
    from epc_fast.scan import Space

    with pytest.raises(TypeError) as error:
        Space(design=[{"name": "phone", "pixel_pitch_um": 1.0, "f_number": 1.88,
                       "focal_length_mm": 5.7}], illuminance_lux=100.0)
    assert str(error.value).startswith(f"design 'phone' gives no sensor size: give it in the "
                                       f"design, one of four ways: {WAYS}; {CORNER}")
    with pytest.raises(TypeError) as error:
        Space(illuminance_lux=100.0, pixel_pitch_um=1.0, f_number=1.88, focal_length_mm=5.7)
    assert str(error.value).startswith("the space gives no sensor size: give pixel_count or "
                                       "sensor_area_mm2, or designs that give it one of four "
                                       f"ways: {WAYS}; {CORNER}")


def test_the_cli_asks_for_a_forgotten_sensor_size_in_the_designs_table(tmp_path, capsys):
    from epc_fast.__main__ import main

    config = tmp_path / "c.toml"
    config.write_text(TOML)
    assert main(["scan", str(config), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "[parameters]" not in err
    assert err.startswith("epc-fast scan: error: scan config [design.custom[0]] 'phone': no "
                          "sensor size: give it in this table")
