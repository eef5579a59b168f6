"""The exposure stage's vector path (exposure/stage.h): the electron rate and T_MPE come out
rounded as their formulas say, step by step, however the core forms its quotients (one
reciprocal shared by the quotients with the same divisor, each corrected to the correctly
rounded one)."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status


def _designs(n, seed):
    rng = np.random.default_rng(seed)

    def log_uniform(lo, hi):
        return np.exp(rng.uniform(np.log(lo), np.log(hi), n))

    return {
        "illuminance_lux": log_uniform(1e-3, 1e6),
        "pixel_pitch_um": log_uniform(0.3, 30.0),
        "f_number": log_uniform(0.6, 90.0),
        "focal_length_mm": rng.uniform(2.0, 200.0, n),
        "sensor_area_mm2": rng.uniform(1.0, 900.0, n),
        "read_noise_e": np.where(rng.random(n) < 0.3, 0.0, log_uniform(0.1, 50.0)),
        "dark_current_e_per_s": np.where(rng.random(n) < 0.3, 0.0, log_uniform(1e-3, 1e4)),
        "shake_deg_per_s": rng.uniform(0.0, 20.0, n),
        "reflectance": rng.uniform(0.05, 1.0, n),
        "lens_transmittance": rng.uniform(0.3, 1.0, n),
        "fill_factor": rng.uniform(0.2, 1.0, n),
        "electrons_per_lux_s_m2": log_uniform(1e14, 1e16),
        "full_well_e": np.inf,
    }


@pytest.mark.parametrize("seed", [1, 2])
def test_the_rate_is_its_product_rounded_at_every_step(seed):
    """r = L R tau cos^4 K a p^2 1e-12 / 4 / F / F (electron_rate's order; field angle 0, so
    cos = 1 exactly): NumPy's IEEE products and quotients in that order give the same bits."""
    d = _designs(200_000, seed)
    r = epc_fast.evaluate(**d)
    expected = d["illuminance_lux"] * d["reflectance"] * d["lens_transmittance"] * 1.0 * 1.0
    for factor in (d["electrons_per_lux_s_m2"], d["fill_factor"], d["pixel_pitch_um"],
                   d["pixel_pitch_um"], 1e-12):
        expected = expected * factor
    expected = expected / 4.0 / d["f_number"] / d["f_number"]
    np.testing.assert_array_equal(r.electron_rate_e_per_s, expected)


@pytest.mark.parametrize("seed", [3, 4])
def test_t_mpe_is_the_electrons_over_the_rate_rounded_once(seed):
    """T_MPE = electrons / rate, one correctly rounded quotient of the two outputs, wherever
    the SNR target is reached."""
    d = _designs(200_000, seed)
    r = epc_fast.evaluate(**d)
    reached = np.isin(r.status, [Status.OK, Status.BLUR_UNBOUNDED])
    assert np.count_nonzero(reached) > 150_000  # the test needs lanes to look at
    np.testing.assert_array_equal(r.t_mpe_s[reached],
                                  r.electrons[reached] / r.electron_rate_e_per_s[reached])
