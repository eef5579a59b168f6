"""Issue #40's wavefront error and denoising in scans, Sobol' indices, the optimiser and the
inverse solvers: drawn per point like any parameter, the same numbers as evaluate on the same
draws, and an optimum the curve of evaluate confirms."""

import numpy as np
import pytest

import epc_fast
from epc_fast import optimize, scan
from epc_fast.inverse import InverseStatus, crossover_lux, lux_for_epc
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import Grid, LogUniform, Summary, Uniform, run
from epc_fast.scan.sampling.space import BLOCK_POINTS

N = BLOCK_POINTS + 333  # a second, partial block
#: A 1/3.2" 1.12 um phone camera whose read noise makes denoising pay at low light.
PHONE = dict(pixel_pitch_um=1.12, f_number=2.0, focal_length_mm=3.82, sensor_width_mm=4.57,
             sensor_height_mm=3.43, read_noise_e=2.0)


def test_the_optics_terms_scan_as_evaluate_gives_them_on_the_same_draws():
    space = scan.Space(design=HIGH_TIER, illuminance_lux=LogUniform(1, 1e5),
                       wavefront_rms_waves=Uniform(0.0, 0.16), denoise_sigma_px=Grid([0, 0.8, 2.5]),
                       read_noise_e=2.0)
    result = run(space, N, seed=40, reductions={"s": Summary(by="design")}, progress=False)
    points = space.points(40, 0, N)
    expected = epc_fast.evaluate(**points.parameters)
    design = points.indices["design"]
    ok = np.isfinite(expected.epc)
    means = [expected.epc[ok & (design == d)].mean() for d in range(4)]
    # the scan's chunks and evaluate's call are the same kernel on the same draws; the sums'
    # order differs (a streamed mean against NumPy's), ~1e-15
    np.testing.assert_allclose(result["s"].mean, means, rtol=1e-12)
    plain = epc_fast.evaluate(**{**points.parameters, "wavefront_rms_waves": 0.0,
                                 "denoise_sigma_px": 0.0})
    assert not np.allclose(plain.epc[ok], expected.epc[ok])


def test_each_optics_term_has_sobol_indices_of_its_own():
    # daylight, where the lens and the filter rather than the shake set f50
    space = scan.Space(design=[epc_fast.presets.Design("phone", **PHONE)],
                       illuminance_lux=LogUniform(1e3, 1e5), wavefront_rms_waves=Uniform(0.0, 0.16),
                       denoise_sigma_px=Uniform(0.0, 1.5))
    result = scan.sobol_indices(space, points=2**8, seed=3, of="log_epc")
    for name in ("wavefront_rms_waves", "denoise_sigma_px"):
        column = result.parameters.index(name)
        assert result.st[0, 0, column] > 0.01, (name, result.st[0, 0])


def test_the_optimiser_finds_the_denoising_that_evaluate_says_is_best():
    design = epc_fast.presets.Design("phone", **PHONE)
    space = scan.Space(design=[design], illuminance_lux=30.0, shake_deg_per_s=4.39)
    problem = optimize.Problem(space, {"denoise_sigma_px": (0.0, 4.0)}, points=1_000, seed=1)
    best = problem.maximize(batches=0).x["denoise_sigma_px"]
    # one scene: the mean is evaluate's EPC; on a fine grid its maximum lies within a step
    sigmas = np.linspace(0.0, 4.0, 801)
    curve = epc_fast.evaluate(30.0, **PHONE, shake_deg_per_s=4.39, snr_at="corner",
                              denoise_sigma_px=sigmas).epc
    at_best = epc_fast.evaluate(30.0, **PHONE, shake_deg_per_s=4.39, snr_at="corner",
                                denoise_sigma_px=best).epc
    assert 0.5 < best < 4.0
    # within 0.1% of the grid's best (the optimiser's xtol on a curve that is flat at its top)
    assert at_best >= 0.999 * curve.max()


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_lux_for_epc_round_trips_with_the_optics_terms(backend):
    design = {**PHONE, "wavefront_rms_waves": np.array([0.0, 0.07, 0.12]),
              "denoise_sigma_px": np.array([0.6, 0.0, 1.2])}
    lux = np.array([30.0, 300.0, 3000.0])
    targets = epc_fast.evaluate(lux, **design).epc
    r = lux_for_epc(design, targets, backend=backend)
    # the inverse solves to rtol 1e-13 in lux; EPC's slope in lux is of order 1
    np.testing.assert_allclose(r.illuminance_lux, lux, rtol=1e-10)
    assert np.all(r.status == InverseStatus.OK)


def test_a_denoised_camera_overtakes_an_unfiltered_one_below_a_crossover():
    # denoising buys exposure at low light and costs resolution at high light: one crossover
    unfiltered, denoised = dict(PHONE), {**PHONE, "denoise_sigma_px": 1.5}
    r = crossover_lux(unfiltered, denoised)
    lux = float(np.asarray(r.illuminance_lux))
    assert 1.0 < lux < 1e5
    below = epc_fast.evaluate(lux / 2, **denoised).epc > epc_fast.evaluate(lux / 2, **unfiltered).epc
    above = epc_fast.evaluate(lux * 2, **denoised).epc < epc_fast.evaluate(lux * 2, **unfiltered).epc
    assert below and above


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_a_color_sensor_scans_as_evaluate_gives_it_on_the_same_draws(backend):
    space = scan.Space(design=HIGH_TIER, illuminance_lux=LogUniform(1, 1e5), read_noise_e=2.0,
                       cfa_transmittance=Uniform(0.25, 0.45),
                       evaluate_options={"cfa": "bayer", "demosaic": "bilinear"})
    n = BLOCK_POINTS + 11
    result = run(space, n, seed=41, reductions={"s": Summary(by="design")}, progress=False,
                 backend=backend)
    points = space.points(41, 0, n)
    expected = epc_fast.evaluate(**points.parameters, cfa="bayer", demosaic="bilinear",
                                 backend=backend)
    design = points.indices["design"]
    ok = np.isfinite(expected.epc)
    means = [expected.epc[ok & (design == d)].mean() for d in range(4)]
    np.testing.assert_allclose(result["s"].mean, means, rtol=1e-12)
    # against the monochrome sensor without filters: t / (g_c g_d) < 1 of its light's worth
    mono = epc_fast.evaluate(**{k: v for k, v in points.parameters.items()
                                if k != "cfa_transmittance"})
    both = (expected.status == 0) & (mono.status == 0)  # (in the dark both blur past all)
    assert np.all(expected.epc[both] < mono.epc[both])


def test_a_scan_config_takes_the_color_sensor(tmp_path):
    from epc_fast.scan.config import load_config

    path = tmp_path / "bayer.toml"
    path.write_text('[scan]\npoints = 1000\nseed = 1\n[design]\npresets = ["HIGH_TIER"]\n'
                    '[parameters]\nilluminance_lux = 100.0\n'
                    '[evaluate]\ncfa = "bayer"\ndemosaic = "menon2007"\n')
    config = load_config(path)
    assert config.space.evaluate_options["cfa"] == "bayer"
    assert config.space.evaluate_options["demosaic"] == "menon2007"
    path.write_text(path.read_text().replace('"menon2007"', '"ahd"'))
    with pytest.raises(Exception, match="demosaic"):
        load_config(path)


def test_sobol_and_the_optimiser_take_lens_tables_and_a_color_sensor():
    from epc_fast.reference import mtf_diffraction

    f = np.linspace(0.0, 1.0 / (550e-6 * 2.0), 20)
    soft = (f, np.minimum.accumulate(mtf_diffraction(f, 550.0, 2.0) * np.exp(-(f / 600.0) ** 2)))
    options = {"lens_mtf": soft, "cfa": "bayer", "demosaic": "malvar2004"}
    design = epc_fast.presets.Design("phone", **PHONE)
    space = scan.Space(design=[design], illuminance_lux=LogUniform(1e3, 1e5),
                       cfa_transmittance=Uniform(0.25, 0.45), evaluate_options=options)
    result = scan.sobol_indices(space, points=2**7, seed=3, of="log_epc")
    column = result.parameters.index("cfa_transmittance")
    assert result.st[0, 0, column] > 0.001
    fixed = scan.Space(design=[design], illuminance_lux=30.0, shake_deg_per_s=4.39,
                       evaluate_options=options)
    problem = optimize.Problem(fixed, {"denoise_sigma_px": (0.0, 4.0)}, points=100, seed=1)
    best = problem.maximize(batches=0).x["denoise_sigma_px"]
    at_best = epc_fast.evaluate(30.0, **PHONE, shake_deg_per_s=4.39, snr_at="corner",
                                denoise_sigma_px=best, **options).epc
    grid = epc_fast.evaluate(30.0, **PHONE, shake_deg_per_s=4.39, snr_at="corner",
                             denoise_sigma_px=np.linspace(0.0, 4.0, 401), **options).epc
    assert at_best >= 0.999 * grid.max()
