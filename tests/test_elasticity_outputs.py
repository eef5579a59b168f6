"""Asking for some elasticities one by one (python/epc_fast/elasticity_outputs.py): each is
the same number as in the full set, on both backends and float widths, through ``out=`` and a
Result as ``out=``; the names and their errors."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.designs import random_design_points

import epc_fast
from epc_fast import _core, elasticity_outputs, params
from epc_fast.api import ELASTICITY_PARAMETERS

BASE = dict(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6, sensor_width_mm=4.57,
            sensor_height_mm=3.43, read_noise_e=2.0, dark_current_e_per_s=5.0, prnu=0.01)
LUX = np.geomspace(1.0, 1e5, 41)
AREA_KEYS = [elasticity_outputs.key(p, False) for p in ELASTICITY_PARAMETERS]


def test_the_core_orders_the_parameters_as_python_does():
    # the core takes PARAMETERS' names in their order
    assert _core.parameter_names == params.PARAMETER_NAMES
    assert params.PARAMETER_NAMES == ELASTICITY_PARAMETERS


@pytest.mark.parametrize("backend", ["core", "reference"])
@pytest.mark.parametrize("key", AREA_KEYS)
def test_each_elasticity_alone_is_the_full_sets(key, backend):
    full = epc_fast.evaluate(LUX, **BASE, outputs="elasticities", backend=backend)
    one = epc_fast.evaluate(LUX, **BASE, outputs=f"elasticity_{key}", backend=backend)
    assert list(one.elasticities) == [key]
    # the same formulas on the same lanes: bit for bit
    np.testing.assert_array_equal(one.elasticities[key], full.elasticities[key])


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_a_subset_across_the_domain_matches_the_full_set(precision):
    design = random_design_points(20000, 11)
    keys = ["f_number", "read_noise_e", "shake_deg_per_s", size_key(design)]
    full = epc_fast.evaluate(**design, outputs=("epc", "elasticities"), precision=precision)
    some = epc_fast.evaluate(**design, outputs=["epc"] + [f"elasticity_{k}" for k in keys],
                             precision=precision)
    assert list(some.elasticities) == [k for k in full.elasticities if k in keys]
    np.testing.assert_array_equal(some.epc, full.epc)
    for key in keys:
        np.testing.assert_array_equal(some.elasticities[key], full.elasticities[key])


def size_key(design):
    return "pixel_count" if "pixel_count" in design else "sensor_area_mm2"


def test_the_sizes_elasticity_goes_by_the_way_the_size_is_given():
    by_count = epc_fast.evaluate(300.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
                                 pixel_count=8e6, outputs=("elasticity_pixel_count",))
    assert by_count.elasticities == {"pixel_count": 1.0}
    with pytest.raises(ValueError, match="elasticity_pixel_count.*by its area.*"
                                         "'elasticity_sensor_area_mm2'"):
        epc_fast.evaluate(300.0, **BASE, outputs=("elasticity_pixel_count",))
    with pytest.raises(ValueError, match="as a pixel count.*'elasticity_pixel_count'"):
        epc_fast.evaluate(300.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
                          pixel_count=8e6, outputs=("elasticity_sensor_area_mm2",))


@pytest.mark.parametrize("name", ["elasticity_size", "elasticity_", "elasticity_lens_mtf",
                                  "elasticity_F"])
def test_an_unknown_elasticity_is_named(name):
    with pytest.raises(ValueError, match=f"unknown field.*'{name}'"):
        epc_fast.evaluate(300.0, **BASE, outputs=(name,))


def test_all_and_some_elasticities_together_are_refused():
    with pytest.raises(ValueError, match="'elasticities', every elasticity, and also "
                                         r"\['elasticity_f_number'\]"):
        epc_fast.evaluate(300.0, **BASE, outputs=("elasticities", "elasticity_f_number"))


def test_scalar_input_gives_floats_in_the_callers_order_of_parameters():
    r = epc_fast.evaluate(500.0, **BASE, outputs=("elasticity_read_noise_e", "epc",
                                                  "elasticity_f_number"))
    assert list(r.elasticities) == ["f_number", "read_noise_e"]
    assert all(type(v) is float for v in r.elasticities.values())
    full = epc_fast.evaluate(500.0, **BASE, outputs="elasticities")
    assert r.elasticities == {k: full.elasticities[k] for k in r.elasticities}
    assert r.status is None and isinstance(r.epc, float)


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_out_arrays_take_single_elasticities(backend):
    out = {"epc": np.empty(LUX.size), "elasticity_f_number": np.empty(LUX.size),
           "elasticity_sensor_area_mm2": np.empty(LUX.size)}
    r = epc_fast.evaluate(LUX, **BASE, outputs=tuple(out), out=out, backend=backend)
    plain = epc_fast.evaluate(LUX, **BASE, outputs=tuple(out), backend=backend)
    assert r.elasticities["f_number"] is out["elasticity_f_number"]
    assert r.elasticities["sensor_area_mm2"] is out["elasticity_sensor_area_mm2"]
    np.testing.assert_array_equal(out["elasticity_f_number"], plain.elasticities["f_number"])
    np.testing.assert_array_equal(out["elasticity_sensor_area_mm2"], 1.0)


def test_out_arrays_of_single_elasticities_are_checked_by_their_names():
    with pytest.raises(ValueError, match=r"out\['elasticity_f_number'\] has shape \(3,\), "
                                         r"expected the broadcast shape \(41,\)"):
        epc_fast.evaluate(LUX, **BASE, outputs="elasticity_f_number",
                          out={"elasticity_f_number": np.empty(3)})
    with pytest.raises(ValueError, match=r"missing: \['elasticity_f_number'\], "
                                         r"unknown: \['elasticity_prnu'\]"):
        epc_fast.evaluate(LUX, **BASE, outputs="elasticity_f_number",
                          out={"elasticity_prnu": np.empty(LUX.size)})
    shared = np.empty(LUX.size)
    with pytest.raises(ValueError, match="share memory"):
        epc_fast.evaluate(LUX, **BASE, outputs=("epc", "elasticity_prnu"),
                          out={"epc": shared, "elasticity_prnu": shared})
    # the size's elasticity by the keyword that gave the size, not the core's name for it
    with pytest.raises(ValueError, match=r"out\['epc'\] and out\['elasticity_sensor_area_mm2'\] "
                                         "share memory"):
        epc_fast.evaluate(LUX, **BASE, outputs=("epc", "elasticity_sensor_area_mm2"),
                          out={"epc": shared, "elasticity_sensor_area_mm2": shared})


@pytest.mark.parametrize("backend", ["core", "reference"])
@pytest.mark.parametrize("size", [dict(pixel_count=8e6), dict(pixel_count=0.0)])
def test_scalar_out_arrays_take_every_elasticity(size, backend):
    # 0-d rows of the (20,) array: the rows themselves are written, not copies of them
    design = dict(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6, **size)
    out = {"status": np.empty((), np.uint8), "elasticities": np.zeros(len(ELASTICITY_PARAMETERS))}
    r = epc_fast.evaluate(300.0, **design, outputs=tuple(out), out=out, backend=backend)
    plain = epc_fast.evaluate(300.0, **design, outputs=tuple(out), backend=backend)
    assert np.shares_memory(r.elasticities["f_number"], out["elasticities"])
    np.testing.assert_array_equal(out["elasticities"], list(plain.elasticities.values()))
    # a pixel count of 0 is INVALID: every elasticity NaN
    assert np.isnan(out["elasticities"]).all() == (size["pixel_count"] == 0.0)


@pytest.mark.parametrize("backend", ["core", "reference"])
@pytest.mark.parametrize("outputs", [("epc", "elasticities"), ("epc", "elasticity_prnu")])
def test_a_result_serves_as_out(outputs, backend):
    first = epc_fast.evaluate(LUX, **BASE, outputs=outputs, backend=backend)
    again = epc_fast.evaluate(LUX * 2, **BASE, outputs=outputs, out=first, backend=backend)
    fresh = epc_fast.evaluate(LUX * 2, **BASE, outputs=outputs, backend=backend)
    assert again.epc is first.epc
    for key, array in first.elasticities.items():
        assert again.elasticities[key] is array
        np.testing.assert_array_equal(array, fresh.elasticities[key])


def test_rows_in_expands_every_elasticity():
    assert elasticity_outputs.rows_in(["epc", "elasticities"]) == elasticity_outputs.ROWS
    assert elasticity_outputs.rows_in(["elasticity_prnu", "elasticity_f_number", "epc"]) == (
        "elasticity_f_number", "elasticity_prnu")
    assert elasticity_outputs.rows_in(["epc"]) == ()


def test_the_core_takes_every_elasticity_in_one_array_or_single_ones_not_both():
    point = dict(illuminance_lux=300.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
                 size=8e6, reflectance=0.4, lens_transmittance=1.0, field_angle_deg=0.0,
                 fill_factor=1.0, electrons_per_lux_s_m2=2.56e15, read_noise_e=2.0,
                 dark_current_e_per_s=0.0, prnu=0.0, full_well_e=np.inf, snr_db=30.0,
                 shake_deg_per_s=4.39, stabilization=1.0, jitter_um=0.0, wavelength_nm=550.0,
                 mtf_threshold=0.5, binning=1.0, frames=1.0, alignment_error_um=0.0,
                 wavefront_rms_waves=0.0, denoise_sigma_px=0.0, lens=0.0,
                 cfa_transmittance=0.6, color_noise_gain=1.2, binning_readout=1.0)
    columns = [np.array([point[name]]) for name in params.PARAMETER_NAMES]
    domains = params.domain_table()
    names = _core.parameter_names
    none = np.empty(0)
    args = (columns, True, domains, none, none, 3, "halley", 1e-14,
            "closed_form", 1e-15, "float64", 1, 1 << 18)
    every = _core.evaluate(*args, None, ["elasticities"])["elasticities"]
    single = _core.evaluate(*args, None, ["elasticity_f_number", "elasticity_size"])
    assert every.shape == (3 * len(names),)
    j = names.index("f_number")
    np.testing.assert_array_equal(single["elasticity_f_number"], every[3 * j:3 * j + 3])
    np.testing.assert_array_equal(single["elasticity_size"], 1.0)
    # every elasticity but those of the whole numbers binning and frames, which have none
    whole = [names.index(p.name) for p in params.PARAMETERS if p.integer and p.name in names]
    rows = every.reshape(len(names), 3)
    assert np.isnan(rows[whole]).all()
    assert np.isfinite(np.delete(rows, whole, axis=0)).all()
    with pytest.raises(ValueError, match="both 'elasticities'.*'elasticity_f_number'"):
        _core.evaluate(*args, None, ["elasticities", "elasticity_f_number"])
    with pytest.raises(ValueError, match="allocate: 'elasticity_size_mm2' is not an output"):
        _core.evaluate(*args, None, ["elasticity_size_mm2"])
