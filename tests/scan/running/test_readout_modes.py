"""Issue #39 in scans: binning, bursts and alignment as scan parameters, a design's
binning_readout, and readout modes (scan/running/readout_modes.py): each chunk's points evaluated
per design's readout, every mode on the same draws, the best per point, and the share of each mode
per group.
"""

import numpy as np
import pytest

import epc_fast
from epc_fast import scan
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (Choice, Empirical, Grid, LogUniform, Summary, TopK, Truncated, Uniform,
                           run)
from epc_fast.scan.running.readout_modes import evaluate_space_points
from epc_fast.scan.sampling.space import BLOCK_POINTS
from epc_fast.scan.reductions.groups import group_key
from epc_fast.scan.running.tasks import PlanItem, _core_plan

N = BLOCK_POINTS + 777  # a second, partial block
MODES = ({"binning": 1}, {"binning": 2}, {"binning": 2, "frames": 4})
#: The 200 MP 0.56 um phone sensor of issue #39, with a read noise that makes binning pay.
PHONE = {"name": "200 MP", "pixel_pitch_um": 0.56, "f_number": 1.8, "focal_length_mm": 6.0,
         "sensor_diagonal_mm": 12.0, "aspect": "4:3", "read_noise_e": 1.5,
         "dark_current_e_per_s": 4.0}


def _light(**more):
    return dict(illuminance_lux=LogUniform(1, 1e5), **more)


def _by_design(values, design, designs):
    return np.array([values[design == d].mean() for d in range(designs)])


def test_the_new_parameters_scan_as_evaluate_gives_them_on_the_same_draws():
    space = scan.Space(design=HIGH_TIER, **_light(
        binning=Choice([1, 2, 4], weights=[0.5, 0.3, 0.2]), frames=Grid([1, 8]),
        alignment_error_um=Truncated(scan.Normal(0.3, 0.2), 0.0, 2.0), read_noise_e=2.0))
    result = run(space, N, seed=5, reductions={"s": Summary(by="design")}, progress=False)
    points = space.points(5, 0, N)
    expected = epc_fast.evaluate(**points.parameters)
    design = points.indices["design"]
    summary = result["s"]
    assert np.array_equal(summary.points, np.bincount(design, minlength=4))
    assert np.array_equal(summary.status_counts[:, 0],
                          np.bincount(design[expected.status == 0], minlength=4))
    ok = np.isfinite(expected.epc)
    np.testing.assert_allclose(summary.mean, _by_design(expected.epc[ok], design[ok], 4),
                               rtol=1e-12)
    assert summary.mode_counts is None and "mode 0" not in summary.columns()
    # and the new parameters change EPC: binned bursts are another camera
    plain = epc_fast.evaluate(**{**points.parameters, "binning": 1.0, "frames": 1.0})
    assert not np.allclose(plain.epc[ok], expected.epc[ok])


def test_a_space_without_modes_or_charge_binning_keeps_the_fused_pass():
    space = scan.Space(design=HIGH_TIER, **_light(binning=Grid([1, 2])))
    assert not space.has_modes
    plan = (PlanItem("s", Summary(by="design"), group_key(space, "design")),)
    core, arrays = _core_plan(space, plan, 1, 10**6)
    assert core.plan == plan and arrays == ()


@pytest.mark.parametrize("name, axis, message", [
    ("binning", Uniform(1, 4), "expected whole numbers in [1, 1e+30) integers"),
    ("frames", LogUniform(1, 16), "expected whole numbers in [1, 1e+30) integers"),
    ("binning", Truncated(scan.Normal(2, 1), 1, 4), "expected whole numbers"),
    ("binning", Choice([1, 2.5]), "choice value 2.5: expected every value in [1, 1e+30) "
                                  "integers"),
    ("frames", Grid([0, 4]), "grid value 0: expected every value in [1, 1e+30) integers"),
    ("frames", Empirical([1, 2, 3.5]), "empirical sample 3.5"),
    ("binning", 0.5, "0.5: expected a value in [1, 1e+30) integers"),
])
def test_binning_and_frames_take_whole_numbers_from_one_only(name, axis, message):
    with pytest.raises(ValueError) as caught:
        scan.Space(design=HIGH_TIER, **_light(**{name: axis}))
    assert str(caught.value).startswith(f"{name} = ") and message in str(caught.value)


def test_whole_number_distributions_of_binning_and_frames_are_taken():
    space = scan.Space(design=HIGH_TIER, **_light(binning=Empirical([1, 2, 2, 4]),
                                                  frames=Choice([1, 4, 16])))
    assert space.axes["frames"] == Choice([1, 4, 16])


def _mode_space(**more):
    return scan.Space(design=[{**PHONE, "modes": MODES}], **_light(alignment_error_um=0.3),
                      **more)


def test_a_scan_keeps_the_mode_the_camera_picks_on_the_same_draws_as_evaluate():
    space = _mode_space()
    assert space.has_modes and space.mode_count == 3
    reductions = {"s": Summary(by="design"), "best": TopK(5)}
    for backend in ("core", "numpy"):
        result = run(space, N, seed=2, reductions=reductions, progress=False, backend=backend)
        points = space.points(2, 0, N)
        params = {k: v for k, v in points.parameters.items() if k != "binning"}
        expected = epc_fast.evaluate(**params, modes=list(MODES))
        summary = result["s"]
        counts = np.bincount(expected.mode + 1, minlength=4)
        assert np.array_equal(summary.mode_counts[0], counts), backend
        assert counts[1:].min() > 0  # every mode is picked somewhere over 1..1e5 lux
        np.testing.assert_allclose(summary.mean[0], np.nanmean(expected.epc), rtol=1e-12)
        np.testing.assert_allclose(summary.columns()["mode 2"], counts[3:4] / N)
        np.testing.assert_array_equal(np.sort(result["best"].value),
                                      np.sort(expected.epc)[-5:])


def test_the_mode_column_of_the_parquet_points_is_evaluates_mode(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    space = _mode_space()
    run(space, N, seed=4, reductions={"s": Summary()}, progress=False,
        parquet=tmp_path / "points")
    table = pq.read_table(tmp_path / "points").to_pydict()
    points = space.points(4, 0, N)
    expected = epc_fast.evaluate(**points.parameters, modes=list(MODES))
    assert np.array_equal(np.asarray(table["mode"]), expected.mode)
    # the core forms the points (a few ulp from NumPy's draws: docs/scan.md)
    np.testing.assert_allclose(np.asarray(table["epc"]), expected.epc, rtol=1e-12)


def test_each_design_is_read_its_own_way_in_one_scan():
    plain = {**PHONE, "name": "plain", "binning": 2}
    charge = {**PHONE, "name": "charge", "binning": 2, "binning_readout": "charge"}
    moded = {**PHONE, "name": "modes", "modes": MODES + ({"binning": 4,
                                                           "binning_readout": "charge"},)}
    space = scan.Space(design=Choice([plain, charge, moded]), **_light())
    assert space.design_readout == ("digital", "charge", "digital")
    assert space.mode_count == 4
    points = space.points(7, 0, N)
    result = evaluate_space_points(space, points, outputs=("epc", "status"))
    design = points.indices["design"]
    for d, entry in enumerate((plain, charge, moded)):
        at = design == d
        call = {k: (v[at] if np.ndim(v) else v) for k, v in points.parameters.items()}
        extra = {}
        if "modes" in entry:
            call.pop("binning", None)
            extra["modes"] = list(entry["modes"])
        alone = epc_fast.evaluate(**call, **extra, outputs=("epc", "status"))
        assert np.array_equal(result.epc[at], alone.epc), entry["name"]
        # a design without modes has one, its own readout: 0, or -1 where it has no EPC
        own = np.where(np.isfinite(alone.epc), 0, -1)
        assert np.array_equal(result.mode[at], alone.mode if "modes" in entry else own)
    # charge binning reads once: never worse than digital at the same binning
    reads = epc_fast.evaluate(**{**points.parameters, "binning": 2.0, "binning_readout": 0.0})
    at = design == 1
    assert np.all(result.epc[at] >= reads.epc[at]) and np.any(result.epc[at] > reads.epc[at])
    summary = run(space, N, seed=7, reductions={"s": Summary(by="design")},
                  progress=False)["s"]
    assert summary.mode_counts.shape == (3, 5)
    assert np.array_equal(summary.mode_counts[:2, 2:], np.zeros((2, 3), np.int64))


@pytest.mark.parametrize("design, more, message", [
    ({**PHONE, "modes": []}, {}, "design '200 MP': modes: at least one readout mode"),
    ({**PHONE, "modes": [{"binnig": 2}]}, {}, "design '200 MP': modes[0]: 'binnig' is not"),
    ({**PHONE, "modes": [{"binning": 1}, {"binning": 1}]}, {},
     "design '200 MP': modes[1] repeats modes[0]"),
    ({**PHONE, "modes": [{"binning": 2.5}]}, {}, "design '200 MP': modes[0]: binning = 2.5: "
                                                 "expected a value in [1, 1e+30) integers"),
    ({**PHONE, "modes": [{"binning": 2}]}, {"binning": Grid([1, 2])},
     "design '200 MP': modes[0]: binning: the space's parameters set binning too"),
    ({**PHONE, "binning": 2, "modes": [{"binning": 4}]}, {},
     "design '200 MP': modes[0]: binning: the design sets binning = 2 too"),
    ({**PHONE, "binning_readout": "analog"}, {}, "binning_readout = 'analog': expected one of"),
])
def test_a_bad_readout_is_refused_naming_the_design_and_the_mode(design, more, message):
    with pytest.raises((TypeError, ValueError)) as caught:
        scan.Space(design=[design], **_light(**more))
    assert message in str(caught.value), str(caught.value)


def test_a_design_object_carries_its_modes_and_readout_into_the_scan():
    design = HIGH_TIER[3].with_(read_noise_e=2.0, binning_readout="charge", modes=MODES)
    space = scan.Space(design=[design, HIGH_TIER[0]], **_light())
    assert space.design_readout == ("charge", "digital")
    assert space.design_modes == (MODES, None)


def test_a_space_describes_each_designs_readout_and_refuses_modes_as_a_parameter():
    design = HIGH_TIER[3].with_(binning_readout="charge", modes=MODES)
    text = scan.Space(design=[design, HIGH_TIER[0]], **_light()).describe()
    assert "1.4 um: SNR target 30 dB at corner (27.03 deg, default); charge binning; modes: " \
           "binning=1 | binning=2 | binning=2, frames=4\n" in text
    assert "2.8 um: SNR target 30 dB at corner (27.03 deg, default)\n" in text
    assert "binning=1" in text.split("defaults")[1]  # the 2.8 um design's
    with pytest.raises(TypeError, match="modes is how a design's sensor is read"):
        scan.Space(design=HIGH_TIER, **_light(modes=MODES))


def test_a_space_of_charge_binned_designs_keeps_the_fused_pass_and_evaluates_as_evaluate():
    charge = HIGH_TIER[3].with_(name="charge", read_noise_e=2.0, binning=2,
                                binning_readout="charge")
    space = scan.Space(design=[charge, HIGH_TIER[3].with_(read_noise_e=2.0, binning=2)],
                       **_light())
    assert not space.has_modes
    np.testing.assert_array_equal(space.design_table["binning_readout"], [1.0, 0.0])
    plan = (PlanItem("s", Summary(by="design"), group_key(space, "design")),)
    core, arrays = _core_plan(space, plan, 1, 10**6)
    assert core.plan == plan and arrays == ()
    points = space.points(3, 0, N)
    design = points.indices["design"]
    expected = epc_fast.evaluate(**points.parameters)
    alone = epc_fast.evaluate(**{**points.parameters, "binning_readout": np.where(
        design == 0, "charge", "digital")})
    np.testing.assert_array_equal(expected.epc, alone.epc)
    # charge binning reads once: better than digital where the read noise matters
    assert np.mean(expected.epc[design == 0]) > np.mean(expected.epc[design == 1])
    summary = run(space, N, seed=3, reductions={"s": Summary(by="design")}, progress=False)["s"]
    ok = np.isfinite(expected.epc)
    np.testing.assert_allclose(summary.mean, _by_design(expected.epc[ok], design[ok], 2),
                               rtol=1e-12)


def test_binning_readout_is_a_parameter_of_a_space_by_name():
    space = scan.Space(design=[HIGH_TIER[3].with_(binning=2)],
                       **_light(binning_readout=Choice(["digital", "charge"])))
    assert space.axes["binning_readout"] == Choice((0.0, 1.0))
    assert scan.Space(design=HIGH_TIER, **_light(binning_readout="charge")).axes[
        "binning_readout"] == 1.0
    with pytest.raises(ValueError, match="binning_readout must be one of 'digital', 'charge'"):
        scan.Space(design=HIGH_TIER, **_light(binning_readout=Grid(["digital", "analog"])))


def test_a_bursts_alignment_share_is_summarised_by_the_fused_pass_as_by_numpy():
    space = scan.Space(design=HIGH_TIER, **_light(
        frames=Choice([1, 4, 16]), alignment_error_um=Uniform(0.0, 1.0)))
    reductions = {"align": Summary(of="share_alignment", by="design"),
                  "epc": Summary(by="design")}
    core, numpy = (run(space, N, seed=6, reductions=reductions, progress=False,
                       backend=backend) for backend in ("core", "numpy"))
    for name in reductions:
        np.testing.assert_allclose(core[name].mean, numpy[name].mean, rtol=1e-12)
        assert np.array_equal(core[name].count, numpy[name].count)
    assert np.all(core["align"].mean > 0.0) and np.all(core["align"].max < 1.0)


NIGHT = ({"binning": 1}, {"binning": 2}, {"binning": 2, "frames": "auto", "max_frames": 4})


@pytest.mark.parametrize("backend", ["core", "numpy"])
def test_a_frame_cap_and_night_mode_scan_as_evaluate_counts_them(backend):
    space = scan.Space(design=[{**PHONE, "modes": list(NIGHT)}], **_light(),
                       evaluate_options={"max_exposure_s": 0.1})
    plan = (PlanItem("s", Summary(by="design"), group_key(space, "design")),)
    assert _core_plan(space, plan, 1, 10**6)[0].plan == ()  # arrays, not the fused pass
    result = run(space, N, seed=3, reductions={"s": Summary(by="design")}, progress=False,
                 backend=backend)
    points = space.points(3, 0, N)
    expected = epc_fast.evaluate(**points.parameters, modes=list(NIGHT), max_exposure_s=0.1)
    counts = np.bincount(expected.status, minlength=len(epc_fast.Status))
    summary = result["s"]
    assert np.array_equal(summary.status_counts[0], counts)
    assert counts[epc_fast.Status.EXPOSURE_LIMIT] > 0  # the dimmest draws, 1 lux and so
    assert summary.columns()["exposure limit"][0] == counts[epc_fast.Status.EXPOSURE_LIMIT]
    assert np.array_equal(summary.mode_counts[0], np.bincount(expected.mode + 1, minlength=4))
    assert summary.mode_counts[0][3] > 0  # night mode is picked somewhere
    np.testing.assert_allclose(summary.mean[0], np.nanmean(expected.epc), rtol=1e-12)


def test_a_frame_cap_without_modes_leaves_the_fused_pass_and_counts_exposure_limit():
    space = scan.Space(design=HIGH_TIER, **_light(), evaluate_options={"max_exposure_s": 0.05})
    plan = (PlanItem("s", Summary(by="design"), group_key(space, "design")),)
    assert _core_plan(space, plan, 1, 10**6)[0].plan == ()
    summary = run(space, N, seed=6, reductions={"s": Summary(by="design")},
                  progress=False)["s"]
    points = space.points(6, 0, N)
    expected = epc_fast.evaluate(**points.parameters, max_exposure_s=0.05)
    design = points.indices["design"]
    for status in epc_fast.Status:
        assert np.array_equal(summary.status_counts[:, status],
                              np.bincount(design[expected.status == status], minlength=4))
    assert summary.status_counts[:, epc_fast.Status.EXPOSURE_LIMIT].sum() > 0
    uncapped = run(scan.Space(design=HIGH_TIER, **_light()), N, seed=6,
                   reductions={"s": Summary(by="design")}, progress=False)["s"]
    assert "exposure limit" not in uncapped.columns()


@pytest.mark.parametrize("cap", [0.0, -1.0, float("nan"), "fast", [0.1, 0.2], True])
def test_a_scans_frame_cap_is_one_positive_value(cap):
    with pytest.raises(ValueError, match="max_exposure_s = .*one value a scan"):
        scan.Space(design=HIGH_TIER, **_light(), evaluate_options={"max_exposure_s": cap})
