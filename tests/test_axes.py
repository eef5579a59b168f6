"""EPC counted in both directions (epc_fast.axes; docs/model.md, "Resolution in both
directions"): f50 across the motion, EPC = 4 S f50 f50_across and every consumer of it."""

import inspect
import math

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, evaluate, inverse, presets
from epc_fast.axes import EPC_AXES, epc_both

#: The paper's 1/3.2" 1.4 um design (presets.HIGH_TIER[3]).
DESIGN = presets.HIGH_TIER[3].evaluate_kwargs()
#: Relative tolerance of an EPC formed from the same two f50s in another order of rounding:
#: 4 S f50 f50_across against EPC f50_across / f50 differ by a few roundings.
ROUNDING = 8 * np.finfo(float).eps


def test_the_default_is_the_papers_epc_and_both_is_each_direction_once():
    lux = np.geomspace(0.1, 1e5, 13)
    motion = evaluate(lux, **DESIGN)
    plain = evaluate(lux, **DESIGN, epc_axes="motion")
    both = evaluate(lux, **DESIGN, epc_axes="both")
    for name in ("epc", "f50_cyc_per_mm", "t_mpe_s", "status"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(motion, name))
    assert motion.f50_across_cyc_per_mm is None  # computed only when asked
    area_mm2 = DESIGN["sensor_area_mm2"]
    expected = 4 * area_mm2 * both.f50_cyc_per_mm * both.f50_across_cyc_per_mm
    np.testing.assert_allclose(both.epc, expected, rtol=ROUNDING)
    np.testing.assert_array_equal(both.f50_cyc_per_mm, motion.f50_cyc_per_mm)
    # the motion only lowers the MTF: across >= along, so the count in both directions is
    # at least the paper's, equal where the shake blurs nothing
    assert np.all(both.f50_across_cyc_per_mm >= motion.f50_cyc_per_mm)
    assert np.all(both.epc >= motion.epc)
    still = evaluate(lux, **{**DESIGN, "shake_deg_per_s": 0.0}, epc_axes="both")
    np.testing.assert_allclose(still.epc, evaluate(lux, **{**DESIGN, "shake_deg_per_s": 0.0}).epc,
                               rtol=ROUNDING)


def test_f50_across_is_the_system_mtf_without_motion_and_keeps_jitter_and_alignment():
    lux = np.array([1.0, 10.0, 1e3, 1e5])
    kw = dict(DESIGN, jitter_um=0.4, frames=4.0, alignment_error_um=0.3)
    across = evaluate(lux, **kw, outputs="f50_across_cyc_per_mm").f50_across_cyc_per_mm
    # independent of the illuminance and of the shake, which set only the motion blur
    np.testing.assert_array_equal(across, np.full(4, across[0]))
    other = evaluate(lux, **{**kw, "shake_deg_per_s": 40.0},
                     outputs="f50_across_cyc_per_mm").f50_across_cyc_per_mm
    np.testing.assert_array_equal(other, across)
    # and it is the f50 of the design without the motion blur, jitter and alignment kept
    still = evaluate(lux, **{**kw, "shake_deg_per_s": 0.0}).f50_cyc_per_mm
    np.testing.assert_array_equal(across, still)
    no_jitter = evaluate(1.0, **{**kw, "jitter_um": 0.0}, outputs="f50_across_cyc_per_mm")
    assert no_jitter.f50_across_cyc_per_mm > across[0] * 1.05


def test_a_burst_and_binning_gain_far_less_counted_in_both_directions():
    """The 1.4 um design at 10 lux: 2x2 binning and 4 frames, against full size."""
    def gain(epc_axes, **mode):
        full = evaluate(10.0, **DESIGN, epc_axes=epc_axes).epc
        return evaluate(10.0, **DESIGN, **mode, epc_axes=epc_axes).epc / full

    # the figures docs/beyond.md gives: 16.3x, 16.3x and 3,956x counted along the motion
    assert gain("motion", binning=2.0) == pytest.approx(16.30, rel=1e-3)
    assert gain("both", binning=2.0) == pytest.approx(2.904, rel=1e-3)
    assert gain("motion", frames=4.0) == pytest.approx(16.30, rel=1e-3)
    assert gain("both", frames=4.0) == pytest.approx(4.038, rel=1e-3)
    assert gain("motion", denoise_sigma_px=3.0) == pytest.approx(3956, rel=1e-3)
    assert gain("both", denoise_sigma_px=3.0) == pytest.approx(12.10, rel=1e-3)
    # across the motion binning loses the pixel's resolution, which the paper's count
    # never sees; 4 frames cut each frame's blur four-fold and keep the resolution across
    assert gain("both", frames=4.0) > gain("both", binning=2.0)


def test_modes_pick_by_the_epc_their_call_counts():
    lux = np.geomspace(0.3, 3e4, 25)
    modes = [{"binning": 1}, {"binning": 2}, {"frames": 4}]
    for epc_axes in EPC_AXES:
        picked = evaluate(lux, **DESIGN, modes=modes, epc_axes=epc_axes)
        each = np.stack([evaluate(lux, **DESIGN, **m, epc_axes=epc_axes).epc for m in modes])
        np.testing.assert_array_equal(picked.mode, np.argmax(each, axis=0))
        np.testing.assert_array_equal(picked.epc, each.max(axis=0))
    both = evaluate(lux, **DESIGN, modes=modes, epc_axes="both")
    assert both.f50_across_cyc_per_mm is not None
    # with read noise, 2 frames against 2x2 binning: in both directions binning loses the
    # pixel's resolution across the motion, and the camera takes the burst in brighter light
    modes = [{"binning": 1}, {"binning": 2}, {"frames": 2}]
    noisy = dict(DESIGN, read_noise_e=2.0)
    both = evaluate(lux, **noisy, modes=modes, epc_axes="both").mode
    motion = evaluate(lux, **noisy, modes=modes).mode
    changed = np.flatnonzero(both != motion)
    assert changed.size and np.all(motion[changed] == 1) and np.all(both[changed] == 2)


def test_elasticities_in_both_directions_are_the_derivatives_of_ln_epc():
    kw = dict(DESIGN, read_noise_e=2.0, jitter_um=0.2, shake_deg_per_s=4.39,
              illuminance_lux=5.0)
    result = evaluate(**kw, epc_axes="both", outputs=("epc", "elasticities"))
    step = 1e-5  # central difference in ln theta: truncation ~ step^2, rounding ~ 1e-16/step
    for name in ("illuminance_lux", "f_number", "pixel_pitch_um", "shake_deg_per_s",
                 "jitter_um", "read_noise_e"):
        up = evaluate(**{**kw, name: kw[name] * math.exp(step)}, epc_axes="both").epc
        down = evaluate(**{**kw, name: kw[name] * math.exp(-step)}, epc_axes="both").epc
        numeric = (math.log(up) - math.log(down)) / (2 * step)
        assert result.elasticities[name] == pytest.approx(numeric, rel=1e-6, abs=1e-8), name


def test_the_reference_and_the_core_agree_in_both_directions():
    lux = np.geomspace(0.05, 1e5, 9)
    kw = dict(DESIGN, jitter_um=0.3, frames=2.0, alignment_error_um=0.2)
    outputs = ("epc", "status", "f50_across_cyc_per_mm", "share_pixel_across",
               "share_motion_across", "share_diffraction", "elasticities")
    core = evaluate(lux, **kw, epc_axes="both", outputs=outputs)
    ref = evaluate(lux, **kw, epc_axes="both", outputs=outputs, backend="reference")
    np.testing.assert_array_equal(core.status, ref.status)
    # the core's f50 is solved to f50_rtol 1e-14, the reference bisects to adjacent floats
    np.testing.assert_allclose(core.f50_across_cyc_per_mm, ref.f50_across_cyc_per_mm, rtol=1e-13)
    np.testing.assert_allclose(core.epc, ref.epc, rtol=1e-12)
    np.testing.assert_allclose(core.share_pixel_across, ref.share_pixel_across, rtol=1e-9)
    np.testing.assert_array_equal(core.share_motion_across, 0.0)
    for key, value in core.elasticities.items():
        np.testing.assert_allclose(value, ref.elasticities[key], rtol=1e-7, atol=1e-9,
                                   err_msg=key)


def test_statuses_in_both_directions():
    lux = np.array([0.0, 1e-3, 10.0])
    both = evaluate(lux, **DESIGN, epc_axes="both")
    assert list(both.status) == [Status.UNREACHABLE, Status.BLUR_UNBOUNDED, Status.OK]
    assert np.isnan(both.f50_across_cyc_per_mm[0]) and np.isnan(both.epc[0])
    # an unbounded blur: EPC 0 in both counts, the f50 across it finite and that of 10 lux
    assert both.epc[1] == 0.0 and both.f50_across_cyc_per_mm[1] == both.f50_across_cyc_per_mm[2]
    # a point whose f50 across passes its lens table's end is BEYOND_TABLE in both counts
    table = ([0.0, 60.0, 120.0], [1.0, 0.8, 0.6])  # 0.6 x the pixel's 0.95 at its end
    kw = {**DESIGN, "lens_mtf": table}
    motion = evaluate(100.0, **kw)  # f50 5.6 cycles/mm along the motion
    both = evaluate(100.0, **kw, epc_axes="both")
    assert motion.status == Status.OK and both.status == Status.BEYOND_TABLE
    assert math.isnan(both.epc) and math.isnan(both.f50_across_cyc_per_mm)
    # an invalid shake stays INVALID across the motion
    bad = evaluate(10.0, **{**DESIGN, "shake_deg_per_s": -1.0},
                   outputs=("status", "f50_across_cyc_per_mm"))
    assert bad.status == Status.INVALID and math.isnan(bad.f50_across_cyc_per_mm)


def test_shapes_broadcast_as_the_pass_along_the_motion():
    shake = np.array([[0.0], [4.39], [20.0]])
    both = evaluate(np.array([1.0, 100.0]), **{**DESIGN, "shake_deg_per_s": shake},
                    epc_axes="both")
    assert both.epc.shape == both.f50_across_cyc_per_mm.shape == both.status.shape == (3, 2)
    scalar = evaluate(10.0, **DESIGN, epc_axes="both")
    assert isinstance(scalar.epc, float) and isinstance(scalar.f50_across_cyc_per_mm, float)
    assert isinstance(scalar.status, Status)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"epc_axes": "across"}, ValueError, "epc_axes"),
    ({"epc_axes": "both", "out": {}, "outputs": "elasticities"}, TypeError,
     "out= cannot take the elasticities with epc_axes"),
    ({"epc_axes": "both", "out": {"epc": np.empty(2)}, "outputs": "epc"}, ValueError,
     r"out\['epc'\] has shape \(2,\), expected the broadcast shape \(\)"),
    ({"outputs": ("f50_across_cyc_per_mm", "nonsense")}, ValueError, "nonsense"),
])
def test_bad_epc_axes_and_its_refusals_name_the_argument(kwargs, error, match):
    with pytest.raises(error, match=match):
        evaluate(10.0, **DESIGN, **kwargs)


def test_out_takes_the_outputs_in_both_directions_and_the_result_holds_its_arrays():
    lux = np.geomspace(1.0, 1e4, 5)
    out = {"epc": np.empty(5), "status": np.empty(5, np.uint8),
           "f50_across_cyc_per_mm": np.empty(5)}
    result = evaluate(lux, **DESIGN, epc_axes="both", out=out,
                      outputs=("epc", "status", "f50_across_cyc_per_mm"))
    plain = evaluate(lux, **DESIGN, epc_axes="both")
    for name, array in out.items():
        assert getattr(result, name) is array
        np.testing.assert_array_equal(array, getattr(plain, name))


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_lux_for_epc_in_both_directions_reaches_the_target_as_evaluate_counts_it(backend):
    design = {k: v for k, v in DESIGN.items()}
    target = np.array([1e5, 1e6, 2e6])  # below the 2.93e6 it reaches at the range's top
    solved = inverse.lux_for_epc(design, target, epc_axes="both", backend=backend)
    assert np.all(solved.status == inverse.InverseStatus.OK)
    reached = evaluate(solved.illuminance_lux, **design, epc_axes="both").epc
    np.testing.assert_allclose(reached, target, rtol=1e-9)  # Brent's rtol 1e-13 on L, x EPC slope
    motion = inverse.lux_for_epc(design, target, backend=backend)
    assert np.all(solved.illuminance_lux < motion.illuminance_lux)  # more counted, less light


def test_crossover_lux_in_both_directions_is_where_both_counts_are_equal():
    a, b = presets.HIGH_TIER[0].evaluate_kwargs(), presets.HIGH_TIER[3].evaluate_kwargs()
    for epc_axes in EPC_AXES:
        core = inverse.crossover_lux(a, b, epc_axes=epc_axes)
        ref = inverse.crossover_lux(a, b, epc_axes=epc_axes, backend="reference")
        assert core.status == inverse.InverseStatus.OK
        assert core.illuminance_lux == pytest.approx(ref.illuminance_lux, rel=1e-9)
        ea = evaluate(core.illuminance_lux, **a, epc_axes=epc_axes).epc
        eb = evaluate(core.illuminance_lux, **b, epc_axes=epc_axes).epc
        assert ea == pytest.approx(eb, rel=1e-9)


def test_epc_both_of_an_unbounded_blur_is_zero_and_nan_stays_nan():
    np.testing.assert_array_equal(epc_both([0.0, np.nan, 8.0], [0.0, np.nan, 2.0],
                                           [3.0, 3.0, 4.0]), [0.0, np.nan, 16.0])


def test_the_package_names_the_axes():
    assert epc_fast.axes.EPC_AXES == ("motion", "both")


def _two_passes(kwargs, **options):
    """The outputs in both directions from two calls, as docs/model.md defines them: along the
    motion as asked, across it with the shake rate 0 (kept where it is out of its domain)."""
    along = evaluate(**kwargs, **options)
    default = inspect.signature(evaluate).parameters["shake_deg_per_s"].default
    shake = np.asarray(kwargs.get("shake_deg_per_s", default), dtype=float)
    still = np.where((shake >= 0.0) & (shake <= 1e300), 0.0, shake)
    across = evaluate(**{**kwargs, "shake_deg_per_s": still}, **options)
    status = np.where((along.status == Status.OK) & (across.status == Status.BEYOND_TABLE),
                      Status.BEYOND_TABLE, along.status)
    epc = epc_both(along.epc, along.f50_cyc_per_mm, across.f50_cyc_per_mm)
    return along, across.f50_cyc_per_mm, status, np.where(status == Status.BEYOND_TABLE, np.nan, epc)


@pytest.mark.parametrize("options", [{}, {"precision": "float32"}, {"f50_solver": "bisection"},
                                     {"f50_solver": "brent"}, {"f50_solver": "newton"}])
def test_the_cores_one_pass_across_the_motion_is_two_calls_bit_for_bit(options):
    # the core solves f50 across the motion in the same pass (kernel.h across_f50): the same
    # bits as a second call with the shake rate 0, over designs with every status (unbounded
    # blur, lens tables passed across but not along, invalid points), denoising and binning
    from helpers.designs import random_design_points

    p = random_design_points(3000, 17, sensor_terms=True)
    rng = np.random.default_rng(3)
    p["shake_deg_per_s"] = np.where(rng.random(3000) < 0.05, 1e12, p["shake_deg_per_s"])
    p["denoise_sigma_px"] = np.where(rng.random(3000) < 0.3, rng.uniform(0, 3, 3000), 0.0)
    p["lens"] = rng.integers(0, 2, 3000).astype(float)
    tables = [([0.0, 60.0, 120.0], [1.0, 0.8, 0.6]), ([0.0, 300.0, 600.0], [1.0, 0.5, 0.1])]
    kwargs = {**p, "lens_mtf": tables}
    along, f50_across, status, epc = _two_passes(kwargs, **options)
    both = evaluate(**kwargs, **options, epc_axes="both")
    seen = set(np.unique(both.status).tolist())
    assert {Status.OK, Status.BLUR_UNBOUNDED, Status.BEYOND_TABLE, Status.INVALID} <= seen, seen
    assert np.any((along.status == Status.OK) & (status == Status.BEYOND_TABLE))
    np.testing.assert_array_equal(both.status, status)
    np.testing.assert_array_equal(both.f50_across_cyc_per_mm, f50_across)
    np.testing.assert_array_equal(both.epc, epc)
    np.testing.assert_array_equal(both.f50_cyc_per_mm, along.f50_cyc_per_mm)
    np.testing.assert_array_equal(both.t_mpe_s, along.t_mpe_s)
    # along the motion with the f50 across asked for: the paper's EPC and status
    motion = evaluate(**kwargs, **options, outputs=("epc", "status", "f50_across_cyc_per_mm"))
    np.testing.assert_array_equal(motion.epc, along.epc)
    np.testing.assert_array_equal(motion.status, along.status)
    np.testing.assert_array_equal(motion.f50_across_cyc_per_mm, f50_across)


def test_the_one_pass_is_the_same_on_any_thread_count_and_takes_a_spectrum():
    spectrum = ([450.0, 550.0, 650.0], [0.25, 0.5, 0.25])
    lux = np.geomspace(1e-3, 1e5, 2001)
    one = evaluate(lux, **DESIGN, epc_axes="both", spectrum=spectrum, threads=1)
    two = evaluate(lux, **DESIGN, epc_axes="both", spectrum=spectrum, threads=2)
    for name in ("epc", "status", "f50_across_cyc_per_mm"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
    _, f50_across, _, epc = _two_passes({**DESIGN, "illuminance_lux": lux}, spectrum=spectrum)
    np.testing.assert_array_equal(one.epc, epc)
    np.testing.assert_array_equal(one.f50_across_cyc_per_mm, f50_across)
