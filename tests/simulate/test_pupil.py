"""The lens's OTF from its sampled pupil against the closed form of the aberration-free
circular pupil (docs/model.md, "System MTF"): the simulator computes it by FFT and never from
that formula, so the formula can check it."""

import numpy as np
import pytest

from epc_fast.simulate import pupil


def closed_form(nu):
    nu = np.minimum(np.asarray(nu, dtype=float), 1.0)
    return (2 / np.pi) * (np.arccos(nu) - nu * np.sqrt(1 - nu ** 2))


def test_the_sampled_pupils_otf_is_the_circular_pupils():
    nu, otf = pupil.otf_profile()
    # A disc of 480 samples' radius: its autocorrelation counts lattice cells, within 5e-5 of
    # the continuous discs' overlap at every lag (measured 4.4e-5: the count's error is of the
    # order of the boundary's length over the area, 2 / R = 4e-3, times the lattice's
    # cancellation).
    assert np.max(np.abs(otf - closed_form(nu))) < 5e-5
    assert otf[0] == 1.0 and otf[-1] == 0.0 and nu[-1] > 1.0


def test_the_pupil_is_a_disc_of_its_radius():
    p = pupil.pupil(100)
    # Cells counted inside a circle of radius 100: pi r^2 within the lattice count's error,
    # under 4 r (Gauss's circle problem) here.
    assert abs(p.sum() - np.pi * 100 ** 2) < 400
    assert p.shape[0] >= 404


@pytest.mark.parametrize("wavelength_nm, f_number", [(550.0, 2.8), (450.0, 1.8), (700.0, 8.0)])
def test_one_wavelengths_transfer_scales_with_lambda_f(wavelength_nm, f_number):
    cutoff = 1 / (wavelength_nm * 1e-6 * f_number)
    f = np.linspace(0, 1.2 * cutoff, 301)
    got = pupil.diffraction_transfer(f, f_number, [wavelength_nm], [1.0])
    # The profile's 5e-5 plus linear interpolation between lags 1/960 apart (under 1e-6 where
    # the OTF is smooth; near the cut-off it goes as (1 - nu)^1.5).
    assert np.max(np.abs(got - closed_form(f / cutoff))) < 1e-4
    assert np.all(got[f > cutoff * (1 + 1e-12)] == 0.0)
    assert pupil.cutoff_cyc_per_mm(f_number, wavelength_nm) == pytest.approx(cutoff)


def test_a_spectrums_transfer_is_its_wavelengths_weighted():
    wavelengths, weights = np.array([480.0, 530.0, 580.0]), np.array([0.2, 0.5, 0.3])
    f = np.linspace(0, 800, 401)
    got = pupil.diffraction_transfer(f, 2.8, wavelengths, weights)
    want = sum(w * pupil.diffraction_transfer(f, 2.8, [l], [1.0])
               for l, w in zip(wavelengths, weights))
    # One profile resampled 16 times finer, then interpolated once: 1e-5 of the direct sum.
    assert np.max(np.abs(got - want)) < 1e-5


@pytest.mark.parametrize("aberration", ["defocus", "spherical"])
def test_a_wavefront_error_lowers_the_otf_and_keeps_its_ends(aberration):
    nu, clean = pupil.otf_profile()
    nu, aberrated = pupil.otf_profile(0.1, aberration)
    assert aberrated[0] == pytest.approx(1.0) and aberrated[-1] == 0.0
    inside = (nu > 0.02) & (nu < 0.98)
    assert np.all(aberrated[inside] < clean[inside])


def test_defocus_of_a_quarter_wave_peak_to_valley_is_the_textbook_one():
    # Defocus W020 = lambda/4 peak to valley is W_rms = 0.25 / (2 sqrt 3) = 0.0722 waves; its
    # Strehl ratio, the volume of the OTF over the aberration-free one's, is about 0.80 for
    # small aberrations: exp(-(2 pi W_rms)^2) = 0.814 (Marechal), the exact value 0.811.
    nu, clean = pupil.otf_profile()
    nu, defocused = pupil.otf_profile(0.25 / (2 * np.sqrt(3)), "defocus")
    strehl = np.trapezoid(defocused * nu, nu) / np.trapezoid(clean * nu, nu)
    assert abs(strehl - 0.811) < 0.005


def test_a_lens_tables_transfer_is_its_interpolant_up_to_its_end_and_0_beyond():
    from epc_fast.mtf_table import mtf_table

    # a diffraction MTF tabulated at 400 points: the table's transfer is the pupil's within the
    # pupil profile's 5e-5 and the interpolant's 1e-8 (tests/reference/test_lens.py)
    cutoff = 1 / (550e-6 * 2.8)
    f = np.linspace(0, cutoff, 400)
    m = closed_form(f / cutoff)
    m[-1] = 0.0
    table = mtf_table("lens_mtf", (f, m))
    grid = np.linspace(0, 1.2 * cutoff, 301)
    transfer = pupil.diffraction_transfer(grid, 2.8, [550.0], [1.0])
    assert np.max(np.abs(pupil.table_transfer(grid, table) - transfer)) < 1e-4
    assert pupil.table_cutoff_cyc_per_mm(table) == f[-1]
    # a table that ends above 0: the lens passes nothing past its last frequency
    short = mtf_table("lens_mtf", ([0.0, 50.0, 100.0], [1.0, 0.7, 0.4]))
    got = pupil.table_transfer(np.array([0.0, 75.0, 100.0, 100.5]), short)
    # (at the last knot the last segment's cubic, to its rounding)
    assert got[0] == 1.0 and 0.4 < got[1] < 0.7 and got[3] == 0.0
    assert got[2] == pytest.approx(0.4, abs=1e-15)
    assert pupil.table_cutoff_cyc_per_mm(short) == 100.0
