"""The frame cap and night mode (epc_fast.exposure_limits; docs/model.md, "Exposure limits and
night mode"): EXPOSURE_LIMIT where T_MPE / frames exceeds max_exposure_s, checked against
evaluate's own T_MPE; frames="auto" against a brute-force search over n; bad values named."""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast.exposure_limits import least_frames

#: The paper's 1/3.2" sensor with a 1.4 um pixel and 2 e- of read noise (T_MPE grows with n).
DESIGN = dict(pixel_pitch_um=1.4, f_number=2.0, focal_length_mm=4.0, pixel_count=8e6,
              read_noise_e=2.0)
LUX = np.geomspace(0.3, 3e3, 23)


def test_the_default_cap_gives_todays_bits_and_inf_given_as_a_value_too():
    plain = epc_fast.evaluate(LUX, **DESIGN)
    for capped in (epc_fast.evaluate(LUX, **DESIGN, max_exposure_s=float("inf")),
                   epc_fast.evaluate(LUX, **DESIGN, max_exposure_s=np.full(LUX.shape, np.inf))):
        for name, value in plain.as_dict().items():
            assert np.array_equal(getattr(capped, name), value, equal_nan=True), name
        assert capped.frames_used is None


def test_a_point_just_over_the_cap_is_exposure_limit_and_just_under_ok():
    plain = epc_fast.evaluate(LUX, **DESIGN, frames=2)
    frame = plain.t_mpe_s / 2  # each of the burst's two frames, s
    above = epc_fast.evaluate(LUX, **DESIGN, frames=2, max_exposure_s=frame * (1 - 1e-12))
    below = epc_fast.evaluate(LUX, **DESIGN, frames=2, max_exposure_s=frame * (1 + 1e-12))
    assert np.all(above.status == Status.EXPOSURE_LIMIT) and np.all(below.status == Status.OK)
    for name, value in plain.as_dict().items():  # within the cap nothing changes
        assert np.array_equal(getattr(below, name), value), name
    # Over it: what the target would need stays, the image's outputs are NaN.
    for name in ("electron_rate_e_per_s", "electrons", "t_mpe_s", "cause"):
        assert np.array_equal(getattr(above, name), getattr(plain, name)), name
    for name in ("blur_mm", "f50_cyc_per_mm", "epc"):
        assert np.all(np.isnan(getattr(above, name))), name
    # Exactly at the cap the frame can be taken (T/n > c is the limit).
    assert np.all(epc_fast.evaluate(LUX, **DESIGN, frames=2, max_exposure_s=frame).status
                  == Status.OK)


def test_shares_elasticities_and_the_across_outputs_are_nan_over_the_cap():
    names = ("status", "share_motion", "elasticity_f_number", "f50_across_cyc_per_mm")
    r = epc_fast.evaluate([1.0, 1e4], **DESIGN, max_exposure_s=0.1, outputs=names)
    assert list(r.status) == [Status.EXPOSURE_LIMIT, Status.OK]
    for value in (r.share_motion, r.elasticities["f_number"], r.f50_across_cyc_per_mm):
        assert np.isnan(value[0]) and np.isfinite(value[1])
    both = epc_fast.evaluate([1.0, 1e4], **DESIGN, max_exposure_s=0.1, epc_axes="both")
    assert list(both.status) == [Status.EXPOSURE_LIMIT, Status.OK]
    assert np.isnan(both.epc[0]) and np.isnan(both.f50_across_cyc_per_mm[0])
    assert both.epc[1] == epc_fast.evaluate(1e4, **DESIGN, epc_axes="both").epc


def test_the_cap_applies_to_timed_statuses_only_and_a_scalar_call_gives_scalars():
    r = epc_fast.evaluate([0.0, 1.0, 1e4], **DESIGN, max_exposure_s=0.1)
    assert list(r.status) == [Status.UNREACHABLE, Status.EXPOSURE_LIMIT, Status.OK]
    one = epc_fast.evaluate(1.0, **DESIGN, max_exposure_s=0.1)
    assert one.status is Status.EXPOSURE_LIMIT and isinstance(one.t_mpe_s, float)
    assert math.isnan(one.epc) and one.t_mpe_s == r.t_mpe_s[1]


def test_the_cap_broadcasts_like_a_parameter():
    caps = np.array([[0.01], [1.0]])
    r = epc_fast.evaluate(LUX, **DESIGN, max_exposure_s=caps)
    plain = epc_fast.evaluate(LUX, **DESIGN)
    assert r.status.shape == (2, LUX.size)
    expected = np.where(plain.t_mpe_s > caps, Status.EXPOSURE_LIMIT, Status.OK)
    assert np.array_equal(r.status, expected) and (r.status == Status.OK).any()


def _brute_force_frames(lux, cap, max_frames, **design):
    """The least n in 1..max_frames whose frame evaluate(frames=n).t_mpe_s / n is within cap,
    one evaluate per point and n."""
    picked = []
    for x in lux:
        for n in range(1, max_frames + 1):
            if epc_fast.evaluate(x, **design, frames=n).t_mpe_s / n <= cap:
                picked.append(n)
                break
        else:
            picked.append(max_frames)
    return np.array(picked, dtype=float)


def test_night_mode_takes_the_least_frames_within_the_cap_by_brute_force():
    r = epc_fast.evaluate(LUX, **DESIGN, max_exposure_s=0.1, frames="auto", max_frames=8)
    expected = _brute_force_frames(LUX, 0.1, 8, **DESIGN)
    assert np.array_equal(r.frames_used, expected)
    assert 1 < len(np.unique(expected)) and expected.max() == 8  # the test spans the range
    again = epc_fast.evaluate(LUX, **DESIGN, frames=r.frames_used)
    for name in ("t_mpe_s", "electrons", "f50_cyc_per_mm"):
        ok = r.status == Status.OK
        assert np.array_equal(getattr(r, name)[ok], getattr(again, name)[ok]), name
    # Where eight frames are not enough, the eight are taken and the point is over the cap.
    over = again.t_mpe_s / 8 > 0.1
    assert over.any() and np.all(r.status[over] == Status.EXPOSURE_LIMIT)
    assert np.all(r.frames_used[over] == 8) and np.all(r.status[~over] == Status.OK)


@pytest.mark.parametrize("max_frames", [1, 2, 3, 5, 16, 17, 100])
def test_night_modes_search_finds_the_brute_force_count_on_random_sensors(max_frames):
    # the search bisects on n, which holds where "T_MPE(n) / n <= cap" holds from n* on: read
    # noise, dark current, PRNU, a full well and binning all vary here, and each candidate
    # count is evaluated alone to find the least that fits
    rng = np.random.default_rng(max_frames)
    n = 4000
    design = dict(illuminance_lux=10 ** rng.uniform(-1, 4, n), pixel_pitch_um=rng.uniform(0.8, 3, n),
                  f_number=2.0, focal_length_mm=5.6, sensor_area_mm2=20.0,
                  read_noise_e=rng.uniform(0, 5, n), dark_current_e_per_s=rng.uniform(0, 50, n),
                  prnu=rng.uniform(0, 0.02, n), full_well_e=rng.uniform(2e3, 2e4, n),
                  binning=rng.choice([1.0, 2.0], n))
    cap = 10 ** rng.uniform(-3, 0, n)
    r = epc_fast.evaluate(**design, max_exposure_s=cap, frames="auto", max_frames=max_frames,
                          outputs=("frames_used", "status"))
    counts = np.arange(1.0, max_frames + 1.0)
    fits = np.stack([epc_fast.evaluate(**design, frames=k, outputs=("t_mpe_s",)).t_mpe_s / k
                     for k in counts]) <= cap
    assert np.all(np.diff(fits.astype(int), axis=0) >= 0)  # fits from n* on: the premise
    expected = np.where(fits.any(axis=0), counts[np.argmax(fits, axis=0)], max_frames)
    np.testing.assert_array_equal(r.frames_used, expected)
    if max_frames >= 16:  # the points span the counts, and some fit none
        assert len(np.unique(expected)) >= 10 and (~fits.any(axis=0)).any()


def test_without_read_noise_night_mode_takes_the_ceiling_of_t_mpe_over_the_cap():
    design = {**DESIGN, "read_noise_e": 0.0}
    t_mpe = epc_fast.evaluate(LUX, **design).t_mpe_s  # the same for every n without read noise
    assert epc_fast.evaluate(LUX, **design, frames=5).t_mpe_s == pytest.approx(t_mpe, rel=1e-15)
    r = epc_fast.evaluate(LUX, **design, max_exposure_s=0.05, frames="auto", max_frames=1024)
    assert np.array_equal(r.frames_used, np.ceil(t_mpe / 0.05))
    assert np.all(r.status == Status.OK)


def test_night_mode_without_a_cap_takes_one_frame_and_frames_used_otherwise_is_frames():
    r = epc_fast.evaluate(LUX, **DESIGN, frames="auto", max_frames=8)
    assert np.all(r.frames_used == 1.0)
    assert np.array_equal(r.epc, epc_fast.evaluate(LUX, **DESIGN).epc)
    given = epc_fast.evaluate(LUX[:3], **DESIGN, frames=[1, 2, 4], outputs=("frames_used",))
    assert list(given.frames_used) == [1.0, 2.0, 4.0] and given.epc is None
    assert epc_fast.evaluate(1.0, **DESIGN, max_exposure_s=0.1).frames_used is None


def test_least_frames_picks_the_first_candidate_within_the_cap():
    frames = np.array([1.0, 2.0, 3.0])[:, None]
    t_mpe = np.array([[0.5, 0.1, np.inf, np.nan], [0.5, 0.1, 0.2, np.nan],
                      [0.5, 0.1, 0.3, np.nan]])
    assert list(least_frames(t_mpe, frames, 0.2)) == [3.0, 1.0, 2.0, 3.0]


def test_the_core_and_the_reference_agree():
    kw = dict(**DESIGN, max_exposure_s=0.1, frames="auto", max_frames=8)
    core = epc_fast.evaluate(LUX, **kw)
    reference = epc_fast.evaluate(LUX, **kw, backend="reference")
    assert np.array_equal(core.status, reference.status)
    assert np.array_equal(core.frames_used, reference.frames_used)
    # the backends agree to 1e-9 on f50 (docs/numerics.md), so on EPC to 2e-9
    np.testing.assert_allclose(core.epc, reference.epc, rtol=2e-9)


def test_a_bad_cap_is_an_invalid_point_or_an_error_naming_it():
    r = epc_fast.evaluate(10.0, **DESIGN, max_exposure_s=[0.1, np.nan, 0.0, -1.0, 10.0])
    assert list(r.status[1:4]) == [Status.INVALID] * 3 and r.status[4] == Status.OK
    assert np.all(np.isnan(r.t_mpe_s[1:4])) and np.all(np.isnan(r.epc[1:4]))
    with pytest.raises(ValueError, match=r"max_exposure_s=0.0 at index \(2,\) is outside its "
                                         r"domain \(0, inf\]"):
        epc_fast.evaluate(10.0, **DESIGN, max_exposure_s=[0.1, 1.0, 0.0], invalid="raise")
    with pytest.raises(TypeError, match="max_exposure_s"):
        epc_fast.evaluate(10.0, **DESIGN, max_exposure_s="fast")


@pytest.mark.parametrize("kwargs, match", [
    (dict(max_frames=8), r"max_frames=8 is given with frames=1.0: max_frames only with "
                         r"frames='auto'"),
    (dict(frames=2, max_frames=8), r"max_frames=8 is given with frames=2"),
    (dict(frames="night", max_frames=8), r"frames='night': a whole number >= 1, or 'auto'"),
    (dict(frames="auto", max_frames=0), r"max_frames=0: a whole number in 1 .. 1024"),
    (dict(frames="auto", max_frames=2.5), r"max_frames=2.5"),
    (dict(frames="auto", max_frames=True), r"max_frames=True"),
])
def test_night_modes_keywords_are_checked_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        epc_fast.evaluate(10.0, **DESIGN, **kwargs)


def test_night_mode_without_max_frames_is_refused_naming_frames():
    # frames="auto" alone is a string where a number belongs: the call's own check names it
    # (evaluate tells night mode by max_frames, which keeps its fixed cost)
    with pytest.raises(TypeError, match="frames must be a number"):
        epc_fast.evaluate(10.0, **DESIGN, frames="auto")
    with pytest.raises(ValueError, match=r"modes\[1\]: frames='auto' \(night mode\) needs "
                                         "max_frames"):
        epc_fast.evaluate(10.0, **DESIGN, modes=[{}, {"frames": "auto"}])


def test_out_is_refused_with_the_cap():
    with pytest.raises(TypeError, match="out= cannot be given with max_exposure_s"):
        epc_fast.evaluate(10.0, **DESIGN, max_exposure_s=0.1, out={})
