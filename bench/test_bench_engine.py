"""Throughput of the engine at 10^6 points: the NumPy reference and the core on 1 and 2 threads,
in one group so that their medians are compared within the same run.

    python -m pytest bench/ --benchmark-only --benchmark-group-by=group

points/s = 10^6 / median. Each benchmark checks its answer against the reference.
"""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status

N = 10**6


@pytest.fixture(scope="module")
def reference_result(designs_1e6):
    return epc_fast.evaluate(**designs_1e6, backend="reference")


def _agrees(result, reference):
    ok = reference.status == Status.OK
    assert np.array_equal(result.status, reference.status)
    # Both resolve f50 to ~1e-14 relative (bisection), far inside 1e-12.
    np.testing.assert_allclose(result.epc[ok], reference.epc[ok], rtol=1e-12)


@pytest.mark.benchmark(group="engine 1e6 points")
def test_reference(benchmark, designs_1e6, reference_result):
    result = benchmark.pedantic(epc_fast.evaluate, kwargs=dict(designs_1e6, backend="reference"),
                                rounds=2, iterations=1)
    _agrees(result, reference_result)


@pytest.mark.benchmark(group="engine 1e6 points")
@pytest.mark.parametrize("threads", [1, 2])
def test_core(benchmark, designs_1e6, reference_result, threads):
    result = benchmark.pedantic(epc_fast.evaluate, kwargs=dict(designs_1e6, threads=threads),
                                rounds=5, iterations=1, warmup_rounds=1)
    _agrees(result, reference_result)
