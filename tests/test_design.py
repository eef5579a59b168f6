"""A camera design: Design as plain data, and resolve, a design's evaluate keywords as the
model's columns (python/epc_fast/design.py)."""

import inspect
import math

import numpy as np
import pytest

import epc_fast
from epc_fast import cfa, params
from epc_fast.design import DESIGN_KEYWORDS, resolve
from epc_fast.presets import HIGH_TIER, ZOOM_3X
from epc_fast.sensor import corner_field_angle_deg
from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2

#: A phone's design: lengths in mm, the pitch in um.
PHONE = {"pixel_pitch_um": 1.4, "f_number": 2.0, "focal_length_mm": 5.0}


def _column(resolved, name):
    return resolved.arrays[params.PARAMETER_NAMES.index(name)]


# --- Design ----------------------------------------------------------------------------------


def test_designs_are_plain_data_that_can_be_changed():
    stabilised = ZOOM_3X.with_(stabilization=4.0)
    assert stabilised.stabilization == 4.0 and ZOOM_3X.stabilization == 1.0
    assert stabilised.evaluate_kwargs()["stabilization"] == 4.0
    assert math.isclose(HIGH_TIER[0].sensor_area_mm2, 15.6751)


def test_a_design_carries_its_whole_sensor_into_evaluate():
    base = HIGH_TIER[3]
    assert set(base.evaluate_kwargs()) == {"pixel_pitch_um", "f_number", "focal_length_mm",
                                           "sensor_area_mm2", "field_angle_deg", "snr_db",
                                           "stabilization"}  # the paper's ideal sensor
    sensor = dict(read_noise_e=2.0, dark_current_e_per_s=8.0, prnu=0.01, full_well_e=6000.0,
                  fill_factor=0.8, binning=2, binning_readout="charge", frames=4,
                  alignment_error_um=0.3)
    design = base.with_(name="own", **sensor)
    kwargs = design.evaluate_kwargs()
    assert {k: kwargs[k] for k in sensor} == sensor
    direct = epc_fast.evaluate(300.0, **{**base.evaluate_kwargs(), **sensor})
    assert epc_fast.evaluate(300.0, **kwargs).epc == direct.epc


def test_a_design_with_modes_is_hashable_and_gives_evaluate_its_modes():
    modes = [{"binning": 1}, {"binning": 4, "binning_readout": "charge"}]
    design = HIGH_TIER[3].with_(name="modes", pixel_pitch_um=0.7, modes=modes)
    assert hash(design) == hash(HIGH_TIER[3].with_(name="modes", pixel_pitch_um=0.7,
                                                   modes=tuple(modes)))
    assert design.evaluate_kwargs()["modes"] == modes
    r = epc_fast.evaluate([10.0, 1e5], **design.evaluate_kwargs())
    assert list(r.mode) == [1, 0]


@pytest.mark.parametrize("modes, match", [([], "at least one"), ([{"bin": 2}], "'bin'"),
                                          ([{"binning": 2}, {"binning": 2}], "repeats")])
def test_a_design_refuses_bad_modes_when_made(modes, match):
    with pytest.raises((TypeError, ValueError), match=match):
        HIGH_TIER[0].with_(modes=modes)


def test_the_design_is_the_same_from_the_package_and_from_presets():
    from epc_fast import design, presets

    assert epc_fast.Design is presets.Design is design.Design
    assert presets.READINGS is design.READINGS


# --- resolve -------------------------------------------------------------------------------


def test_resolve_takes_evaluates_design_keywords_with_evaluates_defaults():
    evaluate = inspect.signature(epc_fast.evaluate).parameters
    ours = inspect.signature(resolve).parameters
    assert set(DESIGN_KEYWORDS) <= set(evaluate)
    assert {k: ours[k].default for k in DESIGN_KEYWORDS} == {
        k: evaluate[k].default for k in DESIGN_KEYWORDS}


def test_the_four_ways_of_giving_the_sensor_give_the_same_columns():
    width, height = 4.0, 3.0
    ways = [resolve(100.0, **PHONE, sensor_width_mm=width, sensor_height_mm=height),
            resolve(100.0, **PHONE, sensor_diagonal_mm=5.0, aspect="4:3"),
            resolve(100.0, **PHONE, sensor_area_mm2=width * height)]
    for resolved in ways:
        assert not resolved.sensor.is_pixel_count
        assert float(_column(resolved, "size")) == pytest.approx(12.0, rel=1e-15)
        for name in params.PARAMETER_NAMES:
            if name != "size":
                assert np.array_equal(_column(resolved, name), _column(ways[0], name))
    assert ways[0].sensor.name == "sensor_width_mm x sensor_height_mm"
    assert ways[1].sensor.name == "sensor_diagonal_mm"
    assert ways[2].sensor.name == "sensor_area_mm2"
    count = resolve(100.0, **PHONE, pixel_count=12.0e6 / 1.4 ** 2)
    assert count.sensor.is_pixel_count and count.sensor.name == "pixel_count"
    assert float(_column(count, "size")) == 12.0e6 / 1.4 ** 2


def test_the_corner_is_the_field_angle_of_half_the_diagonal():
    resolved = resolve(100.0, **PHONE, sensor_width_mm=4.0, sensor_height_mm=3.0,
                       snr_at="corner")
    assert resolved.field_angle_deg == corner_field_angle_deg(4.0, 3.0, 5.0)
    assert float(_column(resolved, "field_angle_deg")) == pytest.approx(
        math.degrees(math.atan(2.5 / 5.0)), rel=1e-15)
    axis = resolve(100.0, **PHONE, sensor_width_mm=4.0, sensor_height_mm=3.0, snr_at="axis")
    assert axis.field_angle_deg == 0.0


def test_the_defaults_fill_the_columns():
    resolved = resolve(100.0, **PHONE, sensor_area_mm2=12.0)
    assert float(_column(resolved, "electrons_per_lux_s_m2")) == DEFAULT_ELECTRONS_PER_LUX_S_M2
    assert float(_column(resolved, "reflectance")) == 0.4
    assert resolved.shape == () and resolved.columns_ready
    assert resolved.spectrum is None and resolved.lens_tables is None


def test_a_spectrum_on_one_wavelength_is_the_monochromatic_model_at_it():
    resolved = resolve(100.0, **PHONE, sensor_area_mm2=12.0,
                       spectrum=([450.0, 600.0], [0.0, 1.0]))
    assert resolved.spectrum is None
    assert float(_column(resolved, "wavelength_nm")) == 600.0
    # the lens still images the caller's wavelengths (a simulated capture's grid)
    wavelengths, weights = resolved.wavelengths()
    assert list(wavelengths) == [450.0, 600.0] and list(weights) == [0.0, 1.0]
    spread = resolve(100.0, **PHONE, sensor_area_mm2=12.0,
                     spectrum=([450.0, 600.0], [0.5, 0.5]))
    assert list(spread.spectrum.wavelengths_nm) == [450.0, 600.0]
    assert float(_column(spread, "wavelength_nm")) == 550.0


def test_the_color_sensor_gives_its_transmittance_and_noise_gain_columns():
    mono = resolve(100.0, **PHONE, sensor_area_mm2=12.0)
    assert (float(_column(mono, "cfa_transmittance")), float(_column(mono, "color_noise_gain"))
            ) == (1.0, 1.0) and mono.color.demosaic_table is None
    behind_a_filter = resolve(100.0, **PHONE, sensor_area_mm2=12.0, cfa_transmittance=0.5)
    assert float(_column(behind_a_filter, "cfa_transmittance")) == 0.5
    bayer = resolve(100.0, **PHONE, sensor_area_mm2=12.0, cfa="bayer", demosaic="bilinear")
    assert float(_column(bayer, "cfa_transmittance")) == cfa.DEFAULT_CFA_TRANSMITTANCE
    assert float(_column(bayer, "color_noise_gain")) == pytest.approx(
        cfa.DEFAULT_COLOR_NOISE_GAIN * cfa.DEMOSAIC_NOISE_GAIN["bilinear"], rel=1e-15)
    assert bayer.color.demosaic_table is not None


def test_binning_readout_is_a_column_of_its_codes_per_point():
    design = dict(PHONE, sensor_area_mm2=12.0, read_noise_e=3.0, binning=[1.0, 2.0, 4.0])
    charge = resolve(100.0, **design, binning_readout="charge")
    assert float(_column(charge, "binning_readout")) == params.READOUT_CODES["charge"] == 1.0
    assert float(_column(resolve(100.0, **design), "binning_readout")) == 0.0
    mixed = resolve(100.0, **design, binning_readout=["charge", "digital", "charge"])
    np.testing.assert_array_equal(_column(mixed, "binning_readout"), [1.0, 0.0, 1.0])
    # one read of sigma for k x k pixels is k^2 reads of sigma / k, on both backends
    for backend in ("core", "reference"):
        by_charge = epc_fast.evaluate(30.0, **design, binning_readout="charge", backend=backend)
        by_reads = epc_fast.evaluate(30.0, **{**design, "read_noise_e": [3.0, 1.5, 0.75]},
                                     backend=backend)
        np.testing.assert_allclose(by_charge.epc, by_reads.epc, rtol=1e-12)
        # per point as one call per readout gives it, bit for bit
        per_point = epc_fast.evaluate(30.0, **design, binning_readout=["charge", "digital",
                                                                       "charge"],
                                      backend=backend)
        digital = epc_fast.evaluate(30.0, **design, backend=backend)
        np.testing.assert_array_equal(per_point.epc, [by_charge.epc[0], digital.epc[1],
                                                      by_charge.epc[2]])


def test_a_lens_table_is_checked_and_picked_by_lens():
    table = ([0.0, 100.0, 200.0], [1.0, 0.6, 0.0])
    resolved = resolve(100.0, **PHONE, sensor_area_mm2=12.0, lens_mtf=[table, table], lens=1.0)
    assert len(resolved.lens_tables) == 2 and resolved.lens_table() is resolved.lens_tables[1]
    assert resolve(100.0, **PHONE, sensor_area_mm2=12.0).lens_table() is None


@pytest.mark.parametrize("change, error, match", [
    ({"pixel_pitch_um": [1.0, 1.4, 2.0], "f_number": [2.0, 2.8]}, ValueError,
     r"do not broadcast: pixel_pitch_um\(3,\), f_number\(2,\)"),
    ({"binning_readout": "analog"}, ValueError, "binning_readout must be one of.*'analog'"),
    ({"spectrum": ([500.0], [1.0]), "wavelength_nm": 600.0}, ValueError, "wavelength_nm=600"),
    ({"spectrum": 600.0}, TypeError, "spectrum must be .* got 600"),
    ({"pixel_count": 1e6}, TypeError, "sensor_area_mm2=12.0, pixel_count=1000000.0"),
    ({"snr_at": "corner"}, TypeError, "snr_at='corner' needs the sensor's diagonal"),
    ({"cfa": "foveon"}, ValueError, "foveon"),
    ({"lens_mtf": ([0.0, 100.0], [1.0, 0.5]), "wavefront_rms_waves": 0.05}, ValueError,
     "wavefront_rms_waves"),
])
def test_a_bad_design_is_an_error_naming_the_argument_and_its_value(change, error, match):
    with pytest.raises(error, match=match):
        resolve(100.0, **{**PHONE, "sensor_area_mm2": 12.0, **change})


def _tuples_named(path, function):
    """The names of each tuple of plain names in ``function`` of the module at ``path`` (an
    argument, an assignment's value or target), in order, as lists."""
    import ast

    tree = ast.parse(path.read_text())
    body = next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == function)
    found = []
    for node in ast.walk(body):
        if isinstance(node, ast.Tuple) and len(node.elts) > 20:
            found.append([ast.unparse(e) for e in node.elts])
    return found


def test_the_keywords_reach_resolved_from_in_design_keywords_order():
    # evaluate and resolve hand resolved_from a tuple, which it unpacks: one order for all three
    from pathlib import Path

    from epc_fast.design import DESIGN_KEYWORDS

    package = Path(epc_fast.__file__).parent
    keywords = list(DESIGN_KEYWORDS)
    assert _tuples_named(package / "api.py", "evaluate") == [keywords]
    assert _tuples_named(package / "design.py", "resolve") == [keywords]
    unpacked, values = _tuples_named(package / "design.py", "resolved_from")
    assert unpacked == keywords
    slots = {"sensor.value": "size", "color.transmittance": "cfa_transmittance",
             "color.noise_gain": "color_noise_gain", "readout": "binning_readout"}
    assert [slots.get(v, v) for v in values] == list(params.PARAMETER_NAMES)
