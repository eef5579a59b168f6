"""Sobol' indices from scrambled Sobol' points against Monte Carlo points, at equal model
evaluations: the spread of S1 and ST over independent seeds (docs/sensitivity.md).

:func:`epc_fast.scan.sobol_indices` lays Saltelli's design on a scrambled Sobol' sequence
(SALib's ``sample.sobol``); the Monte Carlo design here has the same layout (rows A, AB_1 ..
AB_D, B per base point) on independent uniform A and B, and SALib's same estimators read both.

    python bench/qmc_sensitivity.py
"""

from __future__ import annotations

import numpy as np

from epc_fast.scan import LogNormal, LogUniform, Space, Uniform
from epc_fast.scan.indices import estimate

SPACE = Space(illuminance_lux=LogUniform(10, 1e5), pixel_pitch_um=Uniform(0.8, 2.8),
              f_number=Uniform(1.4, 4.0), focal_length_mm=5.6, pixel_count=12e6,
              shake_deg_per_s=LogNormal(3.0, 0.6), read_noise_e=Uniform(0.0, 4.0))
POINTS = 1024
SEEDS = 20


def monte_carlo_design(d: int, points: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    a, b = rng.random((points, d)), rng.random((points, d))
    rows = [a]
    for j in range(d):
        ab = a.copy()
        ab[:, j] = b[:, j]
        rows.append(ab)
    rows.append(b)
    return np.stack(rows, axis=1).reshape(-1, d)


def indices(design: np.ndarray, parameters: tuple, seed: int) -> tuple[np.ndarray, np.ndarray]:
    _, analyze = estimate._salib()
    inputs = estimate.design_inputs(SPACE, parameters, design)
    epc, _, _ = estimate._evaluated_epc(SPACE, 0, inputs, "zero", 2, "")
    found = estimate._analysed(analyze, parameters, np.log(np.maximum(epc, 1.0)), False, 10,
                            0.95, seed)
    return found["S1"], found["ST"]


def main() -> None:
    parameters = estimate.random_parameters(SPACE)
    results = {"Sobol' (SALib)": [], "Monte Carlo": []}
    for seed in range(SEEDS):
        results["Sobol' (SALib)"].append(indices(
            estimate.unit_design(parameters, POINTS, seed), parameters, seed))
        results["Monte Carlo"].append(indices(
            monte_carlo_design(len(parameters), POINTS, seed), parameters, seed))
    print(f"log EPC, {POINTS} base points ({POINTS * (len(parameters) + 2):,} evaluations), "
          f"spread over {SEEDS} seeds:\n")
    print("| parameter | S1 | S1 spread: Sobol' / MC | ST | ST spread: Sobol' / MC |")
    print("|---|---|---|---|---|")
    spread = {k: np.std(np.array(v), axis=0, ddof=1) for k, v in results.items()}
    mean = np.mean(np.array(results["Sobol' (SALib)"]), axis=0)
    for j, name in enumerate(parameters):
        s, m = spread["Sobol' (SALib)"], spread["Monte Carlo"]
        print(f"| {name} | {mean[0, j]:.3f} | {s[0, j]:.2g} / {m[0, j]:.2g} | {mean[1, j]:.3f} | "
              f"{s[1, j]:.2g} / {m[1, j]:.2g} |")


if __name__ == "__main__":
    main()
