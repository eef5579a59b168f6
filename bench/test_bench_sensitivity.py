"""What the MTF-loss shares and the elasticities cost on top of evaluate, on the core at 10^6
points (10^4 with EPC_FAST_BENCH_QUICK=1), 1 and 2 threads, every output written into out=
arrays made once (so that no call pays for new pages):

    python -m pytest bench/test_bench_sensitivity.py --benchmark-only --benchmark-group-by=group

The ratios to the "evaluate" row are the price of each question (docs/limits.md).
"""

import numpy as np
import pytest
from engine_suite import QUICK

import epc_fast
from epc_fast.api import ELASTICITY_PARAMETERS, OUTPUT_DTYPES, SHARE_OUTPUTS
from epc_fast.params import PARAMETERS

N = 10**4 if QUICK else 10**6
#: The elasticity rows a point has: the whole-number parameters (binning, frames, lens) have
#: none.
CONTINUOUS_ROWS = [i for i, name in enumerate(ELASTICITY_PARAMETERS)
                   if not any(p.name == name and p.integer for p in PARAMETERS)]

#: The four elasticities docs/limits.md's question needs, one output each.
FOUR = ("elasticity_illuminance_lux", "elasticity_f_number", "elasticity_read_noise_e",
        "elasticity_shake_deg_per_s")
SELECTIONS = {
    "evaluate": tuple(OUTPUT_DTYPES),
    "evaluate + shares": tuple(OUTPUT_DTYPES) + SHARE_OUTPUTS,
    "evaluate + elasticities": tuple(OUTPUT_DTYPES) + ("elasticities",),
    "evaluate + 4 elasticities": tuple(OUTPUT_DTYPES) + FOUR,
    "evaluate + 1 elasticity": tuple(OUTPUT_DTYPES) + FOUR[1:2],
    "evaluate + both": tuple(OUTPUT_DTYPES) + SHARE_OUTPUTS + ("elasticities",),
}


def _scene():
    rng = np.random.default_rng(2026)
    return {
        "illuminance_lux": 10 ** rng.uniform(1, 5, N),
        "pixel_pitch_um": rng.uniform(0.8, 3.0, N),
        "shake_deg_per_s": np.exp(rng.normal(np.log(4.39), 0.5, N)),
        "f_number": 2.8, "focal_length_mm": 5.6, "sensor_width_mm": 4.57,
        "sensor_height_mm": 3.43, "snr_at": "corner",
    }


def _out(selection):
    return {name: np.empty((len(ELASTICITY_PARAMETERS), N)) if name == "elasticities"
            else np.empty(N, dtype=OUTPUT_DTYPES.get(name, np.float64)) for name in selection}


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("selection", list(SELECTIONS))
def test_sensitivity_cost(benchmark, selection, threads):
    benchmark.group = f"sensitivity 1e{int(np.log10(N))} points, {threads} thread(s)"
    kwargs = dict(_scene(), outputs=SELECTIONS[selection], threads=threads)
    out = _out(SELECTIONS[selection])
    result = benchmark.pedantic(epc_fast.evaluate, kwargs=dict(kwargs, out=out), rounds=5,
                                iterations=1, warmup_rounds=1)
    ok = result.status == epc_fast.Status.OK
    assert ok.mean() > 0.99  # the rest: blur unbounded at low light and strong shake
    if "share_motion" in out:
        total = sum(out[name] for name in SHARE_OUTPUTS)
        np.testing.assert_allclose(total[ok], 1.0, rtol=0, atol=1e-15)
    if "elasticities" in out:
        assert np.isfinite(out["elasticities"][CONTINUOUS_ROWS][:, ok]).all()
        # binning, frames, lens and binning_readout are whole numbers: no elasticity
        assert len(CONTINUOUS_ROWS) == len(ELASTICITY_PARAMETERS) - 4
    for name in set(out) & set(FOUR):
        assert np.isfinite(out[name][ok]).all()
