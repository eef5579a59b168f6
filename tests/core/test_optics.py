"""The core's wavefront error and denoising (cpp/include/epc_fast/aberration.h, denoise.h):
off is today's kernel bit for bit, on agrees with the NumPy reference (the random-domain
comparisons are in tests/test_core_vs_reference.py and tests/test_sensitivity.py), the domains'
ends, and points whose neighbours have the terms."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast.params import DENOISE_SIGMA_PX_MAX, WAVEFRONT_RMS_WAVES_MAX

DESIGN = dict(pixel_pitch_um=1.4, f_number=2.4, focal_length_mm=4.0, pixel_count=8e6,
              read_noise_e=2.0)
LUX = np.geomspace(0.1, 1e5, 16)
FIELDS = ("electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc")


@pytest.mark.parametrize("precision", ["float64", "float32"])
@pytest.mark.parametrize("name, value", [("wavefront_rms_waves", 0.1), ("denoise_sigma_px", 1.3)])
def test_points_without_the_term_keep_their_bits_beside_points_with_it(name, value, precision):
    # a block whose lanes mix the term on and off: the off lanes multiply by ATF = 1 and H = 1
    # exactly and keep their certified starts, so they are the default call's, bit for bit
    plain = epc_fast.evaluate(LUX, **DESIGN, precision=precision)
    mixed = epc_fast.evaluate(LUX, **DESIGN, precision=precision,
                              **{name: np.where(np.arange(16) % 2 == 0, 0.0, value)})
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(mixed, field)[::2], getattr(plain, field)[::2],
                                      err_msg=field)
    moving = plain.epc[1::2] > 0  # (0.1 lux: the blur is unbounded, EPC 0 either way)
    assert moving.sum() >= 6 and np.all(mixed.epc[1::2][moving] != plain.epc[1::2][moving])


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_the_domains_ends_are_valid_and_agree(backend):
    r = epc_fast.evaluate(LUX, wavefront_rms_waves=WAVEFRONT_RMS_WAVES_MAX,
                          denoise_sigma_px=DENOISE_SIGMA_PX_MAX, **DESIGN, backend=backend)
    assert np.all(r.status == Status.OK) and np.all(np.isfinite(r.epc)) and np.all(r.epc > 0)
    ref = epc_fast.evaluate(LUX, wavefront_rms_waves=WAVEFRONT_RMS_WAVES_MAX,
                            denoise_sigma_px=DENOISE_SIGMA_PX_MAX, **DESIGN, backend="reference")
    # a 801-tap filter: the two sum its taps in other orders, ~1e-15; f50 solved to 1e-14
    np.testing.assert_allclose(r.f50_cyc_per_mm, ref.f50_cyc_per_mm, rtol=1e-12)


@pytest.mark.parametrize("value", [5e-324, 2.2e-310])
def test_subnormal_values_are_the_terms_off_in_the_core(value):
    # (W / 0.18)^2 underflows to 0 and exp(-1 / (2 sigma^2)) to 0: ATF = 1, the kernel (1) and
    # its noise gain 1, so the exposure is the same bits; f50 is the same root, but found by
    # Halley's steps rather than the certified start the term's lanes do not take: within
    # f50_rtol (1e-14) of each other, 1e-13 for EPC's square
    plain = epc_fast.evaluate(LUX, **DESIGN)
    for name in ("wavefront_rms_waves", "denoise_sigma_px"):
        r = epc_fast.evaluate(LUX, **DESIGN, **{name: value})
        for field in ("electrons", "t_mpe_s", "blur_mm"):
            np.testing.assert_array_equal(getattr(r, field), getattr(plain, field))
        np.testing.assert_allclose(r.f50_cyc_per_mm, plain.f50_cyc_per_mm, rtol=5e-14)
        np.testing.assert_allclose(r.epc, plain.epc, rtol=1e-13)


def test_values_outside_the_domain_are_invalid_in_the_core():
    r = epc_fast.evaluate(100.0, **DESIGN, wavefront_rms_waves=[0.0, -1e-3, np.nan, 0.17, 0.05],
                          denoise_sigma_px=[0.0, 0.0, 0.0, 0.0, 101.0])
    assert r.status.tolist() == [Status.OK] + [Status.INVALID] * 4
    with pytest.raises(ValueError, match="denoise_sigma_px=-1.0"):
        epc_fast.evaluate(100.0, **DESIGN, denoise_sigma_px=-1.0, invalid="raise")


@pytest.mark.parametrize("f50_solver", ["halley", "newton", "brent", "bisection"])
def test_a_wide_filter_whose_transfer_vanishes_past_f50_is_solved_by_every_solver(f50_solver):
    # sigma = 16 output pixels on a binned pixel: past f50 H falls below 1e-300, where its sum
    # of cosines is rounding noise; the derivative solvers bisect there instead of trusting it
    p = dict(illuminance_lux=111889.9, pixel_pitch_um=0.4546, f_number=7.868,
             focal_length_mm=86.49, sensor_area_mm2=320.9, fill_factor=0.0768,
             wavelength_nm=495.9, mtf_threshold=0.4972, binning=8.0,
             wavefront_rms_waves=0.0689, denoise_sigma_px=16.01)
    ref = epc_fast.evaluate(**p, backend="reference").f50_cyc_per_mm
    core = epc_fast.evaluate(**p, f50_solver=f50_solver).f50_cyc_per_mm
    np.testing.assert_allclose(core, ref, rtol=1e-12)
