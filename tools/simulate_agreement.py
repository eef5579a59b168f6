"""The model against the capture simulator, as a Markdown table: the paper's 1/3.2" designs
from 1 to 100,000 lux and random designs with every term on (the designs of
tests/simulate/test_agreement.py), each compared by :func:`epc_fast.simulate.agreement`.

    python tools/simulate_agreement.py [--seeds 16] [--random 6]

Columns: the model's f50 (along the rows) and the f50 the e-SFR should see across a 5-degree
edge; the MTF50 of the e-SFR with bin-width correction (the camera's own MTF, as the model's;
simulate.edge_sfr) of the noise-free capture and of the seeds' pooled noisy captures
(its standard error), each relative to that f50; one noisy capture's scatter; the target SNR
and the flat patch's measured SNR with its standard error.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from epc_fast import presets, spectra
from epc_fast.simulate.agreement import agreement, every_term_design

LUX = (1.0, 10.0, 100.0, 1000.0, 10_000.0, 100_000.0)


def random_design(rng, i):
    """The i-th random design: every other one with 8 wavelengths."""
    return every_term_design(rng, spectrum=spectra.diffraction_spectrum(8) if i % 2 else None)


def row(name, lux, a) -> str:
    if math.isnan(a.f50_sim_cyc_per_mm):
        why = ("not measured: the camera turns 90 degrees" if a.status.name == "BLUR_UNBOUNDED"
               else f"not measured: the blur needs an edge over {a.edge_shape[1]:,} columns"
               if a.status.name == "OK" else f"no capture: {a.status.name}")
        return (f"| {name} | {lux:,.0f} | {a.f50_model_cyc_per_mm:.4g} | — | — | — | — "
                f"| {a.snr_db_model:.2f} | {why} |")
    n = a.f50_normal_cyc_per_mm
    return (f"| {name} | {lux:,.0f} | {a.f50_model_cyc_per_mm:.4g} | {n:.4g} "
            f"| {100 * (a.f50_noiseless_cyc_per_mm / n - 1):+.2f}% "
            f"| {100 * (a.f50_sim_cyc_per_mm / n - 1):+.2f}% ± {100 * a.f50_sem / n:.2f}% "
            f"| {100 * a.f50_sim_std / n:.2f}% | {a.snr_db_model:.2f} "
            f"| {a.snr_db_sim:.3f} ± {a.snr_db_sem:.3f} |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=16)
    parser.add_argument("--random", type=int, default=6)
    args = parser.parse_args(argv)
    print("MTF50: the e-SFR with bin-width correction (ISO 12233's, its bins' average divided "
          "out: the camera's own MTF)\n")
    print("| design | lux | f50 model (cyc/mm) | f50 across the edge | MTF50 noise-free "
          "| MTF50 pooled ± s.e. | one capture's scatter | SNR target (dB) "
          "| SNR simulated ± s.e. |")
    print("|---|---|---|---|---|---|---|---|---|")
    for design in presets.HIGH_TIER:
        for lux in LUX:
            a = agreement(lux, seeds=args.seeds, **design.evaluate_kwargs())
            print(row(design.name, lux, a), flush=True)
    for i in range(args.random):
        design, lux = random_design(np.random.default_rng([38, i]), i)
        a = agreement(lux, seeds=args.seeds, **design)
        name = (f"random {i}: {design['pixel_pitch_um']:.2f} um F/{design['f_number']:.1f}"
                f"{', 8 wavelengths' if 'spectrum' in design else ''}")
        print(row(name, lux, a), flush=True)


if __name__ == "__main__":
    main()
