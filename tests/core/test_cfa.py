"""The core's colour filter array (cpp/include/epc_fast/cfa.h: the rate times t, the noise gain,
the demosaicker's table and its share; the elasticities in log_slopes.h) against the
NumPy reference on random designs, every demosaicker, both precisions."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, cfa
from helpers.backend_agreement import assert_backends_agree
from helpers.designs import random_design_points

SHARES = tuple(f"share_{n}" for n in epc_fast.outputs.SHARE_NAMES)


def _bayer_points(n, seed):
    p = random_design_points(n, seed, sensor_terms=True, optics_terms=True)
    rng = np.random.default_rng([seed, 42])
    p["cfa_transmittance"] = rng.uniform(0.2, 1.0, n)
    p["color_noise_gain"] = rng.uniform(0.5, 2.0, n)
    return p


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_the_core_agrees_with_the_reference_for_a_bayer_sensor(demosaic):
    p = _bayer_points(10_000, 43)
    core = epc_fast.evaluate(**p, cfa="bayer", demosaic=demosaic)
    ref = epc_fast.evaluate(**p, cfa="bayer", demosaic=demosaic, backend="reference")
    assert_backends_agree(p, core, ref, f"bayer, {demosaic}")
    assert np.count_nonzero(ref.status == Status.OK) > 2_000


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_the_bayer_shares_and_elasticities_agree_with_the_reference(precision):
    p = _bayer_points(5_000, 44)
    asked = ("epc", "status", "elasticities") + SHARES
    core = epc_fast.evaluate(**p, cfa="bayer", demosaic="bilinear", outputs=asked,
                             precision=precision)
    ref = epc_fast.evaluate(**p, cfa="bayer", demosaic="bilinear", outputs=asked,
                            backend="reference")
    ok = ref.status == Status.OK
    # float64: both solve f50 to ~1e-14 and form the same ratios; float32: its f50's 5e-7
    rtol = 1e-9 if precision == "float64" else 1e-4
    for name in SHARES:
        np.testing.assert_allclose(getattr(core, name)[ok], getattr(ref, name)[ok], rtol=0,
                                   atol=rtol, err_msg=name)
    for name in core.elasticities:
        a, b = core.elasticities[name][ok], ref.elasticities[name][ok]
        if name in ("binning", "frames", "lens", "binning_readout"):  # whole numbers: NaN
            continue
        assert np.all(np.abs(a - b) <= rtol * np.maximum(np.abs(b), 1e-3)), name


def test_the_monochrome_default_is_the_same_bits_with_cfa_none_given():
    p = random_design_points(3_000, 45)
    plain = epc_fast.evaluate(**p)
    given = epc_fast.evaluate(**p, cfa="none", cfa_transmittance=1.0, color_noise_gain=1.0)
    for name in ("electron_rate_e_per_s", "t_mpe_s", "f50_cyc_per_mm", "epc", "status"):
        np.testing.assert_array_equal(getattr(given, name), getattr(plain, name))
