"""The inverse solvers lux_for_epc and crossover_lux: known answers, conventions, core vs reference.

Known answers come from two constructed designs whose EPC has a closed form:

- PURE_MOTION: pixel and wavelength so small that only the motion blur is left (the pixel and
  diffraction factors differ from 1 by < 1e-14 at its f50; K is raised so that the light needed
  stays within 1e3..1e7 lux), shot-noise limited. Then f50 = X0 / b with sinc(X0) = 1/2,
  b = f tan(omega T), T = s / r, and EPC = 4 S f50^2, ~ L^2 at small shake angles: the
  illuminance for a target EPC is a closed form.
- PIXEL_ONLY: no shake and no diffraction: f50 = X0 / p at every illuminance, a constant EPC."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

import epc_fast
from epc_fast import reference
from epc_fast.inverse import InverseResult, InverseStatus, crossover_lux, lux_for_epc
from epc_fast.presets import HIGH_TIER
from epc_fast.selfcheck import random_designs

BACKENDS = ("core", "reference")
# Known answers: both backends resolve ln L to ~1e-13 (core: Brent, rtol 1e-13) or to adjacent
# floats (reference), and the model's rounding moves EPC by ~1e-15; 1e-10 is the accuracy the
# inverse solvers are held to.
RTOL = 1e-10

#: 1, the root of sinc(x) = 1/2: f50 of a lone sinc factor of width w is X0 / w.
X0 = float(mp.findroot(lambda x: mp.sin(mp.pi * x) / (mp.pi * x) - 0.5, 0.6))
SNR_ELECTRONS = 1000.0  # 30 dB, shot-noise limited
PURE_MOTION = dict(pixel_pitch_um=1e-8, electrons_per_lux_s_m2=5e29,
                   wavelength_nm=1e-12, f_number=2.8, focal_length_mm=5.6, sensor_area_mm2=15.0,
                   shake_deg_per_s=4.39)
PIXEL_ONLY = dict(pixel_pitch_um=1.4, wavelength_nm=1e-12, f_number=2.8, focal_length_mm=5.6,
                  sensor_area_mm2=15.0, shake_deg_per_s=0.0)
PRESET_1_4 = HIGH_TIER[3].evaluate_kwargs()


def electron_rate_per_lux(design):
    """e-/(s lux): the pixel's electron rate at 1 lux, from the reference formula."""
    return reference.electron_rate(1.0, 0.4, 1.0, 0.0, design["f_number"],
                                   design.get("electrons_per_lux_s_m2",
                                              epc_fast.DEFAULT_ELECTRONS_PER_LUX_S_M2),
                                   1.0, design["pixel_pitch_um"])


def pure_motion_lux_for(target_epc):
    """lux: where PURE_MOTION reaches ``target_epc``, inverting EPC = 4 S (X0 / b)^2 by hand."""
    blur_mm = X0 * np.sqrt(4.0 * PURE_MOTION["sensor_area_mm2"] / target_epc)
    t_mpe_s = (np.arctan(blur_mm / PURE_MOTION["focal_length_mm"])
               / np.deg2rad(PURE_MOTION["shake_deg_per_s"]))
    return SNR_ELECTRONS / (electron_rate_per_lux(PURE_MOTION) * t_mpe_s)


def pixel_only_jumping_at(jump_lux):
    """PIXEL_ONLY with dark current D and a full well W = 2 s: the target is unreachable (EPC 0)
    while (1 + D/r) s > W, i.e. below ``jump_lux`` where r = D; above, the constant EPC."""
    return {**PIXEL_ONLY, "dark_current_e_per_s": electron_rate_per_lux(PIXEL_ONLY) * jump_lux,
            "full_well_e": 2.0 * SNR_ELECTRONS}


def pixel_only_epc():
    """pixels: PIXEL_ONLY's EPC at every illuminance, 4 S (X0 / p)^2."""
    return 4.0 * PIXEL_ONLY["sensor_area_mm2"] * (X0 / (PIXEL_ONLY["pixel_pitch_um"] * 1e-3)) ** 2


# --- lux_for_epc: known answers -----------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_lux_for_epc_inverts_the_pure_motion_closed_form(backend):
    targets = np.logspace(3, 8, 11)
    r = lux_for_epc(PURE_MOTION, targets, backend=backend)
    assert (r.status == InverseStatus.OK).all()
    np.testing.assert_allclose(r.illuminance_lux, pure_motion_lux_for(targets), rtol=RTOL)
    np.testing.assert_allclose(r.epc, targets, rtol=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_in_the_motion_limit_four_times_the_epc_needs_twice_the_light(backend):
    r = lux_for_epc(PURE_MOTION, [1e6, 4e6], backend=backend)
    # EPC ~ L^2 up to tan(x) ~ x: the shake angle here is b / f < 1e-3, so the ratio is 2 to
    # within x^2 < 1e-6.
    assert r.illuminance_lux[1] / r.illuminance_lux[0] == pytest.approx(2.0, rel=1e-6)


@pytest.mark.parametrize("backend", BACKENDS)
def test_lux_for_epc_round_trips_the_forward_model(backend):
    lux = np.array([150.0, 700.0, 3000.0, 12000.0])
    targets = epc_fast.evaluate(lux, **PRESET_1_4).epc
    r = lux_for_epc(PRESET_1_4, targets, backend=backend)
    # EPC rises steeply here (d ln EPC / d ln L > 0.1), so 1e-10 on L is well conditioned.
    np.testing.assert_allclose(r.illuminance_lux, lux, rtol=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_half_the_reflectance_needs_twice_the_light(backend):
    targets = np.array([1e5, 1e6, 2.5e6])
    plain = lux_for_epc(PRESET_1_4, targets, backend=backend)
    dimmer = lux_for_epc({**PRESET_1_4, "reflectance": 0.2}, targets, backend=backend)
    np.testing.assert_allclose(dimmer.illuminance_lux, 2.0 * plain.illuminance_lux, rtol=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_stabilisation_by_k_needs_k_times_less_light(backend):
    # Shot-noise limited, T ~ 1/L and the shake angle is omega T / k: IS by k is exactly k x light.
    targets = np.array([1e4, 1e6, 2.5e6])
    plain = lux_for_epc(PRESET_1_4, targets, backend=backend)
    stabilised = lux_for_epc({**PRESET_1_4, "stabilization": 4.0}, targets, backend=backend)
    np.testing.assert_allclose(stabilised.illuminance_lux, plain.illuminance_lux / 4.0, rtol=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_larger_sensor_reaches_a_proportionally_larger_target_at_the_same_light(backend):
    plain = lux_for_epc(PRESET_1_4, 1e6, backend=backend)
    larger = lux_for_epc({**PRESET_1_4, "sensor_area_mm2": 3.0 * PRESET_1_4["sensor_area_mm2"]},
                         3e6, backend=backend)
    assert larger.illuminance_lux == pytest.approx(plain.illuminance_lux, rel=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_unreachable_snr_counts_as_no_image(backend):
    # Any target under the constant is first reached at the jump (where the EPC returned may
    # sit on either side).
    r = lux_for_epc(pixel_only_jumping_at(1.0), [1e3, 0.5 * pixel_only_epc()], backend=backend)
    np.testing.assert_allclose(r.illuminance_lux, 1.0, rtol=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_lux_for_epc_has_no_solution_when_the_range_misses_the_target(backend):
    epc_at_1000 = epc_fast.evaluate(1000.0, **PRESET_1_4).epc
    met_at_lo = lux_for_epc(PRESET_1_4, epc_at_1000, lux_range=(1100.0, 1e5), backend=backend)
    not_yet_at_hi = lux_for_epc(PRESET_1_4, epc_at_1000, lux_range=(10.0, 900.0),
                                backend=backend)
    never = lux_for_epc(PRESET_1_4, 1e9, backend=backend)  # above the 2.9 Mpixel asymptote
    for r in (met_at_lo, not_yet_at_hi, never):
        assert r.status is InverseStatus.NO_SOLUTION
        assert math.isnan(r.illuminance_lux) and math.isnan(r.epc)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("target", [0.0, -1.0, math.nan, math.inf])
def test_a_target_that_is_not_finite_and_positive_is_invalid(backend, target):
    r = lux_for_epc(PRESET_1_4, target, backend=backend)
    assert r.status is InverseStatus.INVALID
    assert math.isnan(r.illuminance_lux) and math.isnan(r.epc)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_design_input_outside_its_domain_is_invalid_for_its_point_only(backend):
    r = lux_for_epc({**PRESET_1_4, "pixel_pitch_um": [1.4, -1.4, math.nan]}, 1e6,
                    backend=backend)
    assert list(r.status) == [InverseStatus.OK, InverseStatus.INVALID, InverseStatus.INVALID]


# --- crossover_lux: known answers ---------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_rising_curve_crosses_a_constant_where_the_closed_form_says(backend):
    r = crossover_lux(PURE_MOTION, PIXEL_ONLY, backend=backend)
    assert r.status is InverseStatus.OK
    assert r.illuminance_lux == pytest.approx(pure_motion_lux_for(pixel_only_epc()), rel=RTOL)
    assert r.epc == pytest.approx(pixel_only_epc(), rel=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_crossing_does_not_depend_on_the_order_of_the_designs(backend):
    ab = crossover_lux(HIGH_TIER[3].evaluate_kwargs(), HIGH_TIER[0].evaluate_kwargs(),
                       backend=backend)
    ba = crossover_lux(HIGH_TIER[0].evaluate_kwargs(), HIGH_TIER[3].evaluate_kwargs(),
                       backend=backend)
    assert ab.illuminance_lux == pytest.approx(ba.illuminance_lux, rel=RTOL)
    # The EPC is the first design's; at the crossing the two are equal.
    assert ab.epc == pytest.approx(ba.epc, rel=1e-9)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_highest_of_two_crossings_is_found_and_the_range_selects_the_lower(backend):
    # PURE_MOTION (EPC > 0 from 77 lux, where its shake angle falls below pi/2) is above the
    # jumping design below 1000 lux, below it up to the smooth crossing, above it beyond.
    jumping = pixel_only_jumping_at(1000.0)
    highest = crossover_lux(PURE_MOTION, jumping, backend=backend)
    assert highest.illuminance_lux == pytest.approx(pure_motion_lux_for(pixel_only_epc()),
                                                    rel=RTOL)
    lower = crossover_lux(PURE_MOTION, jumping, lux_range=(100.0, 1e4), backend=backend)
    assert lower.illuminance_lux == pytest.approx(1000.0, rel=RTOL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_designs_that_never_cross_have_no_solution(backend):
    doubled = {**PRESET_1_4, "sensor_area_mm2": 2.0 * PRESET_1_4["sensor_area_mm2"]}
    r = crossover_lux(PRESET_1_4, doubled, backend=backend)
    assert r.status is InverseStatus.NO_SOLUTION
    itself = crossover_lux(PRESET_1_4, PRESET_1_4, backend=backend)
    assert itself.status is InverseStatus.NO_SOLUTION and math.isnan(itself.illuminance_lux)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_crossover_with_an_invalid_design_is_invalid(backend):
    r = crossover_lux(PRESET_1_4, {**HIGH_TIER[0].evaluate_kwargs(), "f_number": [2.8, 0.0]},
                      backend=backend)
    assert list(r.status) == [InverseStatus.OK, InverseStatus.INVALID]


# --- Shapes and arguments -----------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_designs_and_targets_broadcast(backend):
    pitch = np.array([1.4, 1.75, 2.2])[:, None]
    targets = np.array([3e5, 1e6])
    r = lux_for_epc({**PRESET_1_4, "pixel_pitch_um": pitch}, targets, backend=backend)
    assert r.illuminance_lux.shape == r.epc.shape == r.status.shape == (3, 2)
    one = lux_for_epc({**PRESET_1_4, "pixel_pitch_um": 1.75}, 1e6, backend=backend)
    assert r.illuminance_lux[1, 1] == one.illuminance_lux


def test_scalar_input_gives_scalars():
    r = lux_for_epc(PRESET_1_4, 1e6, backend="reference")
    assert isinstance(r, InverseResult)
    assert isinstance(r.illuminance_lux, float) and isinstance(r.epc, float)
    assert r.status is InverseStatus.OK


@pytest.mark.parametrize("lux_range", [(0.0, 10.0), (10.0, 10.0), (100.0, 10.0),
                                       (1.0, math.inf), (math.nan, 1.0)])
def test_a_bad_lux_range_is_a_value_error(lux_range):
    with pytest.raises(ValueError, match="lux_range"):
        lux_for_epc(PRESET_1_4, 1e6, lux_range=lux_range, backend="reference")


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="grid_points"):
        crossover_lux(PRESET_1_4, PRESET_1_4, grid_points=1, backend="reference")
    with pytest.raises(TypeError, match="illuminance_lux"):
        lux_for_epc({**PRESET_1_4, "illuminance_lux": 10.0}, 1e6, backend="reference")
    with pytest.raises(TypeError, match="f_number"):
        lux_for_epc({"pixel_pitch_um": 1.4, "focal_length_mm": 5.6, "pixel_count": 1e6}, 1e6)
    with pytest.raises(ValueError, match="backend"):
        lux_for_epc(PRESET_1_4, 1e6, backend="fast")
    with pytest.raises(ValueError, match="spectrum"):
        crossover_lux({**PRESET_1_4, "spectrum": ([500.0, 600.0], [1.0, 1.0])}, PRESET_1_4,
                      backend="reference")


def test_a_shared_spectrum_gives_the_same_crossing_on_both_backends():
    spectrum = ([500.0, 550.0, 600.0], [1.0, 2.0, 1.0])
    a = {**PRESET_1_4, "spectrum": spectrum}
    b = {**HIGH_TIER[0].evaluate_kwargs(), "spectrum": spectrum}
    core, ref = (crossover_lux(a, b, backend=backend) for backend in BACKENDS)
    assert core.illuminance_lux == pytest.approx(ref.illuminance_lux, rel=RTOL)


# --- The core against the reference on random designs -------------------------------------------


def _designs(n, seed):
    """``n`` random phone designs (selfcheck.random_designs) without their illuminance."""
    kwargs = random_designs(n, seed)
    del kwargs["illuminance_lux"]
    return kwargs


def _log_slope(f, lux):
    """|d f / d ln L| at ``lux``, by central differences."""
    h = 1e-4
    return np.abs(f(lux * math.exp(h)) - f(lux * math.exp(-h))) / (2.0 * h)


def _epc(design, lux):
    return epc_fast.evaluate(lux, **design, backend="reference").epc


def _assert_lux_agree(core, ref, slope):
    """Statuses equal; illuminances within RTOL plus the backends' EPC agreement (1e-12,
    selfcheck's bound) times the root's condition number EPC / |d g / d ln L| (``slope``)."""
    np.testing.assert_array_equal(core.status, ref.status)
    ok = ref.status == InverseStatus.OK
    err = np.abs(core.illuminance_lux[ok] / ref.illuminance_lux[ok] - 1.0)
    tol = RTOL + 1e-12 * ref.epc[ok] / slope[ok]
    assert (err <= tol).all(), f"worst {err.max():.3g}, {np.count_nonzero(err > tol)} over"


def test_lux_for_epc_core_agrees_with_the_reference_on_random_designs():
    n = 2000
    design = _designs(n, seed=11)
    rng = np.random.default_rng(12)
    # Targets from the EPC at a random illuminance, times 0.5..2: most solvable, some not.
    targets = _epc(design, 10 ** rng.uniform(0, 5, n)) * rng.uniform(0.5, 2.0, n)
    core = lux_for_epc(design, targets, threads=2)
    ref = lux_for_epc(design, targets, backend="reference")
    ok = ref.status == InverseStatus.OK
    assert ok.sum() > n // 2
    lux = np.where(ok, ref.illuminance_lux, 1.0)
    slope = _log_slope(lambda x: _epc(design, x), lux)
    _assert_lux_agree(core, ref, slope)


def test_crossover_core_agrees_with_the_reference_on_random_pairs():
    n = 2000
    a, b = _designs(n, seed=21), _designs(n, seed=22)
    core = crossover_lux(a, b, threads=2)
    ref = crossover_lux(a, b, backend="reference")
    ok = ref.status == InverseStatus.OK
    assert ok.sum() > n // 10
    lux = np.where(ok, ref.illuminance_lux, 1.0)
    slope = _log_slope(lambda x: _epc(a, x) - _epc(b, x), lux)
    _assert_lux_agree(core, ref, slope)


DATA_SHEET = dict(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6, sensor_width_mm=4.57,
                  sensor_height_mm=3.43, snr_at="corner")
# the same design as evaluate's area and field angle: S = w h, atan(half-diagonal / f)
AS_AREA = dict(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
               sensor_area_mm2=4.57 * 3.43,
               field_angle_deg=math.degrees(math.atan(math.hypot(4.57, 3.43) / 2 / 5.6)))


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_a_design_from_its_data_sheet_solves_as_its_area_and_corner_angle(backend):
    sheet = lux_for_epc(DATA_SHEET, [5e5, 1e6, 2e6], backend=backend)
    area = lux_for_epc(AS_AREA, [5e5, 1e6, 2e6], backend=backend)
    # the same inputs up to the rounding of w h and of the angle: a few ulp, through a solve
    # to rtol 1e-13
    np.testing.assert_allclose(sheet.illuminance_lux, area.illuminance_lux, rtol=1e-12)
    assert (sheet.status == InverseStatus.OK).all()
    diagonal = dict(DATA_SHEET, sensor_width_mm=None, sensor_height_mm=None,
                    sensor_diagonal_mm=math.hypot(4.57, 3.43), aspect=4.57 / 3.43)
    np.testing.assert_allclose(lux_for_epc(diagonal, 1e6, backend=backend).illuminance_lux,
                               area.illuminance_lux[1], rtol=1e-12)
    a, b = dict(DATA_SHEET, pixel_pitch_um=2.8), DATA_SHEET
    np.testing.assert_allclose(
        crossover_lux(a, b, backend=backend).illuminance_lux,
        crossover_lux(dict(AS_AREA, pixel_pitch_um=2.8), AS_AREA, backend=backend).illuminance_lux,
        rtol=1e-12)


def test_a_design_gives_its_sensor_size_one_way():
    with pytest.raises(TypeError, match="sensor_area_mm2=3"):
        lux_for_epc(dict(DATA_SHEET, sensor_area_mm2=3.0), 1e6)
    with pytest.raises(TypeError, match="none of them"):
        lux_for_epc(dict(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6), 1e6)
    with pytest.raises(TypeError, match="snr_at or field_angle_deg"):
        lux_for_epc(dict(DATA_SHEET, field_angle_deg=10.0), 1e6)


# --- Binning, bursts and the readout (issue #39) ------------------------------------------------

#: The 1.4 um preset read 2x2-binned, as a burst of 4 frames with 0.2 um alignment residuals, and
#: a read noise that makes the readout matter.
BINNED = {**PRESET_1_4, "read_noise_e": 2.0, "binning": np.array([1.0, 2.0, 4.0]),
          "frames": np.array([1.0, 4.0, 8.0]), "alignment_error_um": 0.2}


@pytest.mark.parametrize("readout", ["digital", "charge"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_lux_for_epc_round_trips_binned_bursts(backend, readout):
    design = {**BINNED, "binning_readout": readout}
    lux = np.array([30.0, 300.0, 3000.0])
    targets = epc_fast.evaluate(lux, **design).epc
    r = lux_for_epc(design, targets, backend=backend)
    np.testing.assert_allclose(r.illuminance_lux, lux, rtol=RTOL)
    assert np.all(r.status == InverseStatus.OK)


def test_charge_binning_reaches_a_target_in_less_light_than_digital():
    digital = lux_for_epc({**BINNED, "binning_readout": "digital"}, 1e5).illuminance_lux
    charge = lux_for_epc({**BINNED, "binning_readout": "charge"}, 1e5).illuminance_lux
    assert charge[0] == digital[0]  # unbinned: one read either way
    assert np.all(charge[1:] < digital[1:])


@pytest.mark.parametrize("backend", BACKENDS)
def test_crossover_lux_of_full_resolution_and_a_binned_burst(backend):
    full = {**PRESET_1_4, "read_noise_e": 2.0}
    binned = {**full, "binning": 2.0, "frames": np.array([1.0, 4.0]),
              "binning_readout": "charge"}
    r = crossover_lux(full, binned, backend=backend)
    assert np.all(r.status == InverseStatus.OK)
    a = epc_fast.evaluate(r.illuminance_lux, **full).epc
    b = epc_fast.evaluate(r.illuminance_lux, **binned).epc
    np.testing.assert_allclose(a, b, rtol=1e-8)
    np.testing.assert_allclose(r.epc, a, rtol=1e-12)


def test_the_inverse_solvers_take_one_readout_a_design():
    design = {**PRESET_1_4, "modes": [{"binning": 1}, {"binning": 2}]}
    with pytest.raises(TypeError, match="modes: the inverse solvers take one readout"):
        lux_for_epc(design, 1e6)
    with pytest.raises(ValueError, match="binning_readout must be one of"):
        lux_for_epc({**PRESET_1_4, "binning_readout": "analog"}, 1e6)


@pytest.mark.parametrize("extra, match", [
    ({"max_exposure_s": 0.1}, "max_exposure_s: the inverse solvers take no frame cap"),
    ({"frames": "auto", "max_frames": 8}, "frames='auto' and max_frames: the inverse solvers"),
    ({"frames": "auto"}, "frames='auto' and max_frames"),
])
def test_the_inverse_solvers_refuse_a_frame_cap_and_night_mode_by_name(extra, match):
    with pytest.raises(TypeError, match=match):
        lux_for_epc({**PRESET_1_4, **extra}, 1e6)
    with pytest.raises(TypeError, match=match):
        crossover_lux({**PRESET_1_4, **extra}, PRESET_1_4)
