"""A scan against the raw core and the NumPy path, on the same points, in one group:

    python -m pytest bench/test_bench_scan.py --benchmark-only

- raw core: ``evaluate`` on the scan's points drawn beforehand (drawing not timed), computing
  the outputs the scan's reductions read (status and EPC);
- scan: ``scan.run`` end to end, the core's fused pass (draw, evaluate, reduce per block) with
  per-design summary, streamed quantiles and fraction below (``scan_1e9.benchmark_reductions``);
- NumPy path: the same scan with NumPy draws and reductions around ``evaluate``
  (``backend="numpy"``).

The Numba peer of the scan joins the group from ``test_bench_scan_peer.py``. A second group
scans a real phone (a Bayer sensor with Malvar's demosaicker, the phone's lens table, denoising
1 px and its three readout modes: bench compare's phone workload) in the fused pass against the
raw core on the same points. points/s = points / median; ``bench/scan_1e9.py`` measures the same at 10^7..10^9 points, with peak memory.
Under ``EPC_FAST_BENCH_QUICK=1`` (CI) each body runs once on 2^17 points as a correctness check.
"""

import numpy as np
import pytest

from engine_suite import QUICK
from epc_fast import evaluate
from epc_fast.benchcompare.worker import PHONE_LENS, PHONE_MODES
from epc_fast.scan import LogUniform, Space, Uniform, run
from epc_fast.scan.running.core_plan import CorePlan
from scan_1e9 import benchmark_reductions, benchmark_space

POINTS = 1 << 17 if QUICK else 1 << 21
CHUNK = 1 << 17 if QUICK else 1 << 20
SEED = 2009
THREADS = 2
ROUNDS = 1 if QUICK else 5


@pytest.fixture(scope="module")
def space():
    return benchmark_space()


@pytest.fixture(scope="module")
def drawn_chunks(space):
    """The scan's points as the core forms them, chunk by chunk, ahead of time."""
    plan = CorePlan(space, SEED)
    return [plan.points(start, start + CHUNK) for start in range(0, POINTS, CHUNK)]


def _evaluate_chunks(chunks):
    return [evaluate(**chunk.parameters, threads=THREADS, outputs=("status", "epc"))
            for chunk in chunks]


@pytest.fixture(scope="module")
def per_design(drawn_chunks):
    """Mean EPC and count below 2 Mpixel per design, from the raw core's arrays."""
    epc = np.concatenate([r.epc for r in _evaluate_chunks(drawn_chunks)])
    design = np.concatenate([chunk.indices["design"] for chunk in drawn_chunks])
    return (np.array([epc[design == g].mean() for g in range(4)]),
            np.array([np.count_nonzero(epc[design == g] < 2e6) for g in range(4)]))


def _scan(space, backend):
    return run(space, POINTS, seed=SEED, reductions=benchmark_reductions(), threads=THREADS,
               progress=False, backend=backend)


def _check(result, per_design):
    mean, below = per_design
    assert result["summary"].points.sum() == POINTS
    assert np.array_equal(result["below"].below, below)
    # block-wise merging and NumPy's pairwise mean round differently, far inside 1e-12; the
    # NumPy path's draws differ from the core's by a few ulp (docs/scan.md)
    np.testing.assert_allclose(result["summary"].mean, mean, rtol=1e-12)


@pytest.mark.benchmark(group="scan 2^21 points")
def test_raw_core(benchmark, drawn_chunks):
    results = benchmark.pedantic(_evaluate_chunks, args=(drawn_chunks,), rounds=ROUNDS,
                                 iterations=1, warmup_rounds=1)
    assert sum(r.epc.size for r in results) == POINTS


@pytest.mark.benchmark(group="scan 2^21 points")
def test_scan_with_per_design_summary_quantiles_and_fraction_below(benchmark, space,
                                                                   per_design):
    result = benchmark.pedantic(_scan, args=(space, "core"), rounds=ROUNDS, iterations=1,
                                warmup_rounds=1)
    _check(result, per_design)


@pytest.mark.benchmark(group="scan 2^21 points")
def test_scan_on_the_numpy_path(benchmark, space, per_design):
    result = benchmark.pedantic(_scan, args=(space, "numpy"), rounds=1 if QUICK else 3,
                                iterations=1)
    _check(result, per_design)


#: The phone's scene (bench compare's phone workload) as a scan space, and its options.
PHONE_OPTIONS = {"lens_mtf": (np.array(PHONE_LENS[0]), np.array(PHONE_LENS[1])), "cfa": "bayer",
                 "demosaic": "malvar2004"}
PHONE_POINTS = 1 << 17 if QUICK else 1 << 20


@pytest.fixture(scope="module")
def phone_space():
    design = {"name": "phone", "f_number": 2.0, "focal_length_mm": 5.6, "sensor_area_mm2": 20.0,
              "shake_deg_per_s": 4.39, "read_noise_e": 1.5, "denoise_sigma_px": 1.0,
              "modes": tuple(PHONE_MODES)}
    return Space(design=[design], evaluate_options=PHONE_OPTIONS,
                 illuminance_lux=LogUniform(1, 1e5), pixel_pitch_um=Uniform(0.8, 3.0))


@pytest.fixture(scope="module")
def phone_chunks(phone_space):
    """The phone scan's points as the core forms them, chunk by chunk, without the modes'
    own parameters (the modes set them)."""
    plan = CorePlan(phone_space, SEED)
    return [{k: v for k, v in plan.points(start, start + CHUNK).parameters.items()
             if k not in ("binning", "frames")} for start in range(0, PHONE_POINTS, CHUNK)]


def _evaluate_phone(chunks):
    return [evaluate(**chunk, threads=THREADS, outputs=("status", "epc"), modes=list(PHONE_MODES),
                     **PHONE_OPTIONS) for chunk in chunks]


@pytest.mark.benchmark(group="phone scan 2^20 points")
def test_phone_raw_core(benchmark, phone_chunks):
    results = benchmark.pedantic(_evaluate_phone, args=(phone_chunks,), rounds=ROUNDS,
                                 iterations=1, warmup_rounds=1)
    assert sum(r.epc.size for r in results) == PHONE_POINTS


@pytest.mark.benchmark(group="phone scan 2^20 points")
def test_phone_scan_in_the_fused_pass(benchmark, phone_space, phone_chunks):
    def scan():
        return run(phone_space, PHONE_POINTS, seed=SEED, reductions=benchmark_reductions(),
                   threads=THREADS, progress=False)

    result = benchmark.pedantic(scan, rounds=ROUNDS, iterations=1, warmup_rounds=1)
    epc = np.concatenate([r.epc for r in _evaluate_phone(phone_chunks)])
    assert result["summary"].points.sum() == PHONE_POINTS
    assert result["below"].below[0] == np.count_nonzero(epc < 2e6)
    np.testing.assert_allclose(result["summary"].mean[0], np.nanmean(epc), rtol=1e-12)
