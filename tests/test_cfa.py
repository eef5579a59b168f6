"""The colour filter array's names, defaults and demosaicker table (epc_fast.cfa): the defaults
in range and reproduced by tools/cfa_defaults.py from colour-science's data, the colour noise
gain's formula, the shipped table an MtfTable, bad names refused naming the argument, and the
module free of colour-science at runtime."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from epc_fast import cfa, spectra
from epc_fast.mtf_table import MtfTable

ROOT = Path(__file__).resolve().parents[1]


def _tool(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_defaults_are_a_green_pixel_near_ks_sensor_and_a_gain_near_one():
    t_r, t_g, t_b = cfa.DEFAULT_CHANNEL_TRANSMITTANCES
    # The constants are written to 4 decimals: they agree with each other to rounding.
    assert cfa.DEFAULT_CFA_TRANSMITTANCE == pytest.approx((t_r + 2 * t_g + t_b) / 4, abs=1e-4)
    # against the sensor K describes (the bayer_light tests below derive them): a green pixel
    # about 1, red and blue less, the cell about 0.84
    assert abs(t_g - 1.0) < 0.01 and t_r < t_g and t_b < t_g
    assert 0.77 < cfa.DEFAULT_CFA_TRANSMITTANCE < 0.86
    assert sum(cfa.DEFAULT_LUMINANCE_WEIGHTS) == pytest.approx(1.0, abs=2e-4)
    assert cfa.DEFAULT_COLOR_NOISE_GAIN == pytest.approx(cfa.color_noise_gain(), abs=2e-4)
    assert 0.5 < cfa.DEFAULT_COLOR_NOISE_GAIN < 1.5
    assert set(cfa.DEMOSAIC_NOISE_GAIN) == set(cfa.DEMOSAICS)
    assert all(0.3 < g <= 1.05 for g in cfa.DEMOSAIC_NOISE_GAIN.values())


def test_the_defaults_are_what_the_script_derives_from_the_nikon_d5100():
    pytest.importorskip("colour")
    d = _tool("cfa_defaults").derive()
    # Written to 4 decimals: half a unit of the last place.
    assert cfa.DEFAULT_CHANNEL_TRANSMITTANCES == pytest.approx(
        tuple(d["channel_transmittances"]), abs=5e-5)
    assert cfa.DEFAULT_CFA_TRANSMITTANCE == pytest.approx(d["cfa_transmittance"], abs=5e-5)
    assert cfa.DEFAULT_LUMINANCE_WEIGHTS == pytest.approx(tuple(d["luminance_weights"]),
                                                          abs=5e-5)
    assert cfa.DEFAULT_COLOR_NOISE_GAIN == pytest.approx(d["color_noise_gain"], abs=5e-5)
    # The chart's luminance is fitted to 1 % of white: the correction is a real camera's.
    assert d["fit_rms_y"] < 0.01


def test_the_color_noise_gain_of_equal_channels_averaged_equally_is_a_third():
    # t = 0.5, g = 0.5 * 3 * (1/9) / 0.5 = 1/3: three independent channels averaged.
    assert cfa.color_noise_gain((0.5, 0.5, 0.5), (1 / 3, 1 / 3, 1 / 3)) == pytest.approx(1 / 3,
                                                                                       rel=1e-12)
    # Luminance from green alone: t / t_G = (0.1 + 0.8 + 0.3) / 4 / 0.4 = 0.75.
    assert cfa.color_noise_gain((0.1, 0.4, 0.3), (0.0, 1.0, 0.0)) == pytest.approx(0.75,
                                                                                 rel=1e-12)
    # One factor on every channel changes nothing.
    scaled = tuple(0.5 * t for t in cfa.DEFAULT_CHANNEL_TRANSMITTANCES)
    assert cfa.color_noise_gain(scaled) == pytest.approx(cfa.color_noise_gain(), rel=1e-12)


@pytest.mark.parametrize("name", cfa.DEMOSAICS)
def test_each_demosaickers_table_is_an_mtf_table_to_one_cycle_a_pixel(name):
    table = cfa.demosaic_mtf_table(name)
    assert isinstance(table, MtfTable)
    assert table.frequencies[0] == 0.0 and table.values[0] == 1.0
    assert table.last_frequency >= 1.0
    assert table.frequencies.size >= 12
    assert np.all(np.diff(table.values) <= 0.0)
    # The interpolant passes through its knots: knot 10 is 0.5 cycles/pixel.
    assert table.frequencies[10] == 0.5
    assert float(table(0.5)) == table.values[10]


def test_bilinear_loses_most_and_menon_least_at_the_nyquist_frequency():
    at = {name: float(cfa.demosaic_mtf_table(name)(0.5)) for name in cfa.DEMOSAICS}
    assert at["bilinear"] < at["malvar2004"] < at["menon2007"]
    assert 0.4 < at["bilinear"] < 0.55


def test_the_table_ships_inside_the_package():
    # beside the module that reads it, in the source tree and in an installed package alike
    # (CI's tests run against the installed one: the wheel carries the file), and in git
    package = Path(cfa.__file__).resolve().parent
    assert cfa.DEMOSAIC_MTF_PATH.parent == package / "data"
    assert cfa.DEMOSAIC_MTF_PATH.read_text().startswith("# Each demosaicker's luminance MTF")
    source = ROOT / "python" / "epc_fast" / "data" / "demosaic_mtf.csv"
    assert source.read_text() == cfa.DEMOSAIC_MTF_PATH.read_text()


@pytest.mark.parametrize("call, bad, argument", [
    (cfa.demosaic_mtf_table, "ahd", "demosaic"),
    (cfa.demosaic_mtf_table, None, "demosaic"),
    (cfa.check_demosaic, "Malvar2004", "demosaic"),
    (cfa.check_cfa, "xtrans", "cfa"),
    (cfa.check_cfa, 1, "cfa"),
])
def test_a_bad_name_is_refused_naming_the_argument(call, bad, argument):
    with pytest.raises(ValueError, match=rf"^{argument}: one of .* got {bad!r}"):
        call(bad)


def test_the_names_are_the_issues():
    assert cfa.CFAS == ("none", "bayer", "quad_bayer")
    assert cfa.QUAD_BAYER_BINNINGS == (1, 2)
    assert cfa.DEMOSAICS == ("bilinear", "malvar2004", "menon2007")


def test_cfa_and_the_simulator_import_neither_color_science_nor_color_demosaicing():
    code = ("import sys, epc_fast.cfa as c, epc_fast.simulate\n"
            "c.demosaic_mtf_table('menon2007')\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('colour', 'colour_demosaicing')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env={"PYTHONPATH": str(ROOT / "python")})
    assert out.stdout.strip() == "[]"


def test_bilinears_noise_gain_is_its_closed_form():
    # Bilinear interpolation fills each channel from its own pixels: a pixel's interpolated
    # channel c has the variance of one pixel times the sum of squares of its weights, whose
    # mean over the RGGB cell is k_G = (1 + 4 (1/4)^2) / 2 = 5/8 (green sites keep their value,
    # the others average 4) and k_R = k_B = (1 + 2 (2 (1/2)^2) + 4 (1/4)^2) / 4 = 9/16.
    t_c = np.array(cfa.DEFAULT_CHANNEL_TRANSMITTANCES)
    y2 = np.array(cfa.DEFAULT_LUMINANCE_WEIGHTS) ** 2
    k = np.array([9 / 16, 5 / 8, 9 / 16])
    closed_form = np.sum(y2 * k / t_c) / np.sum(y2 / t_c)
    assert closed_form == pytest.approx(0.6148, abs=1e-4)
    # The shipped value is measured over 16 seeds, standard error 0.0017: 4 of them.
    assert cfa.DEMOSAIC_NOISE_GAIN["bilinear"] == pytest.approx(closed_form, abs=4 * 0.0017)


# --- A Bayer sensor against the mpmath model (helpers/mp_model.py) ------------------------------

#: The paper's 1.4 um design (K passed exactly): at F/1.8 in daylight f50 lies at about 0.3
#: cycles/pixel, on the falling part of the bilinear and Malvar tables; dim and binned 2 x 2,
#: with read noise and a colour noise gain of its own, the noise gains set T_MPE and the blur.
MP_DESIGN = dict(illuminance_lux=1e5, pixel_pitch_um=1.4, f_number=1.8, focal_length_mm=5.6,
                 sensor_area_mm2=15.6751, electrons_per_lux_s_m2=2557705539053827.5)
MP_BAYER_CASES = {
    "daylight": MP_DESIGN,
    "dim_binned": dict(MP_DESIGN, illuminance_lux=50.0, f_number=2.8, binning=2.0,
                       read_noise_e=1.5, prnu=0.005, color_noise_gain=1.1,
                       cfa_transmittance=0.4),
}


@pytest.mark.parametrize("backend", ["core", "reference"])
@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
@pytest.mark.parametrize("case", MP_BAYER_CASES)
def test_a_bayer_sensor_matches_the_mpmath_model(case, demosaic, backend):
    import epc_fast
    from helpers.mp_model import assert_matches_model, mp_model

    inputs = MP_BAYER_CASES[case]
    model = mp_model(inputs, demosaic=demosaic)
    if case == "daylight" and demosaic != "menon2007":  # the table is a factor at f50
        assert model["mtf_factors"][-1] < 0.95, model["mtf_factors"]
    result = epc_fast.evaluate(**inputs, cfa="bayer", demosaic=demosaic, backend=backend)
    # The model takes the float64 inputs and the shipped table exactly; both backends form
    # g_c g_d and evaluate the table's cubic with float64 roundings (measured <= 1e-15 on
    # these well-conditioned points): the suite's 1e-12 leaves 1000x room, and a noise gain
    # or transmittance left out moves T_MPE by 0.4% or more.
    assert_matches_model(result, model, rtol=1e-12, label=f"{case}, {demosaic}")


# --- The quad Bayer sensor: binned 2 x 2 a Bayer sensor, full size remosaicked -----------------

#: The 50 MP 1.0 um quad Bayer phone camera of issue 54 (8.16 x 6.12 mm, f/1.9, 5.6 mm).
QUAD = dict(pixel_pitch_um=1.0, f_number=1.9, focal_length_mm=5.6, sensor_width_mm=8.16,
            sensor_height_mm=6.12, read_noise_e=1.5)
LUX = np.array([1.0, 10.0, 100.0, 1e3, 1e4])
#: Outputs that carry every term: the exposure, the MTF, the shares and the elasticities.
ALL = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc",
       "status", "share_pixel", "share_demosaic", "elasticities")


def _same_table(a, b) -> bool:
    return (np.array_equal(a.frequencies, b.frequencies) and np.array_equal(a.values, b.values)
            and np.array_equal(a.coefficients, b.coefficients))


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_a_quad_sensor_takes_the_bayer_terms_binned_and_the_remosaics_full_size(demosaic):
    binned = cfa.sensor_color("quad_bayer", demosaic, None, None, 2.0)
    bayer = cfa.sensor_color("bayer", demosaic, None, None, 2.0)
    assert (binned.transmittance, binned.noise_gain) == (bayer.transmittance, bayer.noise_gain)
    assert _same_table(binned.demosaic_table, bayer.demosaic_table)
    full = cfa.sensor_color("quad_bayer", demosaic, None, None, 1.0)
    assert full.transmittance == cfa.DEFAULT_CFA_TRANSMITTANCE
    assert full.noise_gain == cfa.DEFAULT_COLOR_NOISE_GAIN * cfa.REMOSAIC_NOISE_GAIN[demosaic]
    assert _same_table(full.demosaic_table, cfa.remosaic_mtf_table(demosaic))
    assert not _same_table(full.demosaic_table, bayer.demosaic_table)
    # the remosaic averages five pixels in eight: less variance, and never a higher MTF
    assert cfa.REMOSAIC_NOISE_GAIN[demosaic] < cfa.DEMOSAIC_NOISE_GAIN[demosaic]
    # a Bayer sensor's terms do not depend on the binning
    assert _same_table(cfa.sensor_color("bayer", demosaic, None, None, 3.0).demosaic_table,
                       bayer.demosaic_table)


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_binned_2x2_a_quad_sensor_is_the_bayer_sensor_bit_for_bit(backend):
    import epc_fast

    quad = epc_fast.evaluate(LUX, **QUAD, binning=2, cfa="quad_bayer", outputs=ALL,
                             backend=backend)
    bayer = epc_fast.evaluate(LUX, **QUAD, binning=2, cfa="bayer", outputs=ALL,
                              backend=backend)
    for name in ALL[:-1]:
        np.testing.assert_array_equal(getattr(quad, name), getattr(bayer, name), err_msg=name)
    assert quad.elasticities.keys() == bayer.elasticities.keys()
    for name, value in quad.elasticities.items():
        np.testing.assert_array_equal(value, bayer.elasticities[name], err_msg=name)


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_full_size_both_backends_agree_and_the_remosaic_table_sets_f50(demosaic):
    import epc_fast

    core = epc_fast.evaluate(LUX, **QUAD, cfa="quad_bayer", demosaic=demosaic)
    reference = epc_fast.evaluate(LUX, **QUAD, cfa="quad_bayer", demosaic=demosaic,
                                  backend="reference")
    np.testing.assert_allclose(core.epc, reference.epc, rtol=1e-9)  # the backends' agreement
    # the quad sensor is the Bayer sensor with the remosaic's noise gain and table: given
    # those as a Bayer sensor's colour noise gain, only the table differs, and the remosaic's
    # lies at or below the Bayer one, so that at the same exposure f50 is no higher. (Where
    # both tables are 1 at f50 the two f50 are one root, solved from each table's own fitted
    # start: equal to f50_rtol, 1e-14, and EPC, its square, to twice that.)
    g = cfa.REMOSAIC_NOISE_GAIN[demosaic] / cfa.DEMOSAIC_NOISE_GAIN[demosaic]
    bayer = epc_fast.evaluate(LUX, **QUAD, cfa="bayer", demosaic=demosaic,
                              color_noise_gain=cfa.DEFAULT_COLOR_NOISE_GAIN * g)
    np.testing.assert_array_equal(core.t_mpe_s, bayer.t_mpe_s)
    assert np.all(core.epc <= bayer.epc * (1.0 + 2e-14))
    assert np.any(core.epc < bayer.epc * (1.0 - 1e-3))  # and the remosaic's table is lower


@pytest.mark.parametrize("binning, message", [
    (3, r"^cfa='quad_bayer': binning must be 1 \(full size, remosaicked\) or 2 .*got binning 3"),
    ([1, 4], r"^cfa='quad_bayer': binning must be 1 .*got binning 4"),
    ([1.0, 2.0, 1.0], r"^cfa='quad_bayer': binning takes one value per call .*modes=\[\{'binning'"
                      r": 1\}, \{'binning': 2\}\]"),
])
@pytest.mark.parametrize("backend", ["core", "reference"])
def test_a_quad_sensor_at_another_or_at_both_binnings_is_refused_naming_it(binning, message,
                                                                           backend):
    import epc_fast

    with pytest.raises(ValueError, match=message):
        epc_fast.evaluate(100.0, **QUAD, cfa="quad_bayer", binning=binning, backend=backend)


def test_a_quad_sensors_binning_that_is_no_number_leaves_its_point_invalid():
    import epc_fast

    r = epc_fast.evaluate(100.0, **QUAD, cfa="quad_bayer", binning=[2.0, np.nan])
    one = epc_fast.evaluate(100.0, **QUAD, cfa="quad_bayer", binning=2.0)
    assert r.epc[0] == one.epc and np.isnan(r.epc[1])
    assert int(r.status[1]) == int(epc_fast.Status.INVALID)


# --- A Bayer sensor's light from spectra (cfa.bayer_light) ------------------------------------
# t and K from the same closed-form spectra (an equal-energy illuminant and box filters, where
# the trapezoid rule is exact), K equal to epc_fast.spectra's for the same spectra, the gains'
# scale invariance, the shipped defaults what the function gives for the Nikon D5100 under D50,
# and bad input refused naming the argument and its value.

GRID = spectra.GRID_NM
H_C_J_M = spectra.PLANCK_J_S * spectra.SPEED_OF_LIGHT_M_S


def _box(lo_nm, hi_nm, value=1.0):
    """``value`` strictly inside [lo, hi], half of it at the two edge samples, 0 outside: the
    trapezoid rule integrates it times any linear function exactly (spectra.default_qe)."""
    inside = np.where((GRID > lo_nm) & (GRID < hi_nm), value, 0.0)
    return np.where((GRID == lo_nm) | (GRID == hi_nm), value / 2, inside)


#: Blue, green and red boxes that tile 400..700 nm, in (R, G, B) order.
BOXES = ((600.0, 700.0), (500.0, 600.0), (400.0, 500.0))
FLAT = np.ones_like(GRID)  # the equal-energy illuminant: photons per nm proportional to lambda


def test_bayer_light_is_public():
    assert {"bayer_light", "BayerLight"} <= set(cfa.__all__)


def test_boxes_under_equal_energy_light_have_their_closed_form_t_and_k():
    pytest.importorskip("colour")  # the photopic V behind K
    qe = 0.5
    light = cfa.bayer_light([_box(*b) for b in BOXES], FLAT, quantum_efficiency=qe,
                            reference_quantum_efficiency=spectra.default_qe,
                            wavelengths_nm=GRID)
    # Equal energy per nm is photons per nm proportional to lambda, so a box [a, b] under QE q
    # collects q (b^2 - a^2) / 2 in units where K's sensor (0.7 on [480, 580]) collects
    # 0.7 (580^2 - 480^2) / 2; the trapezoid rule is exact on both (box times linear).
    reference = 0.7 * (580.0 ** 2 - 480.0 ** 2)
    expected = [qe * (b * b - a * a) / reference for a, b in BOXES]
    # 1e-13: a few hundred float64 additions' rounding, relative.
    np.testing.assert_allclose(light.channel_transmittances, expected, rtol=1e-13)
    t_r, t_g, t_b = expected
    assert light.transmittance == pytest.approx((t_r + 2 * t_g + t_b) / 4, rel=1e-13)
    # (700^2 - 600^2) : (600^2 - 500^2) : (500^2 - 400^2) = 13 : 11 : 9
    np.testing.assert_allclose(light.white_balance, (11 / 13, 1.0, 11 / 9), rtol=1e-13)
    assert light.color_noise_gain == pytest.approx(cfa.color_noise_gain(expected), rel=1e-13)
    # K: E per lux is 1 / (683 lm/W integral(V)); photons per joule lambda / (h c)
    v = spectra.photopic_luminosity()
    lux = spectra.LUMINOUS_EFFICACY_LM_PER_W * np.trapezoid(v, GRID)
    k = reference / 2 * 1e-9 / H_C_J_M / lux
    assert light.electrons_per_lux_s_m2 == pytest.approx(k, rel=1e-13)
    # ... and epc_fast.spectra's for the same spectra, bit for bit (one computation)
    assert light.electrons_per_lux_s_m2 == spectra.electrons_per_lux_s_m2(
        FLAT, spectra.default_qe, GRID)


def test_each_channel_collects_t_c_k_of_spectras_electrons():
    pytest.importorskip("colour")
    qe = np.linspace(0.3, 0.9, GRID.size)  # a QE rising to the red, on a named illuminant
    filters = [_box(*b, value=0.8) for b in BOXES]
    light = cfa.bayer_light(filters, "A", quantum_efficiency=qe)
    k = spectra.electrons_per_lux_s_m2("A", qe)
    assert light.electrons_per_lux_s_m2 == k  # the reference defaults to the same QE
    for t_c, f in zip(light.channel_transmittances, filters):
        assert t_c * k == pytest.approx(spectra.electrons_per_lux_s_m2("A", qe * f), rel=1e-15)


def test_no_filter_is_the_reference_sensor_and_a_partition_adds_up_to_it():
    pytest.importorskip("colour")
    bare = cfa.bayer_light([FLAT, FLAT, FLAT], "D65", quantum_efficiency=0.6)
    assert bare.channel_transmittances == (1.0, 1.0, 1.0) and bare.transmittance == 1.0
    assert bare.white_balance == (1.0, 1.0, 1.0)
    # t sum y_c^2 / t_c with t = t_c = 1
    y = np.array(cfa.DEFAULT_LUMINANCE_WEIGHTS)
    assert bare.color_noise_gain == pytest.approx(float(np.sum(y * y)), rel=1e-15)
    # three boxes that tile 400..700 nm against the same QE on 400..700 nm: the channels'
    # electrons add up to the reference's (the trapezoid rule is linear in the QE)
    tiles = cfa.bayer_light([_box(*b) for b in BOXES], "D65", quantum_efficiency=0.6,
                            reference_quantum_efficiency=_box(400.0, 700.0, 0.6))
    assert sum(tiles.channel_transmittances) == pytest.approx(1.0, rel=1e-14)


def test_t_scales_with_the_qe_and_the_gains_do_not():
    # One factor on every channel's electrons: t and the channels take it, the white
    # balance and the colour noise gain (a ratio of the channels) do not (tools/cfa_defaults.py).
    pytest.importorskip("colour")
    filters = [_box(*b, value=0.9) for b in BOXES]
    full = cfa.bayer_light(filters, quantum_efficiency=0.8,
                           reference_quantum_efficiency=spectra.default_qe)
    half = cfa.bayer_light(filters, quantum_efficiency=0.4,
                           reference_quantum_efficiency=spectra.default_qe)
    assert half.transmittance == pytest.approx(full.transmittance / 2, rel=1e-14)
    np.testing.assert_allclose(half.channel_transmittances,
                               np.array(full.channel_transmittances) / 2, rtol=1e-14)
    np.testing.assert_allclose(half.white_balance, full.white_balance, rtol=1e-14)
    assert half.color_noise_gain == pytest.approx(full.color_noise_gain, rel=1e-14)
    assert half.electrons_per_lux_s_m2 == full.electrons_per_lux_s_m2


def test_the_shipped_defaults_are_the_nikon_d5100_against_ks_sensor():
    pytest.importorskip("colour")
    tool = _tool("cfa_defaults")
    light = tool.light(cfa.DEFAULT_LUMINANCE_WEIGHTS)
    # Written to 4 decimals: half a unit of the last place.
    assert cfa.DEFAULT_CHANNEL_TRANSMITTANCES == pytest.approx(
        light.channel_transmittances, abs=5e-5)
    assert cfa.DEFAULT_CFA_TRANSMITTANCE == pytest.approx(light.transmittance, abs=5e-5)
    assert cfa.DEFAULT_COLOR_NOISE_GAIN == pytest.approx(light.color_noise_gain, abs=5e-5)
    # The reference is the sensor behind the shipped K, on the same grid.
    assert light.electrons_per_lux_s_m2 == pytest.approx(spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2,
                                                         rel=1e-14)
    # Against K's sensor, a green pixel of the same peak QE collects about what it does (the
    # green filter passes about K's band) and the cell about 0.84 of it; the three channels
    # together collect more than twice K (the panchromatic sum is not K's sensor).
    assert abs(light.channel_transmittances[1] - 1.0) < 0.01
    assert 0.77 < light.transmittance < 0.86
    assert sum(light.channel_transmittances) > 2.0
    # Each channel's electrons are spectra's K of its own QE: 0.7 times its shape.
    wavelengths, _, sens, _, _ = tool.spectra_()
    shapes = tool.channel_quantum_efficiency_shapes(wavelengths, sens)
    assert np.all(shapes.max(axis=1) == 1.0)
    for t_c, shape in zip(light.channel_transmittances, shapes):
        assert t_c * light.electrons_per_lux_s_m2 == pytest.approx(
            spectra.electrons_per_lux_s_m2("D50", spectra.QE_PEAK * shape), rel=1e-14)


BAD_LIGHT = [
    (dict(filter_transmittances=[FLAT, FLAT]), "filter_transmittances: three filters .* got 2"),
    (dict(filter_transmittances=[FLAT, FLAT, FLAT[:10]]),
     r"filter_transmittances\[2\] \(B\): 401 samples .* got shape \(10,\)"),
    (dict(filter_transmittances=[FLAT, 1.2 * FLAT, FLAT]),
     r"filter_transmittances\[1\] \(G\): in \[0, 1\] .* got 1.2 at 380 nm"),
    (dict(quantum_efficiency=70.0), r"quantum_efficiency: in \[0, 1\] .* got 70.0 at 380 nm"),
    (dict(quantum_efficiency=np.nan), r"quantum_efficiency: in \[0, 1\] .* got nan"),
    (dict(reference_quantum_efficiency=-0.1),
     r"reference_quantum_efficiency: in \[0, 1\] .* got -0.1"),
    (dict(reference_quantum_efficiency=0.0),
     "reference_quantum_efficiency: the reference sensor collects no electrons"),
    (dict(filter_transmittances=[FLAT, FLAT, _box(300.0, 379.0)]),
     r"filter_transmittances: channel B collects no electrons .* got array\(\[ ?0\., ?0\."),
    (dict(luminance_weights=(0.3, 0.6, 0.2)),
     r"luminance_weights: three finite weights .* summing to 1, got \(0.3, 0.6, 0.2\)"),
    (dict(illuminant=FLAT), "wavelengths_nm: required when illuminant is given as an array"),
]


@pytest.mark.parametrize("change, message", BAD_LIGHT)
def test_bayer_light_refuses_bad_input_naming_the_argument_and_its_value(change, message):
    pytest.importorskip("colour")
    kwargs = dict(filter_transmittances=[FLAT, FLAT, FLAT], quantum_efficiency=0.5)
    kwargs.update(change)
    with pytest.raises(ValueError, match="^" + message):
        cfa.bayer_light(**kwargs)


def test_bayer_light_takes_a_non_number_as_a_type_error_naming_the_argument():
    with pytest.raises(TypeError, match="^quantum_efficiency: "):
        cfa.bayer_light([FLAT, FLAT, FLAT], quantum_efficiency="0.7")
    with pytest.raises(TypeError, match="^filter_transmittances: three filters"):
        cfa.bayer_light(lambda nm: nm)
    with pytest.raises(TypeError, match="^filter_transmittances: three filters .* got 'rgb'"):
        cfa.bayer_light("rgb")
