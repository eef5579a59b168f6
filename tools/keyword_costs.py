"""What the real-camera terms and keywords cost against the minimal scene (docs/performance.md,
"What the real-camera terms cost"): evaluate on random points (1-100,000 lux, 0.8-3 um, f/2,
5.6 mm, 20 mm^2, read noise 1.5 e-, 4.39 deg/s), 2 threads, outputs=("epc",), the median of 5
rounds alternated over the cases, each against the minimal scene of the same run, on the build
the machine loads (EPC_FAST_ISA picks another). The terms are those of
../shared/bench/phone_speed.py and more (denoising at 5 px, a 64-point table, every
demosaicker, quad Bayer), then the keywords that choose how a call counts and caps.

    python tools/keyword_costs.py [points]
"""

from __future__ import annotations

import sys
import time

import numpy as np

import epc_fast

from epc_fast.benchcompare.worker import PHONE_LENS as LENS, PHONE_MODES as MODES

NIGHT = [{"binning": 1}, {"binning": 2}, {"binning": 2, "frames": "auto", "max_frames": 16}]
#: A 64-point lens table beside the phone's 7-point one (bench compare's phone workload's).
_FINE = np.linspace(0.0, 400.0, 64)
LENS_64 = (_FINE, 0.27 + 0.73 * np.exp(-_FINE / 120.0))
#: Each case's keywords beside the scene's.
CASES = {
    "the scene alone": {},
    "binning 2": {"binning": 2},
    "4 frames + 0.3 um alignment": {"frames": 4, "alignment_error_um": 0.3},
    "wavefront 0.05 waves": {"wavefront_rms_waves": 0.05},
    "denoising 1 px": {"denoise_sigma_px": 1.0},
    "denoising 3 px": {"denoise_sigma_px": 3.0},
    "denoising 5 px": {"denoise_sigma_px": 5.0},
    "lens table, 7 points": {"lens_mtf": LENS},
    "lens table, 64 points": {"lens_mtf": LENS_64},
    "Bayer, bilinear": {"cfa": "bayer", "demosaic": "bilinear"},
    "Bayer, Malvar": {"cfa": "bayer", "demosaic": "malvar2004"},
    "Bayer, Menon": {"cfa": "bayer", "demosaic": "menon2007"},
    "quad Bayer full size, Malvar": {"cfa": "quad_bayer", "demosaic": "malvar2004"},
    "three modes (1, 2x2, 2x2 x 4 frames)": {"modes": MODES},
    "a phone: Bayer + lens table + three modes + denoising 1 px": {
        "cfa": "bayer", "demosaic": "malvar2004", "lens_mtf": LENS, "denoise_sigma_px": 1.0,
        "modes": MODES},
    "epc_axes='both'": {"epc_axes": "both"},
    "max_exposure_s=0.1": {"max_exposure_s": 0.1},
    "frames='auto', max_frames=16, max_exposure_s=0.1": {"frames": "auto", "max_frames": 16,
                                                          "max_exposure_s": 0.1},
    "three modes, epc_axes='both'": {"modes": MODES, "epc_axes": "both"},
    "three modes with night mode, the cap, 'both'": {"modes": NIGHT, "max_exposure_s": 0.1,
                                                     "epc_axes": "both"},
}


def scene(points: int) -> dict:
    """evaluate's keywords for the scene's ``points`` random points (the same each time), 2
    threads, EPC alone."""
    rng = np.random.default_rng(1)
    return dict(illuminance_lux=10 ** rng.uniform(0, 5, points),
                pixel_pitch_um=rng.uniform(0.8, 3.0, points), f_number=2.0, focal_length_mm=5.6,
                sensor_area_mm2=20.0, shake_deg_per_s=4.39, read_noise_e=1.5, threads=2,
                outputs=("epc",))


def seconds(call) -> float:
    """The wall time of one call of ``call()``."""
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def ratios(points: int = 10**6, rounds: int = 5) -> tuple:
    """(the scene's points a second, {case: its median time over the scene's})."""
    base = scene(points)
    times = {case: [] for case in CASES}
    for _ in range(rounds):
        for case, keywords in CASES.items():
            times[case].append(seconds(lambda: epc_fast.evaluate(**base, **keywords)))
    alone = float(np.median(times["the scene alone"]))
    return points / alone, {case: float(np.median(t)) / alone for case, t in times.items()}


def main(argv=None) -> None:
    args = sys.argv[1:] if argv is None else argv
    rate, by_case = ratios(int(args[0]) if args else 10**6)
    print(f"{epc_fast._core.isa}: the scene alone {rate / 1e6:.1f} M points/s")
    for case, ratio in by_case.items():
        print(f"| {case} | {ratio:.2f}x |")


if __name__ == "__main__":
    main()
