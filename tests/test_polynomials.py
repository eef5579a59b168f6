"""The core's inlined sinpi/acos polynomials (cpp/include/epc_fast/polynomials.h) against mpmath."""

import mpmath as mp
import numpy as np

from epc_fast import _core

ULP = 2.0**-53


def test_core_sinc_is_within_4_ulp_of_mpmath_on_a_dense_grid():
    x = np.linspace(-3.0, 3.0, 6001)
    x = x[np.abs(x - np.round(x)) > 1e-3]  # away from the zeros, where relative error is moot
    exact = np.array([float(mp.sinpi(mp.mpf(v)) / (mp.pi * mp.mpf(v))) for v in x])
    # tools/fit_polynomials.py measures sinpi at <= 3 ulp; the division by pi x adds one.
    assert np.max(np.abs(_core.sinc(x) / exact - 1.0)) <= 4 * ULP


def test_core_sinc_keeps_relative_accuracy_next_to_its_zeros():
    # sinpi reduces x - round(x) exactly, so sinc stays accurate where sin(pi x) would not.
    x = np.array([1.0 + 1e-9, 2.0 - 1e-12, 3.0 + 2.0**-40])
    exact = np.array([float(mp.sinpi(mp.mpf(v)) / (mp.pi * mp.mpf(v))) for v in x])
    assert np.max(np.abs(_core.sinc(x) / exact - 1.0)) <= 8 * ULP


def test_core_diffraction_mtf_matches_mpmath_to_a_few_ulp_of_one():
    nu = np.linspace(0.0, 0.999, 4001)
    exact = np.array([float(2 / mp.pi * (mp.acos(v) - v * mp.sqrt(1 - v * v)))
                      for v in map(mp.mpf, nu)])
    core = _core.mtf_diffraction(nu)
    # acos via asin is <= 2 ulp; acos(nu) - nu sqrt(1 - nu^2) then cancels as nu -> 1, so the
    # error is absolute, a few ulp of 1 (libm's acos does no better: issue "extremes").
    assert np.max(np.abs(core - exact)) <= 4 * ULP
    # Where the MTF is >= 0.1 (nu <= 0.8, every f50 with threshold >= 0.1) an absolute error of
    # about one ulp of 1 is <= ~1.2e-15 relative; 2e-15 leaves room for rounding of the ratio.
    well = nu <= 0.8
    assert np.max(np.abs(core[well] / exact[well] - 1.0)) <= 2e-15
