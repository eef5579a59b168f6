"""The colour filter array in the NumPy reference (epc_fast.reference.cfa and its place in the
model): the rate times t, every noise variance times g_c g_d, the MTF times the demosaicker's
table at f p_out; closed forms, the arguments' checks and the elasticities."""

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, cfa, spectra
from epc_fast.reference.cfa import mtf_demosaic

ROOT = Path(__file__).resolve().parents[2]
DESIGN = dict(pixel_pitch_um=1.4, f_number=2.0, focal_length_mm=4.0, sensor_width_mm=4.57,
              sensor_height_mm=3.43, read_noise_e=2.0)
LUX = np.array([10.0, 100.0, 1000.0, 10000.0])


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_menons_flat_table_is_the_monochrome_model_with_less_light_and_a_higher_target(backend):
    # Menon's luminance MTF is 1 on grey edges (its table is flat): a Bayer sensor with it is
    # the monochrome model whose rate is t r and whose target is s g_c g_d, i.e. the lens
    # transmittance times t and snr_db + 10 log10(g_c g_d), up to rounding (1e-12)
    bayer = epc_fast.evaluate(LUX, **DESIGN, cfa="bayer", demosaic="menon2007", backend=backend)
    gain = cfa.DEFAULT_COLOR_NOISE_GAIN * cfa.DEMOSAIC_NOISE_GAIN["menon2007"]
    mono = epc_fast.evaluate(LUX, **DESIGN, lens_transmittance=cfa.DEFAULT_CFA_TRANSMITTANCE,
                             snr_db=30.0 + 10.0 * math.log10(gain), backend=backend)
    assert np.all(cfa.demosaic_mtf_table("menon2007").values == 1.0)
    np.testing.assert_allclose(bayer.epc, mono.epc, rtol=1e-12)
    np.testing.assert_allclose(bayer.t_mpe_s, mono.t_mpe_s, rtol=1e-13)


def test_the_demosaicker_multiplies_the_mtf_by_its_table_at_f_times_the_output_pitch():
    table = cfa.demosaic_mtf_table("bilinear")
    f = np.linspace(0.0, 700.0, 71)
    for pitch_um, k in ((1.4, 1), (0.7, 2)):  # the same output pitch: the same factor
        np.testing.assert_array_equal(mtf_demosaic(f, pitch_um * k, table), table(f * 1.4e-3))


def test_a_bayer_sensor_needs_1_over_t_more_light_for_the_same_shot_noise_exposure():
    # shot noise alone (no read noise) with Menon's table and g = 1 by color_noise_gain = 1/g_d:
    # t r T = the monochrome r T', so T = T' / t
    shot = {**DESIGN, "read_noise_e": 0.0, "shake_deg_per_s": 0.0}
    mono = epc_fast.evaluate(LUX, **shot, backend="reference")
    bayer = epc_fast.evaluate(LUX, **shot, cfa="bayer", demosaic="menon2007", cfa_transmittance=0.5,
                              color_noise_gain=1.0 / cfa.DEMOSAIC_NOISE_GAIN["menon2007"],
                              backend="reference")
    np.testing.assert_allclose(bayer.t_mpe_s, mono.t_mpe_s / 0.5, rtol=1e-14)
    np.testing.assert_allclose(bayer.electron_rate_e_per_s, 0.5 * mono.electron_rate_e_per_s,
                               rtol=1e-15)


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_a_color_sensor_falls_below_the_monochrome_sensor_of_its_own_silicon(demosaic):
    # t is against K's sensor (QE 0.7 on 480..580 nm only); the D5100's bare silicon, whose QE
    # is at least its channels' envelope, collects at least 1.80 K (tools/cfa_defaults.py)
    pytest.importorskip("colour")
    spec = importlib.util.spec_from_file_location("cfa_defaults", ROOT / "tools" /
                                                  "cfa_defaults.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    bare = tool.bare_silicon_at_least()
    assert bare == pytest.approx(1.795, abs=1e-3)
    k = bare * spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2
    silicon = epc_fast.evaluate(LUX, **DESIGN, electrons_per_lux_s_m2=k)
    bayer = epc_fast.evaluate(LUX, **DESIGN, cfa="bayer", demosaic=demosaic)
    assert np.all(bayer.epc < silicon.epc)


def test_against_ks_narrow_band_sensor_bilinear_interpolation_wins_in_dim_light():
    # K's sensor is not an upper bound: bilinear interpolation averages more noise
    # (g_c g_d = 0.56) than the filters lose light (t = 0.84) and costs MTF only near the
    # pixel's Nyquist frequency, which dim light's motion blur never reaches
    mono = epc_fast.evaluate(LUX, **DESIGN)
    bayer = epc_fast.evaluate(LUX, **DESIGN, cfa="bayer", demosaic="bilinear")
    assert np.all(bayer.epc[:2] > 2.0 * mono.epc[:2]) and bayer.epc[-1] < mono.epc[-1]


@pytest.mark.parametrize("kwargs, message", [
    (dict(cfa="rggb"), "cfa: one of 'none', 'bayer', 'quad_bayer', got 'rggb'"),
    (dict(cfa="bayer", demosaic="ahd"), "demosaic: one of 'bilinear', 'malvar2004', 'menon2007'"),
])
def test_bad_cfa_arguments_are_refused_naming_them(kwargs, message):
    with pytest.raises(ValueError, match=message):
        epc_fast.evaluate(100.0, **DESIGN, **kwargs)


def test_a_monochrome_sensor_behind_a_filter_takes_a_transmittance_too():
    # the transmittance is the rate's factor either way: with cfa="none" it is one more filter
    # in the light path, as lens_transmittance is
    filtered = epc_fast.evaluate(LUX, **DESIGN, cfa_transmittance=0.5)
    np.testing.assert_allclose(filtered.epc, epc_fast.evaluate(LUX, **DESIGN,
                                                               lens_transmittance=0.5).epc,
                               rtol=1e-14)


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_values_outside_the_cfa_domains_are_invalid(backend):
    r = epc_fast.evaluate(100.0, **DESIGN, cfa="bayer", backend=backend,
                          cfa_transmittance=[0.3, 0.0, 1.5, np.nan, 0.3, 0.3],
                          color_noise_gain=[1.0, 1.0, 1.0, 1.0, 0.001, 200.0])
    assert r.status.tolist() == [Status.OK] + [Status.INVALID] * 5
    with pytest.raises(ValueError, match="cfa_transmittance=1.5"):
        epc_fast.evaluate(100.0, **DESIGN, cfa="bayer", cfa_transmittance=1.5, invalid="raise",
                          backend=backend)


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_the_cfa_elasticities_are_the_central_differences_of_ln_epc(demosaic):
    # central differences at h = 1e-5 (truncation ~1e-10, rounding ~1e-11); the table's cubic
    # is smooth inside its segments, and no f50 here sits on a knot
    p = dict(DESIGN, illuminance_lux=LUX, cfa="bayer", demosaic=demosaic, backend="reference",
             cfa_transmittance=0.4, color_noise_gain=0.9)
    r = epc_fast.evaluate(**p, outputs=("epc", "status", "elasticities", "share_demosaic"))
    h = 1e-5
    for name in ("cfa_transmittance", "color_noise_gain", "pixel_pitch_um"):
        up = epc_fast.evaluate(**{**p, name: p[name] * (1 + h)}).epc
        down = epc_fast.evaluate(**{**p, name: p[name] * (1 - h)}).epc
        central = (np.log(up) - np.log(down)) / (2 * h)
        np.testing.assert_allclose(r.elasticities[name], central, rtol=1e-6, atol=1e-9,
                                   err_msg=name)
    # a transmittance is light: its elasticity is the illuminance's
    np.testing.assert_array_equal(r.elasticities["cfa_transmittance"],
                                  r.elasticities["illuminance_lux"])
    if demosaic == "menon2007":  # a flat table loses nothing
        assert np.all(r.share_demosaic == 0.0)
    else:
        assert np.all(r.share_demosaic >= 0.0) and np.any(r.share_demosaic > 0.05)
