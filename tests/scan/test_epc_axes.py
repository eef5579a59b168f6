"""EPC counted in both directions in scans, Sobol' indices, the optimiser and a scan config
(``epc_axes``, docs/model.md "Resolution in both directions"): the numbers evaluate gives on
the same draws."""

import tomllib

import numpy as np
import pytest

import epc_fast
from epc_fast import optimize, scan
from epc_fast.jobs.errors import ConfigError
from epc_fast.presets import HIGH_TIER, Design
from epc_fast.scan import LogUniform, Summary, Uniform, run
from epc_fast.scan.config import parse_space
from epc_fast.scan.sampling.space import BLOCK_POINTS
from epc_fast.terms import terms_on

N = BLOCK_POINTS + 333  # a second, partial block
#: A 1/3.2" 1.12 um phone camera with read noise.
PHONE = dict(pixel_pitch_um=1.12, f_number=2.0, focal_length_mm=3.82, sensor_width_mm=4.57,
             sensor_height_mm=3.43, read_noise_e=2.0)


def _space(epc_axes):
    return scan.Space(design=HIGH_TIER, illuminance_lux=LogUniform(1, 1e5),
                      jitter_um=Uniform(0.0, 0.5), evaluate_options={"epc_axes": epc_axes})


@pytest.mark.parametrize("backend", ["core", "numpy"])
def test_a_scan_in_both_directions_is_evaluate_in_both_directions_on_the_same_draws(backend):
    space = _space("both")
    result = run(space, N, seed=54, reductions={"s": Summary(by="design")}, progress=False,
                 backend=backend)
    points = space.points(54, 0, N)
    expected = epc_fast.evaluate(**points.parameters, epc_axes="both")
    design = points.indices["design"]
    ok = np.isfinite(expected.epc)
    means = [expected.epc[ok & (design == d)].mean() for d in range(4)]
    # the same kernel on the same draws; the sums' order differs (~1e-15)
    np.testing.assert_allclose(result["s"].mean, means, rtol=1e-12)
    motion = run(_space("motion"), N, seed=54, reductions={"s": Summary(by="design")},
                 progress=False, backend=backend)
    assert np.all(result["s"].mean > motion["s"].mean)


def test_the_conditions_of_a_scan_in_both_directions_say_so():
    assert "EPC in both directions (4 S f50 f50_across)" in terms_on(_space("both"))
    assert not any("both directions" in t for t in terms_on(_space("motion")))


def test_a_config_takes_epc_axes_in_evaluate_and_names_a_bad_one(tmp_path):
    text = """
[design]
presets = ["HIGH_TIER"]
[parameters]
illuminance_lux = {distribution = "log_uniform", low = 1, high = 1000}
[evaluate]
epc_axes = "%s"
"""
    space = parse_space(tomllib.loads(text % "both"), tmp_path)
    assert space.evaluate_options["epc_axes"] == "both"
    with pytest.raises(ConfigError, match="epc_axes"):
        parse_space(tomllib.loads(text % "across"), tmp_path)


def test_sobol_indices_in_both_directions_see_the_motion_matter_less():
    design = Design("phone", **PHONE)
    indices = {}
    for epc_axes in ("motion", "both"):
        space = scan.Space(design=[design], illuminance_lux=LogUniform(30.0, 1e4),
                           shake_deg_per_s=Uniform(0.5, 8.0), f_number=Uniform(1.6, 4.0),
                           evaluate_options={"epc_axes": epc_axes})
        result = scan.sobol_indices(space, points=2**8, seed=5, of="log_epc")
        indices[epc_axes] = result.st[0, 0, result.parameters.index("shake_deg_per_s")]
    # ln EPC_both = (ln EPC_motion + ln 4 S f50_across^2) / 2: the second term varies with the
    # f-number and not with the shake, whose share of the variance of ln EPC falls
    assert 0.0 < indices["both"] < indices["motion"]


def test_the_optimiser_maximises_the_epc_its_space_counts():
    design = Design("phone", **PHONE)
    best = {}
    for epc_axes in ("motion", "both"):
        space = scan.Space(design=[design], illuminance_lux=30.0,
                           evaluate_options={"epc_axes": epc_axes})
        problem = optimize.Problem(space, {"denoise_sigma_px": (0.0, 4.0)}, points=1_000,
                                   seed=1)
        best[epc_axes] = problem.maximize(batches=0).x["denoise_sigma_px"]
    sigmas = np.linspace(0.0, 4.0, 801)
    for epc_axes, sigma in best.items():
        curve = epc_fast.evaluate(30.0, **PHONE, snr_at="corner", denoise_sigma_px=sigmas,
                                  epc_axes=epc_axes).epc
        assert abs(sigma - sigmas[np.argmax(curve)]) <= 0.02, epc_axes
    # in both directions denoising's lost resolution across the motion is counted: less of it
    assert best["both"] < best["motion"]


def test_a_scan_summarises_the_f50_across_the_motion_as_evaluate_gives_it():
    space = _space("motion")
    reductions = {"across": Summary(of="f50_across_cyc_per_mm", by="design"),
                  "along": Summary(of="f50_cyc_per_mm", by="design")}
    result = run(space, N, seed=7, reductions=reductions, progress=False)
    points = space.points(7, 0, N)
    expected = epc_fast.evaluate(**points.parameters,
                                 outputs=("f50_cyc_per_mm", "f50_across_cyc_per_mm"))
    design = points.indices["design"]
    for name, values in (("across", expected.f50_across_cyc_per_mm),
                         ("along", expected.f50_cyc_per_mm)):
        ok = np.isfinite(values)
        means = [values[ok & (design == d)].mean() for d in range(4)]
        np.testing.assert_allclose(result[name].mean, means, rtol=1e-12)  # the sums' order
    assert np.all(result["across"].mean > result["along"].mean)


def test_a_scan_in_both_directions_folds_in_the_fused_pass_but_its_shares():
    # the fused pass counts EPC in both directions (kernel.h across_f50); a share takes the
    # two passes of epc_fast.axes, as arrays
    from epc_fast.scan.running.runner import _plan
    from epc_fast.scan.running.tasks import _core_plan

    space = _space("both")
    reductions = {"s": Summary(by="design"), "m": Summary(of="share_motion")}
    core, arrays = _core_plan(space, _plan(space, reductions), 5, N)
    assert [i.name for i in core.plan] == ["s"] and [i.name for i in arrays] == ["m"]
    assert core.epc_both
    result = run(space, N, seed=5, reductions=reductions, progress=False)
    points = space.points(5, 0, N)
    expected = epc_fast.evaluate(**points.parameters, epc_axes="both",
                                 outputs=("epc", "share_motion"))
    ok = np.isfinite(expected.epc)
    design = points.indices["design"]
    means = [expected.epc[ok & (design == d)].mean() for d in range(4)]
    np.testing.assert_allclose(result["s"].mean, means, rtol=1e-12)  # the sums' order differs
    share = expected.share_motion[np.isfinite(expected.share_motion)]
    np.testing.assert_allclose(result["m"].mean, [share.mean()], rtol=1e-12)
