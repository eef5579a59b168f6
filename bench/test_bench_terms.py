"""What each term of a scene costs, against the minimal scene (shot noise, no motion, one
wavelength), on the core at 10^5 points and 1 thread:

    python -m pytest bench/test_bench_terms.py --benchmark-only --benchmark-group-by=group

A term the scene does not use must cost nothing: the kernel compiles the motion and jitter
factors out of blocks that do not need them, takes binning and bursts only into blocks that
have them and never loops over a spectrum for one wavelength.

The wavefront error and the denoising filter enter only blocks that have them; a filter costs
its taps (2 ceil(4 sigma) + 1) at each MTF evaluation, a multiply-add each (its cosines by
rotation, its weights formed once a block). Lens tables and a colour sensor's demosaicker are
tables of the call, looked up in O(1) on a uniform grid, a block's lanes at once. EPC in both
directions solves f50 a second time in the same pass, without the motion; a frame cap is a
pass over the points in Python, night mode ceil(log2(max_frames)) passes of the exposure alone
(a bisection on the frame count) and then the picked frames'.

The second group, "the phone's terms", is the scene and the cases of docs/performance.md's
table ("What the real-camera terms cost", tools/keyword_costs.py): 10^6 points (10^5 under
EPC_FAST_BENCH_QUICK) of an f/2 phone in 1-100,000 lux, 2 threads, EPC alone, each term and
keyword on its own and a phone with them together. Each case records its ratio to the minimal
scene timed in the same test (extra_info "ratio_to_minimal", the median of 5 alternated
rounds), as ../shared/bench/phone_speed.py measures it.
"""

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest

import epc_fast
from epc_fast.spectra import diffraction_spectrum

N = 10**5


def _scene(n=N, **extra):
    rng = np.random.default_rng(2024)
    kwargs = {
        "illuminance_lux": 10 ** rng.uniform(1, 5, n),
        "pixel_pitch_um": rng.uniform(0.8, 3.0, n),
        "f_number": 2.8, "focal_length_mm": 5.6, "sensor_area_mm2": 15.7,
        "shake_deg_per_s": 0.0,
    }
    kwargs.update(extra)
    return kwargs


def _lens_table(points, f_number=2.8, wavelength_nm=550.0):
    """A lens table of the aberration-free MTF at ``points`` frequencies up to its cut-off."""
    from epc_fast.reference import mtf_diffraction

    f = np.linspace(0.0, 1.0 / (wavelength_nm * 1e-6 * f_number), points)
    m = mtf_diffraction(f, wavelength_nm, f_number)
    m[-1] = 0.0
    return f, m


SCENES = {
    "minimal": {},
    "read+dark+prnu": {"read_noise_e": 3.0, "dark_current_e_per_s": 50.0, "prnu": 0.005},
    "motion": {"shake_deg_per_s": 4.39},
    "jitter": {"jitter_um": 1.0},
    "MTF30": {"mtf_threshold": 0.3},  # a threshold with an accurate start (f50/guesses.h)
    "MTF25": {"mtf_threshold": 0.25},  # one without: the cubic start
    "fill factor": {"fill_factor": 0.6},
    "brent T_MPE": {"read_noise_e": 3.0, "t_mpe_solver": "brent"},
    "poly 1": {"spectrum": diffraction_spectrum(1)},
    "poly 4": {"spectrum": diffraction_spectrum(4)},
    "poly 16": {"spectrum": diffraction_spectrum(16)},
    "poly 64": {"spectrum": diffraction_spectrum(64)},
    # binning and bursts (docs/model.md): the exposure of the output pixel of the burst, the
    # binned pixel's aperture (sinc(k p f) at a fill factor of 1) and the alignment residual
    "binning 2": {"binning": 2.0},
    "binning 4 charge": {"binning": 4.0, "binning_readout": "charge", "read_noise_e": 3.0},
    "frames 8": {"frames": 8.0, "read_noise_e": 3.0},
    "frames 8 + alignment": {"frames": 8.0, "read_noise_e": 3.0, "alignment_error_um": 1.0},
    # the lens's wavefront error and denoising (docs/model.md, "System MTF")
    "wavefront 0.07": {"wavefront_rms_waves": 0.07},
    "wavefront 0.07 + poly 16": {"wavefront_rms_waves": 0.07, "spectrum": diffraction_spectrum(16)},
    "denoise 1.0": {"denoise_sigma_px": 1.0},
    "denoise 3.0": {"denoise_sigma_px": 3.0},
    # a lens's MTF table in place of diffraction, one of 20 points and two picked per point
    "lens table 20": {"lens_mtf": _lens_table(20)},
    "lens tables 2 x 20": {"lens_mtf": [_lens_table(20), _lens_table(20, 3.2)],
                           "lens": np.arange(N) % 2},
    # a colour sensor: its transmittance, noise gain and the demosaicker's table
    "bayer malvar2004": {"cfa": "bayer", "demosaic": "malvar2004"},
    "quad bayer full size": {"cfa": "quad_bayer", "demosaic": "malvar2004"},
    # EPC in both directions beside "motion": a second pass without the motion blur
    "motion, epc_axes both": {"shake_deg_per_s": 4.39, "epc_axes": "both"},
    # a frame cap and night mode: every candidate count's exposure, then the picked frames'
    "frame cap 10 s": {"max_exposure_s": 10.0},
    "night mode 16, cap 1 s": {"frames": "auto", "max_frames": 16, "max_exposure_s": 1.0,
                               "read_noise_e": 1.5},
}


@pytest.mark.benchmark(group="terms 1e5 points, 1 thread")
@pytest.mark.parametrize("scene", list(SCENES))
def test_term_cost(benchmark, scene):
    kwargs = _scene(**SCENES[scene])
    result = benchmark.pedantic(epc_fast.evaluate, kwargs=dict(kwargs, threads=1), rounds=5,
                                iterations=1, warmup_rounds=1)
    assert np.all(result.status == epc_fast.Status.OK)
    assert np.all(result.epc > 0)



QUICK = os.environ.get("EPC_FAST_BENCH_QUICK", "").strip() not in ("", "0")
PHONE_POINTS = 10**5 if QUICK else 10**6


def _keyword_costs():
    """tools/keyword_costs.py: docs/performance.md's phone scene and its cases."""
    path = Path(__file__).resolve().parents[1] / "tools" / "keyword_costs.py"
    spec = importlib.util.spec_from_file_location("keyword_costs", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


KEYWORD_COSTS = _keyword_costs()


@pytest.mark.benchmark(group="the phone's terms, 2 threads")
@pytest.mark.parametrize("term", list(KEYWORD_COSTS.CASES))
def test_phone_term_cost(benchmark, term):
    points = KEYWORD_COSTS.scene(PHONE_POINTS)

    def minimal():
        return epc_fast.evaluate(**points)

    def with_term():
        return epc_fast.evaluate(**points, **KEYWORD_COSTS.CASES[term])

    minimal(), with_term()  # warm: the output memory kept, the tables checked once
    rounds = 3 if QUICK else 5
    seconds = KEYWORD_COSTS.seconds
    pairs = [(seconds(minimal), seconds(with_term)) for _ in range(rounds)]
    benchmark.extra_info["ratio_to_minimal"] = float(np.median([t / m for m, t in pairs]))
    result = benchmark.pedantic(with_term, rounds=rounds, iterations=1, warmup_rounds=0)
    finite = np.isfinite(result.epc)  # 0 where the blur is unbounded, NaN over a frame cap
    assert finite.mean() > 0.5 and np.all(result.epc[finite] >= 0)
    assert np.count_nonzero(result.epc[finite] > 0) > 0.5 * finite.size
