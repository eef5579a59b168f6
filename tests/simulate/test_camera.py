"""The capture (epc_fast.simulate.capture): its image against the exact image of an edge, the
photo-electrons the model needs at T_MPE, its noise's statistics, reproducibility from a seed,
and every bad input refused with a message naming it."""

import math

import numpy as np
import pytest

import epc_fast
from epc_fast import presets, simulate
from epc_fast.simulate import camera
from helpers.edges import edge_spread

DESIGN = presets.HIGH_TIER[0].evaluate_kwargs()  # 2.8 um, F/2.8, the SNR met at the corner


def per_reflectance(c, design):
    """e- a pixel collects per unit reflectance: the model's r T over its target's reflectance."""
    r = c.result
    return float(r.electron_rate_e_per_s) * c.exposure_s / design.get("reflectance", 0.4)


@pytest.mark.parametrize("extra, lux", [
    ({}, 1e5),                                               # diffraction and the pixel
    ({"fill_factor": 0.5, "jitter_um": 0.7}, 1e5),           # a small aperture and jitter
    ({}, 300.0),                                             # 10 pixels of motion
    ({"pixel_pitch_um": 1.1, "f_number": 2.0}, 1e4),         # q = 3 samples a pixel
])
def test_an_edges_capture_is_the_exact_image_of_the_edge(extra, lux):
    design = {**DESIGN, **extra}
    chart = simulate.slanted_edge((48, 96), 5.0)
    c = simulate.capture(chart, illuminance_lux=lux, seed=1, **design)
    rows, cols = chart.shape
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    a = math.radians(5.0)
    p = design["pixel_pitch_um"]
    d = ((x - (cols - 1) / 2) * math.cos(a) - (y - (rows - 1) / 2) * math.sin(a)) * p * 1e-3
    omega = math.radians(design.get("shake_deg_per_s", 4.39)) / design.get("stabilization", 1.0)
    esf = edge_spread(d, angle_deg=5.0, f_number=design["f_number"], wavelength_nm=550.0,
                      pitch_um=p, fill_factor=design.get("fill_factor", 1.0),
                      jitter_mm=design.get("jitter_um", 0.0) * 1e-3,
                      motion=(c.exposure_s, design["focal_length_mm"], omega))
    want = 0.1 + 0.3 * esf
    got = c.expected_e / per_reflectance(c, design)
    # The 2-D grid wraps round 200 lambda F beyond the chart: the far side leaks under 3.3e-4
    # of the contrast (0.3) into it (focal_plane.PSF_REACH); the 1-D edge, on a 40 mm period,
    # under 1e-5. Measured: 1.3e-4 at most.
    assert np.max(np.abs(got - want)) < 3.3e-4 * 0.3
    assert c.oversample == camera.grid_oversample(p, design["f_number"], 550.0)


@pytest.mark.parametrize("angle, motion_angle, shape", [
    (85.0, 5.0, (96, 48)),     # the motion along the edge: its normal sees none of it
    (-80.0, -10.0, (96, 48)),  # the same, the other way
    (85.0, 0.0, (96, 48)),     # the motion along the rows: the normal sees cos(85 deg) of it
    (5.0, 30.0, (48, 96)),     # a near-vertical edge, the motion 30 deg off the rows
])
def test_an_edges_capture_is_the_exact_image_whichever_way_the_image_moves(angle, motion_angle,
                                                                           shape):
    # 9.5 pixels of motion at 100 lux, in the direction motion_angle_deg from the rows: the
    # edge's normal (cos a, -sin a) sees cos(a + motion angle) of it (helpers.edges), none
    # when the motion runs along the edge (motion angle 90 - a). Tolerance as above.
    chart = simulate.slanted_edge(shape, angle)
    c = simulate.capture(chart, illuminance_lux=100.0, seed=1, motion_angle_deg=motion_angle,
                         **DESIGN)
    rows, cols = chart.shape
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    a = math.radians(angle)
    p = DESIGN["pixel_pitch_um"]
    d = ((x - (cols - 1) / 2) * math.cos(a) - (y - (rows - 1) / 2) * math.sin(a)) * p * 1e-3
    motion = (c.exposure_s, DESIGN["focal_length_mm"], math.radians(4.39))
    esf = edge_spread(d, angle_deg=angle, f_number=DESIGN["f_number"], wavelength_nm=550.0,
                      pitch_um=p, motion=motion, motion_angle_deg=motion_angle)
    got = c.expected_e / per_reflectance(c, DESIGN)
    assert np.max(np.abs(got - (0.1 + 0.3 * esf))) < 3.3e-4 * 0.3
    assert c.blur_mm / (p * 1e-3) > 9.0  # the image moves 9.5 pixels


@pytest.mark.parametrize("value", [91.0, -90.5, math.nan, "5", None, True, [1.0, 2.0]])
def test_a_bad_motion_angle_is_refused_naming_it(value):
    with pytest.raises(ValueError, match="motion_angle_deg"):
        simulate.capture(simulate.slanted_edge(32), illuminance_lux=1000.0,
                         motion_angle_deg=value, **DESIGN)


def test_a_flat_patch_at_t_mpe_collects_the_electrons_the_target_needs():
    design = {**DESIGN, "read_noise_e": 2.0, "dark_current_e_per_s": 30.0, "prnu": 0.005}
    c = simulate.capture(simulate.flat(64), illuminance_lux=200.0, seed=3, **design)
    # A uniform patch passes the optics at f = 0 only: each pixel expects r T exactly.
    assert np.allclose(c.expected_e, float(c.result.electrons), rtol=1e-12)
    assert c.exposure_s == float(c.result.t_mpe_s)


def test_the_noise_has_the_models_mean_and_variance():
    design = {**DESIGN, "read_noise_e": 3.0, "dark_current_e_per_s": 200.0, "prnu": 0.01}
    c = simulate.capture(simulate.flat(256), illuminance_lux=500.0, seed=5, **design)
    s, t = float(c.result.electrons), c.exposure_s
    var = s + 200.0 * t + 9.0 + (0.01 * s) ** 2
    n = c.image_e.size
    # The sample mean within 5 standard errors; the sample variance within 5 of its own
    # (sqrt(2 / n) of the variance for a near-normal count).
    assert abs(c.image_e.mean() - s) < 5 * math.sqrt(var / n)
    assert abs(c.image_e.var(ddof=1) / var - 1) < 5 * math.sqrt(2 / n)
    target = 10 ** (float(design["snr_db"]) / 20)
    assert abs(s / math.sqrt(var) / target - 1) < 1e-9  # the model meets its target at T_MPE


def test_the_same_seed_gives_the_same_image_and_another_seed_another():
    chart = simulate.slanted_edge(32)
    a = simulate.capture(chart, illuminance_lux=1000.0, seed=11, **DESIGN)
    b = simulate.capture(chart, illuminance_lux=1000.0, seed=11, **DESIGN)
    c = simulate.capture(chart, illuminance_lux=1000.0, seed=12, **DESIGN)
    assert np.array_equal(a.image_e, b.image_e)
    assert not np.array_equal(a.image_e, c.image_e)
    assert np.array_equal(a.redraw(12).image_e, c.image_e)
    assert np.array_equal(a.expected_e, c.expected_e)


def test_the_full_well_clips_the_signal():
    design = {**DESIGN, "full_well_e": 1500.0, "dark_current_e_per_s": 10.0}
    c = simulate.capture(simulate.flat(32), illuminance_lux=1000.0, exposure_s=1.0,
                         seed=0, **design)
    assert c.image_e.max() <= 1500.0 - 10.0 * 1.0
    assert c.exposure_s == 1.0


def test_a_spectrums_image_is_its_wavelengths_images_weighted():
    chart = simulate.slanted_edge((32, 48))
    spectrum = epc_fast.Spectrum([480.0, 620.0], [0.25, 0.75])
    q = camera.grid_oversample(DESIGN["pixel_pitch_um"], DESIGN["f_number"], 480.0)
    both = simulate.capture(chart, illuminance_lux=1e4, spectrum=spectrum, oversample=q,
                            **DESIGN)
    parts = [simulate.capture(chart, illuminance_lux=1e4, wavelength_nm=w, oversample=q,
                              exposure_s=both.exposure_s, **DESIGN).expected_e
             for w in (480.0, 620.0)]
    # Electrons add over wavelengths; the combined profile is one interpolation of the
    # weighted profiles (1e-5 of the transfer, pupil.diffraction_transfer).
    assert np.allclose(both.expected_e, 0.25 * parts[0] + 0.75 * parts[1], rtol=2e-5)


def test_a_picture_keeps_its_shape_and_its_mean_light():
    rng = np.random.default_rng(0)
    values = rng.uniform(0.1, 0.8, (40, 60))
    c = simulate.capture(simulate.image(values), illuminance_lux=1000.0, seed=0, **DESIGN)
    assert c.image_e.shape == (40, 60) and c.image_e.dtype == np.float64
    assert c.pitch_um == DESIGN["pixel_pitch_um"]
    # The optics move light around but lose none: the mean over the interior holds (the
    # picture's border repeats beyond it, so the blur at the edges borrows from no one).
    inner = (slice(8, -8), slice(8, -8))
    ratio = c.expected_e[inner].mean() / (values[inner].mean() * per_reflectance(c, DESIGN))
    assert abs(ratio - 1) < 0.02


@pytest.mark.parametrize("kwargs, error, match", [
    ({"chart": np.ones((8, 8))}, TypeError, "chart"),
    ({"outputs": "epc"}, TypeError, "outputs"),
    ({"not_a_keyword": 1}, TypeError, "not_a_keyword"),
    ({"illuminance_lux": [1.0, 2.0]}, ValueError, "illuminance_lux"),
    ({"f_number": [2.0, 2.8]}, ValueError, "capture simulates one design"),
    ({"pixel_pitch_um": -1.0}, ValueError, "pixel_pitch_um"),
    ({"prnu": 0.05}, ValueError, "cannot reach its SNR target"),
    ({"illuminance_lux": 0.05}, ValueError, "90 degrees"),
    ({"exposure_s": -1.0}, ValueError, "exposure_s"),
    ({"exposure_s": math.nan}, ValueError, "exposure_s"),
    ({"exposure_s": 1e4}, ValueError, "90 degrees"),
    ({"oversample": 4}, ValueError, "oversample"),
    ({"oversample": 1}, ValueError, "oversample"),
    ({"oversample": 5.0}, ValueError, "oversample"),
    ({"seed": -1}, ValueError, r"^seed: .*got -1$"),
    ({"seed": 2.5}, ValueError, r"^seed: .*got 2.5$"),
    ({"illuminance_lux": "100"}, TypeError, r"^illuminance_lux .*got '100'$"),
    ({"frames": 1_000_000}, ValueError, r"^frames: .*got 1,000,000"),
])
def test_bad_input_is_refused_by_name(kwargs, error, match):
    call = {"chart": simulate.flat(8), "illuminance_lux": 100.0, **DESIGN, **kwargs}
    with pytest.raises(error, match=match):
        simulate.capture(call.pop("chart"), **call)


def test_a_grid_beyond_the_memory_is_refused_before_it_is_made(monkeypatch):
    from epc_fast import _limits

    monkeypatch.setattr(_limits, "memory_limit_bytes", lambda: 2**20)
    with pytest.raises(MemoryError, match="smaller chart"):
        simulate.capture(simulate.flat(256), illuminance_lux=100.0, **DESIGN)


@pytest.mark.parametrize("pitch, f_number, wavelength, q", [
    (2.8, 2.8, 550.0, 5), (1.4, 2.8, 550.0, 3), (0.5, 2.8, 550.0, 1), (1.0, 2.0, 400.0, 3)])
def test_the_grid_is_the_least_odd_one_that_carries_the_image(pitch, f_number, wavelength, q):
    got = camera.grid_oversample(pitch, f_number, wavelength)
    assert got == q and got % 2 == 1
    assert got / pitch >= camera.BAND_FACTOR / (wavelength * 1e-3 * f_number)
    assert got == 1 or (got - 2) / pitch < camera.BAND_FACTOR / (wavelength * 1e-3 * f_number)


@pytest.mark.parametrize("k", [2, 3])
def test_a_binned_edge_is_the_sum_of_its_sensor_pixels_exact_images(k):
    design = {**DESIGN, "pixel_pitch_um": 1.4, "binning": k}
    chart = simulate.slanted_edge((24, 40), 5.0)
    c = simulate.capture(chart, illuminance_lux=1e5, seed=1, **design)
    assert c.image_e.shape == chart.shape and c.pitch_um == pytest.approx(1.4 * k)
    rows, cols = chart.shape
    # Sensor pixel (i, j) sits at output-pixel coordinates ((i - (k-1)/2) / k, ...).
    ys, xs = np.mgrid[0:rows * k, 0:cols * k].astype(float)
    y, x = (ys - (k - 1) / 2) / k, (xs - (k - 1) / 2) / k
    a = math.radians(5.0)
    d = ((x - (cols - 1) / 2) * math.cos(a) - (y - (rows - 1) / 2) * math.sin(a)) * 1.4e-3 * k
    esf = edge_spread(d, angle_deg=5.0, f_number=design["f_number"], wavelength_nm=550.0,
                      pitch_um=1.4)
    want = (0.1 + 0.3 * esf).reshape(rows, k, cols, k).sum(axis=(1, 3))
    got = c.expected_e / per_reflectance(c, design) * k * k
    # As for one pixel, k^2 times (the sum of k^2 sensor pixels' images).
    assert np.max(np.abs(got - want)) < k * k * 3.3e-4 * 0.3


#: The 200 MP sensor of docs/beyond.md, read 1x1, 2x2 or 4x4 (charge), and its modes.
SENSOR_200MP = dict(pixel_pitch_um=0.56, sensor_width_mm=9.14, sensor_height_mm=6.85,
                    f_number=1.7, focal_length_mm=6.3, snr_at="corner", read_noise_e=1.5,
                    dark_current_e_per_s=5.0, full_well_e=6000.0)
MODES = [{"binning": 1}, {"binning": 2}, {"binning": 4, "binning_readout": "charge"}]


@pytest.mark.parametrize("lux, picked", [(1000.0, 2), (30_000.0, 1)])
def test_a_capture_with_modes_is_the_picked_modes_capture_and_meets_the_target(lux, picked):
    chart = simulate.flat(96)
    c = simulate.capture(chart, illuminance_lux=lux, seed=4, modes=MODES, **SENSOR_200MP)
    assert c.result.mode == picked
    mode = MODES[picked]
    alone = simulate.capture(chart, illuminance_lux=lux, seed=4, **mode, **SENSOR_200MP)
    assert c.pitch_um == pytest.approx(0.56 * mode["binning"])
    assert c.exposure_s == alone.exposure_s == float(alone.result.t_mpe_s)
    np.testing.assert_array_equal(c.image_e, alone.image_e)
    # the SNR of 96 x 96 pixels scatters by 20 log10(e) / sqrt(2 N) = 0.064 dB: 0.3 dB is
    # near 5 of that
    assert simulate.snr(c.image_e).snr_db >= 30.0 - 0.3


def test_frames_whose_images_exceed_the_memory_are_refused_by_name(monkeypatch):
    from epc_fast import _limits

    monkeypatch.setattr(_limits, "memory_limit_bytes", lambda: 2**20)
    with pytest.raises(MemoryError, match=r"^frames: 200 frames of a 32 x 32 chart hold"):
        simulate.capture(simulate.flat(32), illuminance_lux=1000.0, frames=200, **DESIGN)


def test_night_mode_captures_the_frames_evaluate_takes_each_within_the_cap():
    night = dict(frames="auto", max_frames=16, max_exposure_s=0.1, read_noise_e=2.0)
    taken = epc_fast.evaluate(10.0, **DESIGN, **night)
    n = taken.frames_used
    assert taken.status == epc_fast.Status.OK and 1 < n < 16
    burst = simulate.capture(simulate.flat(16), illuminance_lux=10.0, seed=3, **DESIGN, **night)
    same = simulate.capture(simulate.flat(16), illuminance_lux=10.0, seed=3, **DESIGN,
                            read_noise_e=2.0, frames=n)
    assert len(burst.frames_e) == n and burst.exposure_s / n <= 0.1  # each frame within it
    np.testing.assert_array_equal(burst.image_e, same.image_e)  # the burst of n frames itself
    # a camera picking its mode captures in the mode and the frames it takes
    modes = [{}, {"binning": 2, "frames": "auto", "max_frames": 16}]
    picked = simulate.capture(simulate.flat(16), illuminance_lux=10.0, seed=3, **DESIGN,
                              read_noise_e=2.0, max_exposure_s=0.1, modes=modes)
    expected = epc_fast.evaluate(10.0, **DESIGN, read_noise_e=2.0, max_exposure_s=0.1,
                                 modes=modes)
    assert expected.mode == 1 and picked.exposure_s == pytest.approx(expected.t_mpe_s)


def test_a_design_over_its_frame_cap_has_no_image_to_capture():
    with pytest.raises(ValueError, match=r"^max_exposure_s: every frame the design can take is "
                                         r"longer than max_exposure_s = 0.001 s"):
        simulate.capture(simulate.flat(16), illuminance_lux=10.0, seed=1, **DESIGN,
                         max_exposure_s=0.001)
