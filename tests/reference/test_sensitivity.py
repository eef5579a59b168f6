"""The NumPy reference's sensitivities (epc_fast.reference.sensitivity): the zeta constants of
its series, ln sinc and the diffraction loss with their slopes, against mpmath."""

from __future__ import annotations

import mpmath
import pytest

import epc_fast
from epc_fast.reference import sensitivity as rs
from helpers.mp_model import mp_diffraction


def test_zeta_constants_are_mpmaths_rounded():
    assert rs.ZETA_EVEN == tuple(float(mpmath.zeta(2 * k)) for k in range(1, 16))


Y_GRID = [1e-300, 1e-9, 1e-3, 0.1, 0.2499, 0.25, 0.2501, 0.5, 0.9, 0.999999]


@pytest.mark.parametrize("y", Y_GRID)
def test_log_sinc_and_its_slope_match_mpmath(y):
    with mpmath.workdps(40):
        sinc = mpmath.sincpi(mpmath.mpf(y))
        log_sinc = mpmath.log(sinc)
        slope = mpmath.mpf(y) * mpmath.diff(lambda t: mpmath.log(mpmath.sincpi(t)), mpmath.mpf(y))
    # both are formed from a few roundings where nothing cancels (series below 1/4): 1e-14
    assert rs.log_sinc(y) == pytest.approx(float(log_sinc), rel=1e-14, abs=1e-320)
    assert rs.sinc_log_slope(y) == pytest.approx(float(slope), rel=1e-14, abs=1e-320)


@pytest.mark.parametrize("nu", [1e-12, 1e-6, 0.1, 0.5, 0.5000001, 0.9, 0.999999])
def test_diffraction_loss_and_slope_match_mpmath(nu):
    with mpmath.workdps(40):
        v = mpmath.mpf(nu)
        d = mp_diffraction(v)
        slope = v * mpmath.diff(mp_diffraction, v)
    assert rs.diffraction_loss(nu) == pytest.approx(float(1 - d), rel=1e-14)
    value = epc_fast.reference.mtf_diffraction(nu, 1e6, 1.0)  # nu = f (1e6 nm) (F = 1)
    assert rs.log_mtf_diffraction(value, rs.diffraction_loss(nu)) == pytest.approx(
        float(mpmath.log(d)), rel=1e-13)
    assert rs.diffraction_log_slope_numerator(nu) == pytest.approx(float(slope), rel=1e-13)
