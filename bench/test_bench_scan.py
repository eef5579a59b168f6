"""A scan against the raw core and the NumPy path, on the same points, in one group:

    python -m pytest bench/test_bench_scan.py --benchmark-only

- raw core: ``evaluate`` on the scan's points drawn beforehand (drawing not timed), computing
  the outputs the scan's reductions read (status and EPC);
- scan: ``scan.run`` end to end, the core's fused pass (draw, evaluate, reduce per block) with
  per-design summary, streamed quantiles and fraction below (``scan_1e9.benchmark_reductions``);
- NumPy path: the same scan with NumPy draws and reductions around ``evaluate``
  (``backend="numpy"``).

The Numba peer of the scan joins the group from ``test_bench_scan_peer.py``. points/s =
points / median; ``bench/scan_1e9.py`` measures the same at 10^7..10^9 points, with peak memory.
Under ``EPC_FAST_BENCH_QUICK=1`` (CI) each body runs once on 2^17 points as a correctness check.
"""

import numpy as np
import pytest

from engine_suite import QUICK
from epc_fast import evaluate
from epc_fast.scan import run
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
