"""A scan with its reductions against the raw core, on the same 2^21 points, in one group:

    python -m pytest bench/test_bench_scan.py --benchmark-only

The raw core evaluates pre-drawn chunks (drawing is not timed); the scan draws, evaluates and
reduces them (per-design summary, histogram and quantiles: ``scan_1e9.benchmark_reductions``).
points/s = 2^21 / median; the ratio of the two medians is the scan's share of the core's
throughput. ``bench/scan_1e9.py`` measures the same at 10^7..10^9 points, with peak memory.
"""

import numpy as np
import pytest

from epc_fast import evaluate
from epc_fast.scan import run
from epc_fast.scan.runner import DEFAULT_CHUNK_POINTS
from scan_1e9 import benchmark_reductions, benchmark_space

POINTS = 2 * DEFAULT_CHUNK_POINTS
SEED = 2009
THREADS = 2


@pytest.fixture(scope="module")
def space():
    return benchmark_space()


@pytest.fixture(scope="module")
def drawn_chunks(space):
    """The scan's points, drawn chunk by chunk ahead of time."""
    return [space.points(SEED, start, start + DEFAULT_CHUNK_POINTS)
            for start in range(0, POINTS, DEFAULT_CHUNK_POINTS)]


def _evaluate_chunks(chunks):
    return [evaluate(**chunk.parameters, threads=THREADS).epc for chunk in chunks]


@pytest.fixture(scope="module")
def mean_epc_per_design(drawn_chunks):
    epc = np.concatenate(_evaluate_chunks(drawn_chunks))
    design = np.concatenate([chunk.indices["design"] for chunk in drawn_chunks])
    return np.array([epc[design == g].mean() for g in range(design.max() + 1)])


@pytest.mark.benchmark(group="scan 2^21 points")
def test_raw_core(benchmark, drawn_chunks):
    epc = benchmark.pedantic(_evaluate_chunks, args=(drawn_chunks,), rounds=3, iterations=1)
    assert sum(e.size for e in epc) == POINTS and all(np.isfinite(e).all() for e in epc)


@pytest.mark.benchmark(group="scan 2^21 points")
def test_scan_with_per_design_summary_histogram_and_quantiles(benchmark, space,
                                                              mean_epc_per_design):
    result = benchmark.pedantic(run, args=(space, POINTS), rounds=3, iterations=1, kwargs=dict(
        seed=SEED, reductions=benchmark_reductions(), threads=THREADS, progress=False))
    assert result["summary"].points.sum() == POINTS
    # Block-wise merging and NumPy's pairwise mean round differently, far inside 1e-12.
    np.testing.assert_allclose(result["summary"].mean, mean_epc_per_design, rtol=1e-12)
