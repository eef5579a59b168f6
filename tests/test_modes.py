"""Readout modes (epc_fast.modes, evaluate(modes=...)): per point the mode with the highest
EPC, its outputs and its index, against each mode evaluated alone; bad modes refused by name."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast._validation import compiled_core
from epc_fast.modes import NO_MODE, check_modes

#: A 200 MP 0.56 um phone sensor: read 1x1, 4x4-binned, and 4x4-binned in bursts of 8.
SENSOR = dict(pixel_pitch_um=0.56, f_number=1.8, focal_length_mm=6.0, sensor_area_mm2=62.7,
              read_noise_e=2.0, dark_current_e_per_s=5.0)
MODES = [{"binning": 1}, {"binning": 4}, {"binning": 4, "frames": 8, "alignment_error_um": 0.5}]
LUX = np.geomspace(0.5, 1e5, 41)


def test_each_point_gets_the_mode_with_the_highest_epc_and_its_outputs():
    r = epc_fast.evaluate(LUX, **SENSOR, modes=MODES)
    alone = [epc_fast.evaluate(LUX, **SENSOR, **m) for m in MODES]
    epc = np.stack([a.epc for a in alone])
    assert np.array_equal(r.mode, np.argmax(np.where(np.isfinite(epc), epc, -np.inf), axis=0))
    for i in range(LUX.size):
        chosen = alone[r.mode[i]]
        for name in ("epc", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "electrons", "status"):
            assert getattr(r, name)[i] == getattr(chosen, name)[i], name
    # Dim light picks the burst, daylight full resolution: the point of modes.
    assert r.mode[0] == 2 and r.mode[-1] == 0 and r.mode.dtype == np.int16
    assert np.all(r.epc >= epc.max(axis=0, initial=0, where=np.isfinite(epc)))


def test_a_scalar_call_gives_scalars_and_equal_epcs_pick_the_first():
    r = epc_fast.evaluate(1e4, **SENSOR, modes=[{"binning": 1}, {"frames": 1, "binning": 1.0,
                                                                 "alignment_error_um": 0.5}])
    assert r.mode == 0 and isinstance(r.mode, int) and isinstance(r.epc, float)
    assert r.status == Status.OK and isinstance(r.status, Status)


def test_where_no_mode_has_an_epc_the_first_modes_outputs_say_why():
    r = epc_fast.evaluate([0.0, 100.0], **SENSOR, modes=MODES)
    assert r.mode[0] == NO_MODE and r.status[0] == Status.UNREACHABLE
    assert r.mode[1] >= 0


def test_outputs_and_sensitivities_follow_the_chosen_mode():
    r = epc_fast.evaluate(LUX[:5], **SENSOR, modes=MODES,
                          outputs=("status", "share_alignment", "elasticity_f_number"))
    assert r.epc is None and r.t_mpe_s is None
    alone = [epc_fast.evaluate(LUX[:5], **SENSOR, **m, outputs=("epc", "share_alignment"))
             for m in MODES]
    for i in range(5):
        assert r.share_alignment[i] == alone[r.mode[i]].share_alignment[i]
    assert set(r.elasticities) == {"f_number"}


@pytest.mark.parametrize("modes, error, match", [
    ([], ValueError, "at least one"),
    ({"binning": 4}, TypeError, "a list of readout modes"),
    ("binning", TypeError, "a list of readout modes"),
    ([{"binning": 4}, 3], TypeError, r"modes\[1\]"),
    ([{"binnig": 4}], ValueError, r"'binnig' is not a readout mode's key"),
    ([{"binning": 4}, {"binning": 4.0}], ValueError, r"modes\[1\] repeats modes\[0\]"),
    ([{"binning": [1, 4]}], ValueError, "one value a mode"),
])
def test_bad_modes_are_refused_by_name(modes, error, match):
    with pytest.raises(error, match=match):
        check_modes(modes)
    with pytest.raises(error, match=match):
        epc_fast.evaluate(100.0, **SENSOR, modes=modes)


def test_a_mode_key_given_to_evaluate_as_well_and_out_are_refused():
    with pytest.raises(ValueError, match="binning = 2 is given to evaluate and in modes"):
        epc_fast.evaluate(100.0, **SENSOR, binning=2, modes=MODES)
    with pytest.raises(TypeError, match="out= cannot be given with modes"):
        epc_fast.evaluate(100.0, **SENSOR, modes=MODES, out={})


def test_a_bad_value_in_a_mode_is_the_points_status_as_any_bad_value():
    r = epc_fast.evaluate(100.0, **SENSOR, modes=[{"binning": 2.5}, {"binning": 1}])
    assert r.mode == 1
    with pytest.raises(ValueError, match="binning"):
        epc_fast.evaluate(100.0, **SENSOR, modes=[{"binning": 2.5}], invalid="raise")


def test_a_quad_bayer_sensors_modes_read_one_layout_each():
    # full size is remosaicked, binned 2 x 2 is the Bayer sensor of twice the pitch: each mode
    # is its own call with its binning, and the pick is the better of the two per point
    quad = dict(pixel_pitch_um=1.0, f_number=1.9, focal_length_mm=5.6, sensor_width_mm=8.16,
                sensor_height_mm=6.12, read_noise_e=1.5, cfa="quad_bayer")
    lux = np.array([1.0, 10.0, 100.0, 1e3, 1e4])
    modes = [{"binning": 1}, {"binning": 2}]
    r = epc_fast.evaluate(lux, **quad, modes=modes)
    full = epc_fast.evaluate(lux, **quad, binning=1)
    binned = epc_fast.evaluate(lux, **{**quad, "cfa": "bayer"}, binning=2)
    best = np.where(full.epc >= binned.epc, full.epc, binned.epc)
    np.testing.assert_array_equal(r.epc, best)
    np.testing.assert_array_equal(r.mode, np.where(full.epc >= binned.epc, 0, 1))
    assert set(np.asarray(r.mode).tolist()) == {0, 1}  # dim light binned, daylight full size


#: A 1/10 s frame cap's modes: full size, 2 x 2 binned, and 2 x 2 binned night mode.
NIGHT_MODES = [{}, {"binning": 2}, {"binning": 2, "frames": "auto", "max_frames": 8}]
#: The paper's 1/3.2" sensor with a 1.4 um pixel and 2 e- of read noise.
PHONE = dict(pixel_pitch_um=1.4, f_number=2.0, focal_length_mm=4.0, pixel_count=8e6,
             read_noise_e=2.0)


def test_a_frame_cap_picks_night_mode_in_dim_light_and_no_mode_past_its_frames():
    lux = np.array([1.0, 10.0, 100.0, 1e4])
    r = epc_fast.evaluate(lux, **PHONE, max_exposure_s=0.1, modes=NIGHT_MODES)
    alone = [epc_fast.evaluate(lux, **PHONE, max_exposure_s=0.1, **m) for m in NIGHT_MODES]
    epc = np.stack([a.epc for a in alone])
    finite = np.isfinite(epc)
    pick = np.where(finite.any(axis=0), np.argmax(np.where(finite, epc, -np.inf), axis=0), -1)
    assert np.array_equal(r.mode, pick)
    # 1 lux: 2 s of exposure binned, more than 8 frames of 1/10 s: no mode, the first's status;
    # 10 lux: 0.2 s binned, so three frames (T_MPE(3) / 3 <= 0.1 s, T_MPE(2) / 2 > 0.1 s);
    # 100 lux: binned frames of 0.02 s, night mode's one frame equals it, the first is taken;
    # daylight: full size.
    assert list(r.mode) == [NO_MODE, 2, 1, 0]
    assert r.status[0] == Status.EXPOSURE_LIMIT and np.isnan(r.epc[0])
    assert list(r.frames_used) == [1.0, 3.0, 1.0, 1.0]  # each picked mode's frames
    assert alone[2].frames_used[1] == 3.0 and alone[2].frames_used[0] == 8.0
    t2, t3 = (epc_fast.evaluate(10.0, **PHONE, binning=2, frames=n).t_mpe_s for n in (2, 3))
    assert t2 / 2 > 0.1 >= t3 / 3


def test_night_modes_are_checked_and_compared_as_modes():
    with pytest.raises(ValueError, match=r"modes\[1\] repeats modes\[0\]"):
        check_modes([{"frames": "auto", "max_frames": 8}, {"frames": "auto", "max_frames": 8.0}])
    with pytest.raises(ValueError, match=r"modes\[0\]: max_frames=8 is given with frames=1.0"):
        check_modes([{"max_frames": 8}])
    assert len(check_modes([{"frames": "auto", "max_frames": 8},
                            {"frames": "auto", "max_frames": 4}, {"frames": 8}])) == 3
    with pytest.raises(ValueError, match="frames = 'auto' is given to evaluate and in modes"):
        epc_fast.evaluate(10.0, **PHONE, frames="auto", max_frames=8, modes=[{"frames": 2}])


def _numpy_pick(epcs):
    epc = np.stack(epcs)
    finite = np.isfinite(epc)
    pick = np.argmax(np.where(finite, epc, -np.inf), axis=0)
    return np.where(finite.any(axis=0), pick, NO_MODE)


def test_the_cores_pick_is_the_first_largest_finite_epc_on_any_thread_count():
    core = compiled_core()
    rng = np.random.default_rng(5)
    n = 100_003  # blocks of 4096 and a partial last one
    # few distinct values, so that ties are common; NaN, +-inf and -0.0 among them
    choices = np.array([np.nan, np.inf, -np.inf, 0.0, -0.0, 1.0, 2.0, 2.0 + 2**-51, 3e300])
    epcs = [rng.choice(choices, n) for _ in range(4)]
    expected = _numpy_pick(epcs)
    assert np.count_nonzero(expected == NO_MODE) > 100  # points with no mode at all
    for threads in (1, 2):
        mode = core.best_mode(epcs, threads)
        assert mode.dtype == np.int16
        np.testing.assert_array_equal(mode, expected)
    pick = np.maximum(expected, 0)
    for dtype in (np.uint8, np.int16, np.float32, np.float64, np.int64):
        values = [rng.integers(0, 100, n).astype(dtype) for _ in range(4)]
        taken = core.take_mode(mode, values, 2)
        assert taken.dtype == dtype
        np.testing.assert_array_equal(taken, np.take_along_axis(np.stack(values), pick[None], 0)[0])


def test_the_cores_pick_refuses_columns_it_cannot_read_in_one_line():
    core = compiled_core()
    one = np.ones(10)
    with pytest.raises(ValueError, match="one C-contiguous 1-d array of 10 items per mode"):
        core.best_mode([one, np.ones(9)], 1)
    with pytest.raises(ValueError, match="one C-contiguous 1-d array"):
        core.take_mode(np.zeros(10, np.int16), [one, one.astype(np.float32)], 1)
    with pytest.raises(ValueError, match="an index past the modes given"):
        core.take_mode(np.full(10, 2, np.int16), [one, one], 1)
    with pytest.raises(ValueError, match="between 1 and 32767 modes"):
        core.best_mode([], 1)


@pytest.mark.parametrize("shape", [(41,), (3, 41)])
def test_the_core_and_the_reference_backend_pick_the_same_modes(shape):
    lux = np.broadcast_to(LUX, shape)
    core = epc_fast.evaluate(lux, **SENSOR, modes=MODES, threads=2)
    ref = epc_fast.evaluate(lux, **SENSOR, modes=MODES, backend="reference")
    assert core.mode.shape == shape and core.epc.shape == shape
    np.testing.assert_array_equal(core.mode, ref.mode)
    np.testing.assert_array_equal(core.status, ref.status)
    np.testing.assert_allclose(core.epc, ref.epc, rtol=1e-12)  # the backends' own agreement


#: Modes that set binning and frames (one of them outside binning's domain: every point
#: INVALID in it); alignment_error_um stays the call's own column, per point.
CORE_MODES = [{"binning": 1}, {"binning": 2, "binning_readout": "charge"},
              {"binning": 1, "frames": 4}, {"binning": 0.5}]


@pytest.mark.parametrize("options", [
    {}, {"precision": "float32"}, {"threads": 1}, {"epc_axes": "both"},
    {"outputs": ("epc", "status", "cause", "share_pixel", "share_motion", "elasticities")},
    {"outputs": ("f50_cyc_per_mm", "f50_across_cyc_per_mm", "t_mpe_s")},
])
def test_the_cores_one_pass_over_the_modes_is_each_mode_alone_and_the_pick(options):
    # evaluate(modes=...) runs every mode of a block in turn in the core and keeps each lane's
    # best (modes.h evaluate_modes): the same bits as a call per mode and the pick
    from helpers.designs import random_design_points

    p = random_design_points(3000, 23, sensor_terms=True)
    del p["binning"], p["frames"]
    r = epc_fast.evaluate(**p, modes=CORE_MODES, **options)
    alone = [epc_fast.evaluate(**p, **m, **{**options, "outputs": None}
                               if "outputs" not in options else
                               {**options, "outputs": (*options["outputs"], "epc")})
             for m in CORE_MODES]
    pick = _numpy_pick([a.epc for a in alone])
    np.testing.assert_array_equal(r.mode, pick)
    assert {-1, 0, 1, 2} <= set(np.unique(r.mode).tolist())
    assert np.all(np.isnan(alone[3].epc))  # binning 0.5: INVALID everywhere
    take = np.maximum(pick, 0)
    names = [n for n in epc_fast.Result.__dataclass_fields__
             if n not in ("mode", "elasticities", "snr_target") and getattr(r, n) is not None]
    assert names
    for name in names:
        expected = np.take_along_axis(np.stack([getattr(a, name) for a in alone]), take[None], 0)[0]
        np.testing.assert_array_equal(getattr(r, name), expected, err_msg=name)
    if r.elasticities is not None:
        for key, values in r.elasticities.items():
            expected = np.take_along_axis(np.stack([a.elasticities[key] for a in alone]),
                                          take[None], 0)[0]
            np.testing.assert_array_equal(values, expected, err_msg=key)
