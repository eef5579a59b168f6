"""The core's inlined sinpi/acos polynomials (cpp/include/epc_fast/polynomials.h) against mpmath."""

import mpmath as mp
import numpy as np

from epc_fast import _core
from helpers.mp_model import mp_diffraction

ULP = 2.0**-53


def test_core_sinc_is_within_4_ulp_of_mpmath_on_a_dense_grid():
    x = np.linspace(-3.0, 3.0, 6001)
    x = x[np.abs(x - np.round(x)) > 1e-3]  # away from the zeros, where relative error is moot
    exact = np.array([float(mp.sinpi(mp.mpf(v)) / (mp.pi * mp.mpf(v))) for v in x])
    # tools/fit_polynomials.py measures sinpi at <= 3 ulp; the division by pi x adds one.
    assert np.max(np.abs(_core.testing.sinc(x) / exact - 1.0)) <= 4 * ULP


def test_core_sinc_keeps_relative_accuracy_next_to_its_zeros():
    # sinpi reduces x - round(x) exactly, so sinc stays accurate where sin(pi x) would not.
    x = np.array([1.0 + 1e-9, 2.0 - 1e-12, 3.0 + 2.0**-40])
    exact = np.array([float(mp.sinpi(mp.mpf(v)) / (mp.pi * mp.mpf(v))) for v in x])
    assert np.max(np.abs(_core.testing.sinc(x) / exact - 1.0)) <= 8 * ULP


def test_core_diffraction_mtf_is_within_8_ulp_of_mpmath_up_to_the_cutoff():
    nu = np.linspace(0.0, 0.999999, 6001)
    with mp.workdps(40):  # acos(nu) - nu sqrt(1 - nu^2) cancels near 1: the reference needs digits
        exact = np.array([float(mp_diffraction(v)) for v in nu])
    # The core writes D in the half-angle form, which keeps relative accuracy up to nu -> 1;
    # its polynomial is <= 6 ulp (tools/fit_polynomials.py), 8 leaves room for the final rounding.
    assert np.max(np.abs(_core.testing.mtf_diffraction(nu) / exact - 1.0)) <= 8 * ULP
