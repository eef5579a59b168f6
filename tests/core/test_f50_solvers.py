"""Every f50 solver (cpp/include/epc_fast/f50/solvers.h) at several tolerances, against the NumPy
reference (which bisects f50 to adjacent doubles) on scenes that use every term."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast.selfcheck import random_designs
from epc_fast.spectra import diffraction_spectrum

SOLVERS = ("halley", "newton", "brent", "bisection")
N = 4000


def _scenes():
    rng = np.random.default_rng(77)
    base = random_designs(N, seed=5)
    return {
        "phones": {},
        "jitter": {"jitter_um": rng.uniform(0.0, 3.0, N)},
        "fill factor": {"fill_factor": rng.uniform(0.2, 1.0, N)},
        "threshold": {"mtf_threshold": rng.uniform(0.05, 0.95, N)},
        "sensor noise": {"dark_current_e_per_s": rng.uniform(0, 500, N),
                         "prnu": rng.uniform(0, 0.02, N)},
        "polychromatic": {"spectrum": diffraction_spectrum(8)},
        # 400 and 1000 nm: the bracket is the short wavelength's, so f50 often lies past the
        # long one's cut-off, where its D'' is 0 (the formula's 1/0 there once stopped Halley
        # at a wrong f50, up to 70% off, mtf.h diffraction_slopes)
        "wide spectrum": {"spectrum": epc_fast.Spectrum([400.0, 1000.0], [0.5, 0.5]),
                          "mtf_threshold": rng.uniform(0.05, 0.95, N)},
    }, base


SCENES, BASE = _scenes()


@pytest.fixture(scope="module", params=list(SCENES))
def scene(request):
    kwargs = dict(BASE, **SCENES[request.param])
    return request.param, kwargs, epc_fast.evaluate(**kwargs, backend="reference")


def _f50_error(result, reference):
    ok = reference.status == Status.OK
    assert np.array_equal(result.status, reference.status)
    assert ok.sum() > N // 2
    return np.max(np.abs(result.f50_cyc_per_mm[ok] / reference.f50_cyc_per_mm[ok] - 1))


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("rtol", [1e-14, 1e-10, 1e-6])
def test_every_solver_meets_its_tolerance(scene, solver, rtol):
    name, kwargs, reference = scene
    result = epc_fast.evaluate(**kwargs, f50_solver=solver, f50_rtol=rtol)
    # The tolerance, plus the reference's and the core's own rounding of a well-conditioned
    # f50 (a few 1e-15: docs/numerics.md section 4); T_MPE's hypot and tan differ from NumPy's
    # by an ulp, which these random phones' conditioning (< 30) keeps below 1e-14.
    assert _f50_error(result, reference) <= rtol + 3e-14, (name, solver, rtol)


@pytest.mark.parametrize("solver", SOLVERS)
def test_every_solver_gives_the_same_bits_on_any_thread_count(scene, solver):
    _, kwargs, _ = scene
    one = epc_fast.evaluate(**kwargs, f50_solver=solver, threads=1)
    two = epc_fast.evaluate(**kwargs, f50_solver=solver, threads=2)
    assert np.array_equal(one.f50_cyc_per_mm, two.f50_cyc_per_mm, equal_nan=True)


def test_the_solvers_agree_with_each_other_at_the_default_tolerance(scene):
    _, kwargs, reference = scene
    ok = reference.status == Status.OK
    results = {s: epc_fast.evaluate(**kwargs, f50_solver=s).f50_cyc_per_mm[ok] for s in SOLVERS}
    for s in SOLVERS[1:]:
        # each within 1e-14 of the truth (above), so within 2e-14 + rounding of each other
        np.testing.assert_allclose(results[s], results["halley"], rtol=4e-14)


def test_a_looser_tolerance_is_faster_in_evaluations_not_in_correctness():
    # rtol = 0.5: every solver still returns a point inside the bracket, below f_hi, and
    # within 50% of the truth (bisection's answer is the midpoint of a bracket of that width).
    kwargs = dict(BASE)
    reference = epc_fast.evaluate(**kwargs, backend="reference")
    ok = reference.status == Status.OK
    for solver in SOLVERS:
        f50 = epc_fast.evaluate(**kwargs, f50_solver=solver, f50_rtol=0.5).f50_cyc_per_mm[ok]
        assert np.all(np.abs(f50 / reference.f50_cyc_per_mm[ok] - 1) <= 0.5), solver


def test_an_unknown_solver_is_refused_by_name():
    with pytest.raises(ValueError, match="f50_solver"):
        epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, sensor_area_mm2=15.7, f50_solver="secant")


def test_an_invalid_point_in_a_block_does_not_change_its_neighbours_broadcast_values():
    # Found by fuzz/fuzz_evaluate.py: an invalid lane 0 holds stand-in parameters, and the
    # exposure stage once read a broadcast column's value (snr_db) from lane 0.
    shake = np.array([np.nan, 4.39, 90.0])
    core = epc_fast.evaluate(1.0, 1.0, 1.0, 1.0, sensor_area_mm2=90.0, shake_deg_per_s=shake,
                             stabilization=0.5)
    reference = epc_fast.evaluate(1.0, 1.0, 1.0, 1.0, sensor_area_mm2=90.0,
                                  shake_deg_per_s=shake, stabilization=0.5, backend="reference")
    assert np.array_equal(core.status, reference.status)
    np.testing.assert_allclose(core.t_mpe_s[1:], reference.t_mpe_s[1:], rtol=1e-14)
