"""The f50 start fitted to a demosaicker (cpp/include/epc_fast/f50/demosaic_fit.h) against the
exact f50, which lanes take it, its determinism, and the solve it starts."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, _core, reference
from epc_fast.cfa import demosaic_mtf_table, remosaic_mtf_table
from epc_fast.core_call import core_tables
from epc_fast.reference.cfa import mtf_demosaic

THRESHOLDS = (0.5, 0.3, 0.2, 0.1)
TABLES = {"malvar2004": demosaic_mtf_table("malvar2004"),
          "bilinear": demosaic_mtf_table("bilinear"),
          "remosaic malvar2004": remosaic_mtf_table("malvar2004")}
#: The fitted start's largest relative error per table over every threshold on the points
#: below, measured 7.4e-3, 1.4e-3 and 6.2e-3: Malvar's table is 1 up to 0.25 cycles per pixel
#: and falls steeply after, a kink the polynomial smooths over. The start it replaces, which
#: knows no demosaicker, is off by up to 20% to 81% (50%, 81% and 53% at MTF50).
START_BOUND = {"malvar2004": 1e-2, "bilinear": 2e-3, "remosaic malvar2004": 1e-2}


def _triple(table):
    return core_tables((table,))[0]


def _exact(table, lambda_f, pitch_mm, blur_mm, threshold):
    """The reference's f50 (bisection to adjacent doubles): diffraction at lambda F (550 nm),
    the pixel (fill factor 1), the motion and the demosaicker at f p, from lengths."""
    f_number = lambda_f / 550e-6
    with np.errstate(divide="ignore"):
        f_hi = np.minimum(np.minimum(1.0 / lambda_f, 1.0 / pitch_mm), 1.0 / blur_mm)

    def mtf(f):
        return (reference.mtf_diffraction(f, 550.0, f_number)
                * reference.mtf_pixel(f, pitch_mm * 1e3, 1.0) * reference.mtf_motion(f, blur_mm)
                * mtf_demosaic(f, pitch_mm * 1e3, table))

    return reference.f50_bisection(mtf, f_hi, threshold)


@pytest.mark.parametrize("name", list(TABLES))
def test_the_demosaic_start_is_within_its_bound_and_far_better_than_the_start_it_replaces(name):
    triple = _triple(TABLES[name])
    rng = np.random.default_rng(5)
    n = 4_000
    # lengths whose ratios span e^-3 .. e^3: diffraction-, pixel- and motion-bound points and
    # every mix, 20% without motion
    lambda_f = 550e-6 * rng.uniform(1.0, 8.0, n)
    pitch = lambda_f * np.exp(rng.uniform(-3.0, 3.0, n))
    blur = lambda_f * np.exp(rng.uniform(-3.0, 3.0, n)) * (rng.random(n) < 0.8)
    for threshold in THRESHOLDS:
        exact = _exact(TABLES[name], lambda_f, pitch, blur, threshold)
        got = _core.testing.f50_pixel_start(triple, lambda_f, pitch, blur, np.full(n, threshold))
        error = np.max(np.abs(got / exact - 1))
        before = np.max(np.abs(_core.testing.f50_start(lambda_f, pitch, blur, 0.0, threshold)
                               / exact - 1))
        assert error <= START_BOUND[name] and error < 0.05 * before, (threshold, error, before)


def test_a_table_that_leaves_the_pixels_half_point_gets_no_start():
    # Menon's table is 1 up to the sinc's 1/2 point: the accurate start serves there
    assert _core.testing.pixel_start(_triple(demosaic_mtf_table("menon2007"))) is None
    fitted = _core.testing.pixel_start(_triple(TABLES["malvar2004"]))
    assert 0.3 < fitted["x50"] < 0.6033545644016142  # below the sinc's alone
    assert fitted["coefficients"].shape == (4, 66)


def test_the_fit_is_the_same_bits_every_time():
    first = _core.testing.pixel_start(_triple(TABLES["bilinear"]))["coefficients"]
    for name in ("malvar2004", "remosaic malvar2004"):
        _core.testing.pixel_start(_triple(TABLES[name]))
    again = _core.testing.pixel_start(_triple(TABLES["bilinear"]))["coefficients"]
    assert np.array_equal(first.view(np.uint64), again.view(np.uint64))


def _scene(n, seed, **more):
    rng = np.random.default_rng(seed)
    return dict(illuminance_lux=10 ** rng.uniform(0, 5, n), pixel_pitch_um=rng.uniform(0.6, 4, n),
                f_number=rng.uniform(1.4, 4.0, n), focal_length_mm=5.6, sensor_area_mm2=20.0,
                read_noise_e=1.5, shake_deg_per_s=rng.uniform(0, 8, n), **more)


def test_a_point_gets_the_same_bits_alone_and_among_lanes_that_take_other_starts():
    # full-resolution lanes take the fitted start; binned, partly filled or denoised ones keep
    # theirs: a lane's start (and result) depends on its own inputs only
    rng = np.random.default_rng(3)
    n = 3_000
    scene = _scene(n, 11, fill_factor=np.where(rng.random(n) < 0.3, 0.8, 1.0),
                   binning=np.where(rng.random(n) < 0.3, 2.0, 1.0),
                   denoise_sigma_px=np.where(rng.random(n) < 0.3, 1.0, 0.0))
    whole = epc_fast.evaluate(**scene, cfa="bayer", threads=2)
    for i in (0, 17, 1234, 2999):
        alone = epc_fast.evaluate(**{k: v[i:i + 1] if np.ndim(v) else v for k, v in scene.items()},
                                  cfa="bayer", threads=1)
        assert alone.f50_cyc_per_mm[0].tobytes() == whole.f50_cyc_per_mm[i].tobytes(), i


@pytest.mark.parametrize("f50_solver", ["halley", "newton"])
@pytest.mark.parametrize("cfa, demosaic", [("bayer", "malvar2004"), ("bayer", "bilinear"),
                                           ("quad_bayer", "malvar2004")])
@pytest.mark.parametrize("threshold", THRESHOLDS)
def test_the_solve_from_it_matches_the_reference(f50_solver, cfa, demosaic, threshold):
    scene = _scene(2_000, 12)
    options = dict(cfa=cfa, demosaic=demosaic, mtf_threshold=threshold)
    core = epc_fast.evaluate(**scene, **options, f50_solver=f50_solver)
    ref = epc_fast.evaluate(**scene, **options, backend="reference")
    assert np.array_equal(core.status, ref.status)
    ok = core.status == Status.OK
    assert ok.sum() > 500
    # f50_rtol 1e-14 times the MTF's condition number at f50: a demosaicker's flat table makes
    # it larger than diffraction's (tests/test_core_vs_reference.py states the bound)
    assert np.max(np.abs(core.f50_cyc_per_mm[ok] / ref.f50_cyc_per_mm[ok] - 1)) <= 1e-12
