"""scan/running/camera_terms.py: a real phone (lens table, Bayer sensor, denoising, readout modes)
in the core's fused pass, every reduction as evaluate gives the points the core forms, and the
spaces the pass cannot read left to the arrays."""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import scan
from epc_fast.scan import (Choice, FractionBelow, Grid, LogUniform, Normal, Quantiles, Summary,
                           TopK, Uniform, run)
from epc_fast.scan.reductions.groups import group_key
from epc_fast.scan.running.tasks import PlanItem, _core_plan
from epc_fast.scan.sampling.space import BLOCK_POINTS
from epc_fast.status import Status

N = 2 * BLOCK_POINTS + 777  # two whole blocks and a partial one
LENS = (np.array([0, 50, 100, 150, 200, 250, 300.0]),
        np.array([1, 0.88, 0.74, 0.60, 0.47, 0.36, 0.27]))
MODES = ({"binning": 1}, {"binning": 2}, {"binning": 2, "frames": 4})
PHONE = {"name": "phone", "f_number": 2.0, "focal_length_mm": 5.6, "sensor_area_mm2": 20.0,
         "shake_deg_per_s": 4.39, "read_noise_e": 1.5, "denoise_sigma_px": 1.0}
BAYER = {"cfa": "bayer", "demosaic": "malvar2004"}


def _space(design=None, options=None, **parameters):
    parameters = {"illuminance_lux": LogUniform(1, 1e5), "pixel_pitch_um": Uniform(0.8, 3.0),
                  **parameters}
    return scan.Space(design=design or [{**PHONE, "modes": MODES}],
                      evaluate_options={"lens_mtf": LENS, **BAYER} if options is None else options,
                      **parameters)


def _plan(space, reductions):
    return tuple(PlanItem(name, r, None if isinstance(r, TopK) else group_key(space, r.by))
                 for name, r in reductions.items())


def _fused(space, reductions) -> bool:
    plan = _plan(space, reductions)
    core, arrays = _core_plan(space, plan, 1, 10**6)
    return core.plan == plan and arrays == ()


def _expected(space, seed, modes=MODES, **options):
    """evaluate at the points the core forms (CorePlan.points), with the space's options."""
    core, _ = _core_plan(space, (), seed, N)
    points = core.points(0, N)
    call = {k: v for k, v in points.parameters.items()}
    if modes is not None:
        call = {k: v for k, v in call.items() if k not in ("binning", "frames")}
        options["modes"] = list(modes)
    return points, epc_fast.evaluate(**call, **space.evaluate_options, **options)


REDUCTIONS = {"s": Summary(), "below": FractionBelow(2e6),
              "q": Quantiles(q=(0.1, 0.5, 0.9), exact_up_to=0), "best": TopK(7)}


def test_a_phone_scans_in_the_fused_pass_as_evaluate_gives_its_points():
    space = _space()
    assert _fused(space, REDUCTIONS)
    result = run(space, N, seed=3, reductions=REDUCTIONS, progress=False)
    _, expected = _expected(space, 3)
    epc = expected.epc
    ok = np.isfinite(epc)
    summary = result["s"]
    # the same points and the same kernel: counts exact, the mean to its summation order
    assert np.array_equal(summary.status_counts[0],
                          np.bincount(expected.status, minlength=len(Status)))
    np.testing.assert_allclose(summary.mean[0], epc[ok].mean(), rtol=1e-13)
    assert summary.min[0] == epc[ok].min() and summary.max[0] == epc[ok].max()
    assert float(result["below"].fraction[0]) == np.mean(epc[ok] < 2e6)
    np.testing.assert_array_equal(np.sort(result["best"].value), np.sort(epc[ok])[-7:])
    # the streamed quantiles: within their bins' width (1000 a decade: 0.23%)
    np.testing.assert_allclose(next(iter(result["q"].quantile(0.5).values())), np.quantile(epc[ok], 0.5),
                               rtol=2.4e-3)
    # each point's mode, counted by the core: more than one is picked over 1 .. 1e5 lux
    picked = np.bincount(expected.mode + 1, minlength=4)
    assert np.array_equal(summary.mode_counts[0], picked) and np.sum(picked[1:] > 0) > 1


def test_the_fused_pass_and_the_arrays_give_one_phone_scan():
    space = _space()
    reductions = {"s": Summary(by="design"), "below": FractionBelow(2e6)}
    fused = run(space, N, seed=8, reductions=reductions, progress=False)
    arrays = run(space, N, seed=8, reductions=reductions, progress=False, backend="numpy")
    np.testing.assert_allclose(fused["s"].mean, arrays["s"].mean, rtol=1e-9)  # (the draws: ulps)
    assert abs(float(fused["below"].fraction[0]) - float(arrays["below"].fraction[0])) < 1e-3


def test_points_beyond_the_lens_table_are_counted_on_a_grid_key_too():
    # a lens that ends at 60 cycles/mm with its MTF still 0.7: the large pixels' f50 lies past it
    short = (np.array([0.0, 30.0, 60.0]), np.array([1.0, 0.85, 0.7]))
    space = _space(design=[PHONE], options={"lens_mtf": short},
                   pixel_pitch_um=Grid([0.8, 1.4, 3.0, 6.0]))
    reductions = {"s": Summary(by="pixel_pitch_um"), "all": Summary()}
    assert _fused(space, reductions)
    result = run(space, N, seed=5, reductions=reductions, progress=False)
    points, expected = _expected(space, 5, modes=None)
    beyond = expected.status == Status.BEYOND_TABLE
    assert beyond.any() and not beyond.all()
    assert result["all"].status_counts[0, Status.BEYOND_TABLE] == beyond.sum()
    pitch = points.parameters["pixel_pitch_um"]
    for k, p in enumerate((0.8, 1.4, 3.0, 6.0)):
        counts = np.bincount(expected.status[pitch == p], minlength=len(Status))
        assert np.array_equal(result["s"].status_counts[k], counts), p


def test_a_color_noise_gain_on_a_choice_takes_the_demosaickers_gain_once():
    space = _space(design=[PHONE], options=BAYER, color_noise_gain=Choice([0.8, 1.3]),
                   cfa_transmittance=Grid([0.3, 0.45]))
    reductions = {"s": Summary(by="color_noise_gain"), "best": TopK(3)}
    assert _fused(space, reductions)
    result = run(space, N, seed=6, reductions=reductions, progress=False)
    points, expected = _expected(space, 6, modes=None)
    gain = points.parameters["color_noise_gain"]
    assert set(np.unique(gain)) == {0.8, 1.3}  # the points as the space gives them
    for k, g in enumerate((0.8, 1.3)):
        ok = np.isfinite(expected.epc) & (gain == g)
        np.testing.assert_allclose(result["s"].mean[k], expected.epc[ok].mean(), rtol=1e-13)
    assert set(result["best"].parameters["color_noise_gain"]) <= {0.8, 1.3}


@pytest.mark.parametrize("change", [
    {"options": {"cfa": "quad_bayer"}},
    {"options": {**BAYER, "max_exposure_s": 0.1}},
    {"options": BAYER, "color_noise_gain": Uniform(0.8, 1.2)},  # drawn: unscaled in the core
    {"options": {"lens_mtf": [LENS, LENS]}, "lens": Choice([0, 1])},  # the table varies
    {"options": {"lens_mtf": LENS}, "f_number": Normal(2.0, 0.1)},  # no least f-number
    {"design": [{**PHONE, "modes": MODES}, {**PHONE, "name": "other", "modes": MODES[:2]}]},
    {"design": [{**PHONE, "modes": ({"binning": 1}, {"frames": "auto", "max_frames": 8})}]},
])
def test_spaces_the_fused_pass_cannot_read_are_evaluated_as_arrays(change):
    change = dict(change)
    design = change.pop("design", [PHONE])
    options = change.pop("options", {})
    space = _space(design=design, options=options, **change)
    assert not _fused(space, {"s": Summary()})


def test_a_lens_table_above_the_spaces_most_permissive_design_is_refused_first():
    # at f/8 and 550 nm diffraction ends at 227 cycles/mm, where the table is still 0.4
    design = [{k: v for k, v in PHONE.items() if k != "f_number"}]
    space = _space(design=design, options={"lens_mtf": LENS}, f_number=Uniform(8.0, 16.0))
    with pytest.raises(ValueError, match=r"lens_mtf lies above diffraction.*at f/8 and 550 nm"):
        run(space, N, seed=1, reductions={"s": Summary()}, progress=False)


def test_the_fused_phone_scan_does_not_depend_on_the_thread_count():
    space = _space()
    one = run(space, N, seed=9, reductions=REDUCTIONS, progress=False, threads=1)
    two = run(space, N, seed=9, reductions=REDUCTIONS, progress=False, threads=2)
    assert one["s"].mean[0] == two["s"].mean[0]
    assert one["q"].quantile(0.9) == two["q"].quantile(0.9)
    assert math.isfinite(one["s"].mean[0])
