"""Shared inputs for the benchmarks, made once per session: the same random designs and the
same reference results for every peer of a group (engine_suite.py), and the peers' entry points
with their JIT compilation done outside any timing."""

import numpy as np
import pytest

from engine_suite import QUICK, SIZES, THREADS, Data, output_arrays


@pytest.fixture(scope="session")
def data():
    """Designs per size (random_designs(n, seed=12345)) and the reference on each."""
    return Data()


@pytest.fixture(scope="session")
def numba_evaluate(data):
    """The Numba peer on THREADS threads, compiled (and its thread pool started) on a few
    points with the benchmarks' own argument types, so that no round pays for the JIT."""
    numba = pytest.importorskip("numba")
    from peers import numba_peer

    numba.set_num_threads(min(THREADS, numba.config.NUMBA_NUM_THREADS))
    few = data.prefix(SIZES["1e4"].points, 16)
    numba_peer.evaluate(**few)
    numba_peer.evaluate(**few, same_algorithm=True)  # its own compiled signature
    return numba_peer.evaluate


@pytest.fixture(scope="session")
def brentq_evaluate():
    """The per-point SciPy peer (scipy.optimize.brentq)."""
    pytest.importorskip("scipy")
    from peers import scipy_peer

    return scipy_peer.evaluate


@pytest.fixture(scope="module")
def out_1e7():
    """Preallocated outputs for the 10^7 suite's scan-style call, reused by every round."""
    return output_arrays(SIZES["1e7"].points)


def pytest_benchmark_update_machine_info(config, machine_info):
    """What the numbers depend on besides the machine: the core's build and the peers'."""
    from epc_fast import _core

    machine_info["epc_fast_isa"] = getattr(_core, "isa", None)
    machine_info["numpy"] = np.__version__
    machine_info["bench_quick"] = QUICK
    for name in ("numba", "scipy"):
        try:
            machine_info[name] = __import__(name).__version__
        except ImportError:
            machine_info[name] = None
