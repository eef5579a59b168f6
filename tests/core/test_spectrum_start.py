"""The f50 start fitted to a call's spectrum (cpp/include/epc_fast/f50/spectrum_fit.h) against the
exact f50, its determinism, and the solve it starts."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, _core
from epc_fast.selfcheck import random_designs
from epc_fast.spectra import diffraction_spectrum
from helpers.f50_cases import exact_f50, lengths

THRESHOLDS = (0.5, 0.3, 0.2, 0.1)

#: The fitted start's largest relative error per threshold for the default spectra (D50 and
#: the default QE, 480..580 nm), over lengths spanning e^-9..e^9: measured 1.0e-7, 1.9e-6,
#: 7.9e-6 and 8.5e-5 (16 wavelengths; 4 and 64 within 1%), with room for the rounding of the
#: lengths. Halley's stop test (f50/solvers.h) accepts its first step from up to about 1e-5 at the
#: default tolerance: MTF50 to MTF20 stop after one evaluation of the MTF, MTF10 after two.
SPECTRUM_BOUND = {0.5: 2e-7, 0.3: 2.5e-6, 0.2: 1e-5, 0.1: 1.2e-4}


def _exact_f50(spectrum, f_number, aperture_mm, blur_mm, threshold):
    """The reference's f50 with the spectrum, from lengths."""
    return exact_f50(f_number, aperture_mm, blur_mm, 0.0, threshold, spectrum.wavelengths_nm,
                     spectrum.weights)


def _start(spectrum, lambda_f, aperture, blur, threshold):
    return _core.testing.f50_spectrum_start(spectrum.wavelengths_nm, spectrum.weights, lambda_f,
                                            aperture, blur, np.full(len(lambda_f), threshold))


@pytest.mark.parametrize("samples", [4, 16, 64])
@pytest.mark.parametrize("threshold", THRESHOLDS)
def test_the_spectrum_start_is_within_its_bound_everywhere(samples, threshold):
    spectrum = diffraction_spectrum(samples)
    mean_nm = float(np.sum(spectrum.weights * spectrum.wavelengths_nm))
    f_number, lambda_f, aperture, blur = lengths(5_000, seed=samples, wavelength_nm=mean_nm)
    exact = _exact_f50(spectrum, f_number, aperture, blur, threshold)
    error = np.max(np.abs(_start(spectrum, lambda_f, aperture, blur, threshold) / exact - 1))
    assert error <= SPECTRUM_BOUND[threshold]
    # the fit's own report agrees in size (its nodes are a subset of the domain)
    fit_error = _core.testing.spectrum_start(spectrum.wavelengths_nm, spectrum.weights)["fit_error"]
    assert fit_error[THRESHOLDS.index(threshold)] <= SPECTRUM_BOUND[threshold]
    # and it is that threshold's fit: the cubic start, the alternative, is far coarser
    cubic = _core.testing.f50_cubic_start(lambda_f, aperture, blur, 0.0, threshold)
    assert np.max(np.abs(cubic / exact - 1)) > 10 * error


def test_one_wavelength_fits_the_monochromatic_accurate_start():
    # The same function fitted twice: offline by minimax on 140^2 nodes (f50/guesses.h's rows,
    # within 4.2e-8 .. 5.2e-5), and here by least squares on 24^2; the two polynomials agree
    # within the sum of their errors.
    spectrum = epc_fast.Spectrum([550.0], [1.0])
    f_number, lambda_f, aperture, blur = lengths(5_000, seed=7, wavelength_nm=550.0)
    for threshold, bound in zip(THRESHOLDS, (2e-7, 4e-6, 2e-5, 2e-4)):
        fitted = _start(spectrum, lambda_f, aperture, blur, threshold)
        offline = _core.testing.f50_start(lambda_f, aperture, blur, 0.0, threshold)
        assert np.max(np.abs(fitted / offline - 1)) <= bound, threshold


def test_the_fit_is_the_same_bits_every_time():
    # a point's result must not depend on its call: the fit is a fixed sequence of operations
    # on the spectrum's values, whether it comes from the cache or is fitted again after others
    # pushed it out (the cache keeps 8)
    spectrum = diffraction_spectrum(12)
    first = _core.testing.spectrum_start(spectrum.wavelengths_nm, spectrum.weights)["coefficients"]
    for samples in range(20, 30):
        other = diffraction_spectrum(samples)
        _core.testing.spectrum_start(other.wavelengths_nm, other.weights)
    again = _core.testing.spectrum_start(spectrum.wavelengths_nm, spectrum.weights)["coefficients"]
    assert np.array_equal(first.view(np.uint64), again.view(np.uint64))
    assert first.shape == (4, 36) and np.all(np.isfinite(first))


def test_a_point_gets_the_same_bits_alone_and_in_a_large_call():
    spectrum = diffraction_spectrum(8)
    designs = random_designs(3_000, seed=11)
    whole = epc_fast.evaluate(**designs, spectrum=spectrum, threads=2)
    for i in (0, 1234, 2999):
        alone = epc_fast.evaluate(**{k: v[i:i + 1] for k, v in designs.items()},
                                  spectrum=spectrum, threads=1)
        assert alone.f50_cyc_per_mm[0].tobytes() == whole.f50_cyc_per_mm[i].tobytes()


@pytest.mark.parametrize("f50_solver", ["halley", "newton"])
@pytest.mark.parametrize("threshold", THRESHOLDS)
def test_the_solve_from_it_matches_the_reference(f50_solver, threshold):
    spectrum = diffraction_spectrum(8)
    designs = random_designs(2_000, seed=12)
    core = epc_fast.evaluate(**designs, spectrum=spectrum, mtf_threshold=threshold,
                             f50_solver=f50_solver)
    ref = epc_fast.evaluate(**designs, spectrum=spectrum, mtf_threshold=threshold,
                            backend="reference")
    assert np.array_equal(core.status, ref.status)
    ok = core.status == Status.OK
    assert ok.sum() > 1_000
    # f50_rtol 1e-14 times the blur's condition number, under 5 in these designs
    # (tests/test_core_vs_reference.py states the bound in general)
    assert np.max(np.abs(core.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)) <= 1e-13


def test_a_spectrum_the_polynomial_fits_badly_still_converges_to_the_reference():
    # 400 and 1000 nm, equal weights: the long wavelength's cut-off puts a kink into the MTF
    # where MTF20 and MTF10 lie, and the fit there is coarse (3.7e-3 and 4.0e-3, 50 times the
    # default spectrum's). The start decides only how many steps the solver takes.
    spectrum = epc_fast.Spectrum([400.0, 1000.0], [0.5, 0.5])
    fit_error = _core.testing.spectrum_start(spectrum.wavelengths_nm, spectrum.weights)["fit_error"]
    assert fit_error[2] > 1e-3 and fit_error[3] > 1e-3  # the case this test is about
    designs = random_designs(2_000, seed=13)
    for threshold in THRESHOLDS:
        core = epc_fast.evaluate(**designs, spectrum=spectrum, mtf_threshold=threshold)
        ref = epc_fast.evaluate(**designs, spectrum=spectrum, mtf_threshold=threshold,
                                backend="reference")
        assert np.array_equal(core.status, ref.status)
        ok = core.status == Status.OK
        assert np.max(np.abs(core.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)) <= 1e-13


@pytest.mark.parametrize("wavelengths, weights, message", [
    ([], [], "non-empty"),
    ([500.0, 600.0], [1.0], "one length"),
    ([500.0, -600.0], [0.5, 0.5], "positive"),
    ([500.0, 600.0], [0.5, np.nan], "non-negative"),
    ([500.0, 600.0], [0.0, 0.0], "all be 0"),
])
def test_bad_spectra_are_refused_by_name(wavelengths, weights, message):
    with pytest.raises(ValueError, match=message):
        _core.testing.spectrum_start(np.array(wavelengths, dtype=float),
                                     np.array(weights, dtype=float))
