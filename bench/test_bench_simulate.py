"""The capture simulator's speed (epc_fast.simulate): one 1,024 x 1,024 capture of a picture
with every term on, on 2 threads, and a slanted-edge capture with its e-SFR, the unit of the
agreement with the model:

    python -m pytest bench/test_bench_simulate.py --benchmark-only

The FFT's grid holds p/q per sample, q the least odd number that carries the image without
loss (simulate.camera.grid_oversample): 3 at the 1.0 um pitch below (a 3,400 x 3,400 grid with
its margins). ``EPC_FAST_BENCH_QUICK=1`` shrinks the picture to 256 x 256.
"""

import numpy as np
import pytest

from engine_suite import QUICK
from epc_fast import simulate, spectra

SIZE = 256 if QUICK else 1024
#: Every term of the model on: a 1.0 um pixel with 80% fill factor, read noise, dark current,
#: PRNU, a full well, jitter, motion, the SNR met 20 degrees off the axis, 16 wavelengths.
EVERY_TERM = dict(pixel_pitch_um=1.0, f_number=2.0, focal_length_mm=4.0, pixel_count=12e6,
                  read_noise_e=2.0, dark_current_e_per_s=50.0, prnu=0.01, full_well_e=6000.0,
                  jitter_um=0.5, fill_factor=0.8, field_angle_deg=20.0, threads=2)


@pytest.fixture(scope="module")
def picture():
    rng = np.random.default_rng(0)
    return simulate.image(rng.uniform(0.05, 0.9, (SIZE, SIZE)))


@pytest.mark.benchmark(group=f"simulate {SIZE}x{SIZE}, 2 threads")
@pytest.mark.parametrize("spectrum", [None, 16], ids=["one wavelength", "16 wavelengths"])
def test_capture_every_term(benchmark, picture, spectrum):
    design = dict(EVERY_TERM)
    if spectrum:
        design["spectrum"] = spectra.diffraction_spectrum(spectrum)
    simulate.capture(picture, illuminance_lux=100.0, seed=0, **design)  # the OTF's profile
    c = benchmark.pedantic(simulate.capture, args=(picture,),
                           kwargs=dict(illuminance_lux=100.0, seed=0, **design), rounds=5,
                           iterations=1, warmup_rounds=0)
    assert c.image_e.shape == (SIZE, SIZE) and np.isfinite(c.image_e).all()
    # At T_MPE a pixel of the target's reflectance collects the electrons the target needs.
    assert 0.5 * c.result.electrons < np.mean(c.expected_e) < 2 * c.result.electrons


@pytest.mark.benchmark(group=f"simulate {SIZE}x{SIZE}, 2 threads")
def test_edge_capture_and_its_esfr(benchmark):
    chart = simulate.slanted_edge((384, 162))
    design = dict(EVERY_TERM)

    def measure():
        c = simulate.capture(chart, illuminance_lux=1000.0, seed=0, **design)
        return c, simulate.esfr(c.image_e, c.pitch_um).mtf50_cyc_per_mm

    c, mtf50 = benchmark.pedantic(measure, rounds=5, iterations=1, warmup_rounds=1)
    model = float(c.result.f50_cyc_per_mm)
    assert abs(mtf50 / model - 1) < 0.1  # one noisy capture: its scatter is a few percent
