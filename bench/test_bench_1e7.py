"""Every peer at 10^7 points, in one benchmark group (see engine_suite.py), with the core's
scan-style calls besides its default one:

    python -m pytest bench/test_bench_1e7.py --benchmark-only

The NumPy reference runs on the first 10^6 of the points (test_reference_scaled: compare its
points/s, not its median), and every other peer is checked against it on those 10^6.
"""

import pytest

import engine_suite as suite

SIZE = suite.SIZES["1e7"]
pytestmark = pytest.mark.benchmark(group=SIZE.group)


@pytest.mark.parametrize("threads", [1, 2], ids=["1 thread", "2 threads"])
def test_core(benchmark, data, threads):
    suite.bench_core(benchmark, data, SIZE, threads)


@pytest.mark.parametrize("threads", [1, 2], ids=["1 thread", "2 threads"])
def test_core_float32(benchmark, data, threads):
    """precision="float32": f50 solved in float32."""
    suite.bench_core(benchmark, data, SIZE, threads, precision="float32")


def test_core_2_threads_out_preallocated(benchmark, data, out_1e7):
    """As a scan calls it: outputs written into the same preallocated arrays every round."""
    suite.bench_core_into_outputs(benchmark, data, SIZE, out_1e7)


def test_core_2_threads_lean_outputs(benchmark, data):
    """Only f50, EPC and status computed."""
    suite.bench_core_outputs(benchmark, data, SIZE)


def test_core_2_threads_peer_outputs(benchmark, data):
    """The outputs the peers return (T_MPE, f50, EPC, status): the same bytes written."""
    suite.bench_core_outputs(benchmark, data, SIZE, outputs=suite.PEER_OUTPUTS)


def test_reference_scaled(benchmark, data):
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


def test_paired_2_threads_vs_1(benchmark, data):
    """The default call on 2 threads and on 1, taken in turn."""
    suite.bench_paired(benchmark, data, SIZE, suite.core_contender("core, 2 threads"),
                       suite.core_contender("core, 1 thread", threads=1))


def test_paired_float32_vs_float64(benchmark, data):
    """precision="float32" and the default float64, on 2 threads, taken in turn."""
    suite.bench_paired(benchmark, data, SIZE,
                       suite.core_contender("core float32, 2 threads", precision="float32"),
                       suite.core_contender("core, 2 threads"))
