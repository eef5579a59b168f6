"""Every peer at 10^6 points, in one benchmark group (see engine_suite.py):

    python -m pytest bench/test_bench_1e6.py --benchmark-only
"""

import pytest

import engine_suite as suite

SIZE = suite.SIZES["1e6"]
pytestmark = pytest.mark.benchmark(group=SIZE.group)


@pytest.mark.parametrize("threads", [1, 2], ids=["1 thread", "2 threads"])
def test_core(benchmark, data, threads):
    suite.bench_core(benchmark, data, SIZE, threads)


@pytest.mark.parametrize("threads", [1, 2], ids=["1 thread", "2 threads"])
def test_core_float32(benchmark, data, threads):
    """precision="float32": f50 solved in float32."""
    suite.bench_core(benchmark, data, SIZE, threads, precision="float32")


def test_reference(benchmark, data):
    suite.bench_reference(benchmark, data, SIZE)


def test_numba(benchmark, data, numba_evaluate):
    suite.bench_numba(benchmark, data, SIZE, numba_evaluate)


def test_numba_same_algorithm(benchmark, data, numba_evaluate):
    """The Numba peer running the core's f50 algorithm: what the C++ buys beyond it."""
    suite.bench_numba(benchmark, data, SIZE, numba_evaluate, same_algorithm=True)


def test_scipy_brentq_1000_points(benchmark, data, brentq_evaluate):
    suite.bench_brentq(benchmark, data, SIZE, brentq_evaluate)


def test_paired_core_vs_numba(benchmark, data, numba_evaluate):
    """The default call and the Numba peer taken in turn: the speed-up, round by round."""
    suite.bench_paired(benchmark, data, SIZE, suite.core_contender("core, 2 threads"),
                       suite.numba_contender(numba_evaluate))
