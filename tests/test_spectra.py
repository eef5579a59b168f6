"""Tests for epc_fast.spectra: lux to electrons (docs/model.md, "Photometry: from lux to electrons") and diffraction weights."""

import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest

import epc_fast
from epc_fast import spectra
from helpers.child_env import with_python_path

# float64 sums in a different order from the mpmath reference: agreement to ~1e-15, checked to 1e-12.
RTOL_SUMMATION = 1e-12


def test_default_k_is_the_golden_reference_value():
    k = spectra.electrons_per_lux_s_m2()
    assert k == pytest.approx(2557705539053827.5, rel=RTOL_SUMMATION)
    assert spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2 == 2557705539053827.5


def test_full_weight_qe_edges_widen_the_band_and_raise_k_by_one_percent():
    qe = np.where((spectra.GRID_NM >= 480) & (spectra.GRID_NM <= 580), 0.7, 0.0)
    k = spectra.electrons_per_lux_s_m2(qe=qe, wavelengths_nm=spectra.GRID_NM)
    assert k == pytest.approx(2583008029115995.0, rel=RTOL_SUMMATION)


def test_default_qe_has_half_weight_edges():
    qe = spectra.default_qe([479.0, 480.0, 481.0, 530.0, 579.0, 580.0, 581.0])
    np.testing.assert_array_equal(qe, [0.0, 0.35, 0.7, 0.7, 0.7, 0.35, 0.0])


def test_flat_illuminant_and_flat_qe_match_the_closed_form():
    # S = 1, QE = 1: K = ∫ λ/(hc) dλ / (683 ∫ V dλ). The trapezoid rule is exact for the linear
    # λ, giving (780² − 380²)/2 nm²; ∫ V dλ is the trapezoid sum of the 1 nm CIE table, in mpmath.
    import colour

    v = colour.colorimetry.SDS_LEFS_PHOTOPIC["CIE 1924 Photopic Standard Observer"]
    table = dict(zip(v.wavelengths, v.values))
    with mpmath.workdps(30):
        samples = [mpmath.mpf(float(table[w])) for w in range(380, 781)]
        integral_v = sum(samples) - (samples[0] + samples[-1]) / 2
        h, c = mpmath.mpf("6.62607015e-34"), mpmath.mpf(299792458)
        integral_photons = mpmath.mpf(780**2 - 380**2) / 2 * mpmath.mpf("1e-9") / (h * c)
        expected = float(integral_photons / (683 * integral_v))

    ones = np.ones_like(spectra.GRID_NM)
    k = spectra.electrons_per_lux_s_m2(ones, qe=ones, wavelengths_nm=spectra.GRID_NM)
    assert k == pytest.approx(expected, rel=RTOL_SUMMATION)


def test_k_is_linear_in_qe():
    half = spectra.default_qe(spectra.GRID_NM) / 2
    k_half = spectra.electrons_per_lux_s_m2(qe=half)
    k_full = spectra.electrons_per_lux_s_m2(qe=2 * half)
    # Multiplying by 2 is exact in float64, so the two sums differ by exactly a factor 2.
    assert k_full == 2 * k_half


def test_k_does_not_depend_on_the_illuminant_scale():
    grid, d50 = spectra.illuminant("D50")
    k_by_name = spectra.electrons_per_lux_s_m2("D50")
    k_by_array = spectra.electrons_per_lux_s_m2(d50, wavelengths_nm=grid)
    k_scaled = spectra.electrons_per_lux_s_m2(7 * d50, wavelengths_nm=grid)
    assert k_by_array == k_by_name
    # E₁ is normalised to 1 lux; × 7 only changes rounding in the two integrals.
    assert k_scaled == pytest.approx(k_by_name, rel=1e-14)


def test_qe_may_be_a_callable():
    k = spectra.electrons_per_lux_s_m2(qe=spectra.default_qe)
    assert k == spectra.electrons_per_lux_s_m2()


def test_another_illuminant_gives_a_different_k():
    # Illuminant A is red-heavy: fewer electrons in the blue-green QE band per lux than D50.
    assert spectra.electrons_per_lux_s_m2("A") < 0.9 * spectra.electrons_per_lux_s_m2("D50")


def test_tables_are_interpolated_linearly_onto_the_1nm_grid():
    grid, d50 = spectra.illuminant("D50")
    np.testing.assert_array_equal(grid, np.arange(380.0, 781.0))
    # D50 is tabulated every 5 nm: 382 nm lies 2/5 of the way from 380 to 385.
    assert d50[2] == pytest.approx(0.6 * d50[0] + 0.4 * d50[5], rel=1e-15)
    v = spectra.photopic_luminosity()
    assert v.shape == grid.shape
    assert v[555 - 380] == pytest.approx(1.0, abs=1e-12)


def test_diffraction_weights_are_a_normalised_positive_spectrum_inside_the_band():
    spectrum = spectra.diffraction_spectrum(16)
    assert spectrum.weights.sum() == pytest.approx(1.0, rel=1e-15)
    assert np.all(spectrum.weights > 0)
    assert np.all((spectrum.wavelengths_nm > 480) & (spectrum.wavelengths_nm < 580))
    np.testing.assert_allclose(spectrum.wavelengths_nm, 480 + 6.25 * (np.arange(16) + 0.5),
                               rtol=1e-15)


def test_one_diffraction_sample_sits_at_the_band_centre():
    spectrum = spectra.diffraction_spectrum(1)
    np.testing.assert_array_equal(spectrum.wavelengths_nm, [530.0])
    np.testing.assert_array_equal(spectrum.weights, [1.0])


@pytest.mark.parametrize("n_samples", [1, 3, 16, 100, 257])
def test_splitting_the_band_loses_no_electrons(n_samples, monkeypatch):
    captured = {}
    original = spectra.Spectrum

    def capture(wavelengths_nm, weights):
        captured["weights"] = np.asarray(weights)
        return original(wavelengths_nm, weights)

    monkeypatch.setattr(spectra, "Spectrum", capture)
    spectra.diffraction_spectrum(n_samples)
    total = captured["weights"].sum()
    # Sub-band integrals telescope to the full trapezoid sum, up to float64 rounding.
    assert total == pytest.approx(spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2, rel=RTOL_SUMMATION)


def test_a_custom_band_places_samples_inside_it():
    spectrum = spectra.diffraction_spectrum(4, band_nm=(500.0, 540.0))
    np.testing.assert_allclose(spectrum.wavelengths_nm, [505.0, 515.0, 525.0, 535.0], rtol=1e-15)


def test_spectrum_stores_normalised_read_only_weights():
    spectrum = spectra.Spectrum(np.array([450.0, 550.0]), np.array([1.0, 3.0]))
    np.testing.assert_array_equal(spectrum.weights, [0.25, 0.75])
    with pytest.raises(ValueError):
        spectrum.weights[0] = 1.0
    mono = spectra.Spectrum.monochromatic(550.0)
    np.testing.assert_array_equal(mono.wavelengths_nm, [550.0])
    np.testing.assert_array_equal(mono.weights, [1.0])


@pytest.mark.parametrize("wavelengths, weights, match", [
    ([], [], r"Spectrum\.wavelengths_nm: must not be empty"),
    ([[500.0]], [1.0], r"Spectrum\.wavelengths_nm: must be 1-D"),
    ([500.0, -1.0], [1.0, 1.0], r"Spectrum\.wavelengths_nm: .*-1\.0"),
    ([500.0, np.nan], [1.0, 1.0], r"Spectrum\.wavelengths_nm: .*nan"),
    ([500.0, 600.0], [1.0], r"Spectrum\.weights: length 1"),
    ([500.0, 600.0], [1.0, -0.5], r"Spectrum\.weights: .*-0\.5"),
    ([500.0, 600.0], [1.0, np.inf], r"Spectrum\.weights: .*inf"),
    ([500.0, 600.0], [0.0, 0.0], r"Spectrum\.weights: must have a positive sum"),
])
def test_spectrum_rejects_bad_fields_by_name(wavelengths, weights, match):
    with pytest.raises(ValueError, match=match):
        spectra.Spectrum(np.array(wavelengths, dtype=float), np.array(weights, dtype=float))


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match=r"illuminant: unknown illuminant 'D51'"):
        spectra.electrons_per_lux_s_m2("D51")
    with pytest.raises(ValueError, match=r"name: unknown illuminant"):
        spectra.illuminant("nope")
    with pytest.raises(ValueError, match=r"name: .*covers 350\.\.690 nm"):
        spectra.illuminant("ISO 7589 Studio Tungsten")
    with pytest.raises(ValueError, match=r"wavelengths_nm: required"):
        spectra.electrons_per_lux_s_m2(np.ones(401))
    with pytest.raises(ValueError, match=r"qe: must be in \[0, 1\].*70\.0"):
        spectra.electrons_per_lux_s_m2(qe=np.full(401, 70.0))
    with pytest.raises(ValueError, match=r"qe: has 3 samples"):
        spectra.electrons_per_lux_s_m2(qe=[0.1, 0.2, 0.3])
    with pytest.raises(TypeError, match=r"qe: must be None"):
        spectra.electrons_per_lux_s_m2(qe="flat")
    with pytest.raises(ValueError, match=r"wavelengths_nm: must be strictly increasing"):
        spectra.electrons_per_lux_s_m2(np.ones(3), wavelengths_nm=[500.0, 500.0, 510.0])
    with pytest.raises(ValueError, match=r"n_samples: must be >= 1"):
        spectra.diffraction_spectrum(0)
    with pytest.raises(ValueError, match=r"band_nm: must satisfy"):
        spectra.diffraction_spectrum(4, band_nm=(600.0, 500.0))


def test_importing_spectra_does_not_import_colour():
    root = Path(__file__).resolve().parents[1]
    code = "import sys, epc_fast.spectra; assert 'colour' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], cwd=root, check=True,
                   env=with_python_path(root / "python"))


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_a_spectrum_with_its_weight_on_one_wavelength_is_that_monochromatic_call(backend):
    # design.one_wavelength: 1 D + 0 D' = D, so the monochromatic model at that wavelength, which
    # the core solves on its monochromatic path (the accurate f50 start): the same bits.
    from epc_fast.selfcheck import random_designs

    d = random_designs(3000, seed=21)
    mono = epc_fast.evaluate(**d, wavelength_nm=620.0, backend=backend)
    for spectrum in (spectra.Spectrum([620.0], [1.0]), ([450.0, 620.0, 700.0], [0.0, 2.0, 0.0])):
        one = epc_fast.evaluate(**d, spectrum=spectrum, backend=backend)
        for field in ("t_mpe_s", "f50_cyc_per_mm", "epc", "status"):
            assert np.array_equal(getattr(one, field), getattr(mono, field), equal_nan=True)


def test_a_one_wavelength_spectrum_agrees_with_the_polychromatic_reference():
    # The reference's sum over the spectrum, zero weights included, is the same model: the
    # routed core call must agree with it as any core call does with the reference.
    from epc_fast.selfcheck import random_designs

    d = random_designs(3000, seed=22)
    spectrum = ([450.0, 620.0], [0.0, 1.0])
    core = epc_fast.evaluate(**d, spectrum=spectrum)
    ref = epc_fast.evaluate(**d, spectrum=spectrum, backend="reference")
    ok = ref.status == epc_fast.Status.OK
    assert np.array_equal(core.status, ref.status) and ok.sum() > 1500
    # f50_rtol 1e-14 plus both engines' rounding of these well-conditioned phones
    assert np.max(np.abs(core.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)) <= 4e-14
