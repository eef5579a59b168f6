"""gather.h gather: a thread's first block sets up the broadcast columns (ColumnLayout), the
blocks after it with the same columns read only the varying ones. Every block must come out as
if it had been read on its own: the same bits as calls of one block each."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status

N = 64 * 37 + 5  # many blocks per thread, and a partial last one


def _designs(seed):
    rng = np.random.default_rng(seed)
    return {"illuminance_lux": rng.uniform(1.0, 1e4, N), "pixel_pitch_um": rng.uniform(0.6, 3.0, N),
            "f_number": rng.uniform(1.4, 8.0, N), "focal_length_mm": 4.0,
            "sensor_area_mm2": 20.0, "read_noise_e": 2.0, "shake_deg_per_s": rng.uniform(0, 8, N)}


@pytest.mark.parametrize("threads", [1, 2])
def test_every_block_of_a_call_is_read_as_a_block_alone(threads):
    designs = _designs(3)
    whole = epc_fast.evaluate(**designs, threads=threads)
    for start in range(0, N, 64 * 5):  # calls of one block at several offsets
        part = {k: v[start:start + 64] if np.ndim(v) else v for k, v in designs.items()}
        alone = epc_fast.evaluate(**part, threads=1)
        for name in ("epc", "t_mpe_s", "f50_cyc_per_mm", "status"):
            np.testing.assert_array_equal(getattr(whole, name)[start:start + 64],
                                          getattr(alone, name), err_msg=name)


@pytest.mark.parametrize("threads", [1, 2])
def test_a_broadcast_value_outside_its_domain_makes_every_block_invalid(threads):
    designs = _designs(4)
    result = epc_fast.evaluate(**designs, reflectance=1.5, threads=threads)
    assert np.all(result.status == Status.INVALID)
    assert np.all(np.isnan(result.epc))


def test_a_scalar_that_changes_between_calls_is_read_anew():
    designs = _designs(5)
    a = epc_fast.evaluate(**designs, threads=1, jitter_um=0.0)
    b = epc_fast.evaluate(**designs, threads=1, jitter_um=0.5)
    c = epc_fast.evaluate(**designs, threads=1, jitter_um=0.0)
    ok = (a.status == Status.OK) & (b.status == Status.OK)
    assert ok.mean() > 0.9
    assert np.all(b.f50_cyc_per_mm[ok] < a.f50_cyc_per_mm[ok])  # jitter blurs
    np.testing.assert_array_equal(a.epc, c.epc)


def test_the_inverse_solver_s_trial_illuminances_replace_the_column():
    # lux_for_epc evaluates trial illuminances in place of the column (the layout of a Block
    # then holds a replaced column, told apart from a plain call's): its answers give back the
    # target EPC in a plain call
    designs = _designs(6)
    designs.pop("illuminance_lux")
    target = 0.5 * epc_fast.evaluate(1e4, **designs, threads=1).epc
    lux = epc_fast.lux_for_epc(designs, target, threads=2).illuminance_lux
    ok = np.isfinite(lux)
    assert ok.mean() > 0.5
    back = epc_fast.evaluate(lux[ok], **{k: v[ok] if np.ndim(v) else v
                                         for k, v in designs.items()}, threads=1).epc
    np.testing.assert_allclose(back, target[ok], rtol=1e-9)  # Brent's rtol 1e-13 on lux
