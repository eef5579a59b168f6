"""A one-parameter optimisation over 10^7 scene draws per candidate, on 2 threads:

    python -m pytest bench/test_bench_optimize.py --benchmark-only

The pixel pitch (0.8..4 um) that maximises the median EPC of the paper's 1/3.2" design under
log-uniform 10..100,000 lux (docs/optimize.md's worked example, without stabilisation):

- ``test_optimum_with_its_uncertainty``: ``epc_fast.optimize.maximize`` end to end: the
  scene drawn once, the start grid and bounded Brent on every draw, the same on 10 batches for
  the optimum's standard error, and the objective's standard error at the optimum;
- ``test_search_alone``: the search on every draw only (the draws made beforehand, no batch).

Each checks its answer against the pitch that is best at the median light, 1000 lux (EPC rises
with the light, so the median EPC is the EPC at the median light), found on the deterministic
model. Under ``EPC_FAST_BENCH_QUICK=1`` (CI) each runs once on 2^17 draws.
"""

import numpy as np
import pytest
from engine_suite import QUICK, THREADS, record

import epc_fast
from epc_fast import optimize, scan
from epc_fast.presets import HIGH_TIER

POINTS = 1 << 17 if QUICK else 10**7
SEED = 2009
BOUNDS = {"pixel_pitch_um": (0.8, 4.0)}
OBJECTIVE = optimize.Quantile(0.5)


@pytest.fixture(scope="module")
def space():
    return scan.Space(design=[HIGH_TIER[2]], illuminance_lux=scan.LogUniform(10, 1e5))


@pytest.fixture(scope="module")
def best_at_median_light():
    """um: the pitch of the largest EPC at 1000 lux, on a 10^-4 um grid."""
    kwargs = {k: v for k, v in HIGH_TIER[2].evaluate_kwargs().items() if k != "pixel_pitch_um"}
    pitches = np.linspace(2.9, 3.2, 3001)
    return pitches[np.argmax(epc_fast.evaluate(1000.0, pitches, **kwargs).epc)]


def _check(best, known, with_batches: bool):
    # The sample's median light moves the best pitch by its Monte Carlo error (~0.0014 um at
    # 10^7 draws, ~0.012 um at 2^17): 5 of them, or 0.05 um without batches to measure it.
    pitch = best.x["pixel_pitch_um"]
    error = best.x_standard_error["pixel_pitch_um"]
    assert abs(pitch - known) < (5 * error if with_batches else 0.05)
    assert best.evaluations < 40


@pytest.mark.benchmark(group="optimize 10^7 draws per candidate")
def test_optimum_with_its_uncertainty(benchmark, space, best_at_median_light):
    record(benchmark, "optimize.maximize", POINTS, THREADS, batches=10)
    best = benchmark.pedantic(
        optimize.maximize, args=(space, BOUNDS, OBJECTIVE),
        kwargs=dict(points=POINTS, seed=SEED, threads=THREADS, batches=10), rounds=1,
        iterations=1)
    benchmark.extra_info.update(evaluations=best.evaluations,
                                batch_evaluations=best.batch_evaluations)
    _check(best, best_at_median_light, with_batches=True)


@pytest.mark.benchmark(group="optimize 10^7 draws per candidate")
def test_search_alone(benchmark, space, best_at_median_light):
    record(benchmark, "Problem.maximize(batches=0)", POINTS, THREADS, batches=0)
    problem = optimize.Problem(space, BOUNDS, OBJECTIVE, points=POINTS, seed=SEED,
                               threads=THREADS)
    best = benchmark.pedantic(problem.maximize, kwargs=dict(batches=0), rounds=1 if QUICK else 3,
                              iterations=1)
    benchmark.extra_info.update(evaluations=best.evaluations)
    _check(best, best_at_median_light, with_batches=False)
