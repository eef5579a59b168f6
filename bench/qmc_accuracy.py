"""Points to accuracy: plain Monte Carlo against scrambled Sobol' sampling, with SciPy's and
qmcpy's quasi-Monte Carlo as peers, on two spaces (docs/scan.md, "Sobol' sampling"):

- the README's example (the paper's four 1/3.2" designs on a grid with read noise 0 or 2 e-,
  log-uniform light, log-normal shake, a choice of stabilisation);
- a random 8-parameter space (light, pitch, f-number, focal length, shake, read noise,
  reflectance, dark current, each drawn; one sensor of 12 Mpixel).

For each, the relative RMS error over independent seeds (against a reference of 2^25 Sobol'
points) of the mean EPC, the median, the 5% quantile and the fraction below 2 Mpixel, at 2^12
to 2^20 points, for Monte Carlo, scrambled Sobol' (16 replicates) and SciPy's scrambled Sobol'
points evaluated by :func:`epc_fast.evaluate`; and the time (and points) to a mean with 1e-3
relative standard error: the scan's stopping rule under both samplings, SciPy's points doubled
until 16 scramblings agree, and qmcpy's adaptive ``CubQMCNetG`` (its own stopping rule).

    python bench/qmc_accuracy.py                  # tables; docs/images/qmc_accuracy.png
    python bench/qmc_accuracy.py --quick          # fewer seeds and points, no plot
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from epc_fast import evaluate
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (Choice, FractionBelow, Grid, LogNormal, LogUniform, Quantiles, Space,
                           Summary, Truncated, Uniform, run)

ROOT = Path(__file__).resolve().parents[1]
STATISTICS = ("mean", "median", "q5", "P(EPC < 2 Mpixel)")
METHODS = ("monte_carlo", "sobol", "scipy")
REPLICATES = 16
REFERENCE_POINTS = 1 << 25
THREADS = 2


def readme_space() -> Space:
    """The README's example scan's space."""
    return Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
                 shake_deg_per_s=Truncated(LogNormal(4.39, 0.5), 0.2, 40),
                 stabilization=Choice((1.0, 4.0), (0.5, 0.5)), read_noise_e=Grid((0.0, 2.0)))


def random8_space() -> Space:
    """Eight drawn parameters over a phone camera's range, one 12 Mpixel sensor."""
    return Space(illuminance_lux=LogUniform(10, 1e5), pixel_pitch_um=Uniform(0.8, 2.8),
                 f_number=Uniform(1.4, 4.0), focal_length_mm=Uniform(3.0, 8.0),
                 shake_deg_per_s=LogNormal(3.0, 0.6), read_noise_e=Uniform(0.0, 4.0),
                 reflectance=Uniform(0.1, 0.9), dark_current_e_per_s=LogUniform(1.0, 100.0),
                 pixel_count=12e6)


SPACES = {"README example": readme_space, "random 8 parameters": random8_space}


def _reductions() -> dict:
    return {"summary": Summary(), "q": Quantiles((0.05, 0.5), exact_up_to=1 << 30),
            "below": FractionBelow(2e6)}


def scan_statistics(result) -> dict:
    return {"mean": result["summary"].mean[0], "median": result["q"].estimate[0, 1],
            "q5": result["q"].estimate[0, 0], "P(EPC < 2 Mpixel)": result["below"].fraction[0]}


def array_statistics(epc: np.ndarray) -> dict:
    epc = epc[np.isfinite(epc)]
    q5, median = np.quantile(epc, (0.05, 0.5))
    return {"mean": epc.mean(), "median": median, "q5": q5,
            "P(EPC < 2 Mpixel)": np.count_nonzero(epc < 2e6) / epc.size}


def reference(space: Space, points: int = REFERENCE_POINTS) -> dict:
    result = run(space, points, seed=2**63 + 12345, sampling="sobol", replicates=REPLICATES,
                 reductions=_reductions(), progress=False, threads=THREADS)
    return scan_statistics(result)


# -- SciPy's and qmcpy's points, evaluated by epc_fast ---------------------------------------

def peer_epc(space: Space, u: np.ndarray) -> np.ndarray:
    """EPC (points, grid cells) at uniforms u (points, random parameters): each point at every
    cell of the space's grid, as a scan stratifies over them."""
    cells = np.arange(space.grid_size)
    indices, cell_values = space._grid_cells(cells) if space.grid_axes else ({}, {})
    n, g = u.shape[0], cells.size
    parameters = {name: np.repeat(np.asarray(v, dtype=float)[None, :], n, axis=0)
                  for name, v in cell_values.items()}
    for d, name in enumerate(space.random_axes):
        axis = space.axes[name]
        if isinstance(axis, Choice):
            values = np.asarray(axis.values, dtype=float)[axis.indices_from_uniform(u[:, d])]
        else:
            values = axis.from_uniform(u[:, d])
        parameters[name] = np.repeat(values[:, None], g, axis=1)
    for name, axis in space.axes.items():
        if isinstance(axis, float):
            parameters[name] = axis
    for name in space.design_constant:
        parameters[name] = float(space.design_table[name][0])
    return evaluate(**parameters, threads=THREADS, outputs=("epc",)).epc


def scipy_points(space: Space, points: int, seed: int) -> np.ndarray:
    """EPC at ``points`` evaluations: 16 SciPy scrambled Sobol' sets of points / (16 cells)."""
    from scipy.stats import qmc

    per = points // (REPLICATES * space.grid_size)
    d = len(space.random_axes)
    sets = [qmc.Sobol(d, scramble=True, seed=seed * REPLICATES + r).random(per)
            for r in range(REPLICATES)]
    return peer_epc(space, np.concatenate(sets)).ravel()


def error_table(space: Space, ref: dict, sizes, seeds: int) -> dict:
    """{method: {points: {statistic: relative RMS error over seeds}}}."""
    table = {m: {} for m in METHODS}
    for n in sizes:
        for method in METHODS:
            errors = {s: [] for s in STATISTICS}
            for seed in range(seeds):
                if method == "scipy":
                    stats = array_statistics(scipy_points(space, n, seed))
                else:
                    stats = scan_statistics(run(
                        space, n, seed=seed, sampling=method,
                        replicates=REPLICATES if method == "sobol" else 1,
                        reductions=_reductions(), progress=False, threads=THREADS))
                for s in STATISTICS:
                    errors[s].append((stats[s] - ref[s]) / abs(ref[s]))
            table[method][n] = {s: math.sqrt(np.mean(np.square(e))) for s, e in errors.items()}
    return table


def fewer_points(table: dict, n: int) -> dict:
    """{statistic: how many times fewer points Sobol' takes than Monte Carlo for its error at
    ``n`` points}: Monte Carlo's error falls as n^-1/2, so it needs n (e_mc / e_sobol)^2."""
    return {s: (table["monte_carlo"][n][s] / table["sobol"][n][s]) ** 2 for s in STATISTICS}


# -- time to a mean with 1e-3 relative standard error ------------------------------------------

def time_ours(space: Space, sampling: str, relative: float, cap: int = 1 << 31) -> dict:
    start = time.perf_counter()
    result = run(space, cap, seed=7, sampling=sampling, replicates=REPLICATES,
                 reductions={"summary": Summary(target={"relative": relative})},
                 progress=False, threads=THREADS)
    seconds = time.perf_counter() - start
    summary = result["summary"]
    return {"points": result.points, "seconds": seconds, "estimate": summary.mean[0],
            "claimed": summary.mean_error[0] / summary.mean[0]}


def time_scipy(space: Space, relative: float, cap: int = 1 << 31) -> dict:
    """SciPy's scrambled Sobol' points, 16 engines continued in powers of two until the
    replicates' standard error of the mean is within ``relative``."""
    from scipy.stats import qmc

    start = time.perf_counter()
    d, g = len(space.random_axes), space.grid_size
    engines = [qmc.Sobol(d, scramble=True, seed=7 * REPLICATES + r) for r in range(REPLICATES)]
    sums = np.zeros(REPLICATES)
    counts = np.zeros(REPLICATES)
    per = max(1, (1 << 16) // (REPLICATES * g))
    while True:
        for r, engine in enumerate(engines):
            epc = peer_epc(space, engine.random(per))
            finite = np.isfinite(epc)
            sums[r] += epc[finite].sum()
            counts[r] += np.count_nonzero(finite)
        means = sums / counts
        mean = sums.sum() / counts.sum()
        error = means.std(ddof=1) / math.sqrt(REPLICATES)
        points = int(counts.sum())
        if error <= relative * abs(mean) or points >= cap:
            break
        per = int(counts[0] // g)  # double: the next as many points as so far
    return {"points": points, "seconds": time.perf_counter() - start, "estimate": mean,
            "claimed": error / mean}


def time_qmcpy(space: Space, relative: float) -> dict:
    """qmcpy's CubQMCNetG (digital nets, its adaptive stopping rule) on the mean over the grid's
    cells, to ``relative``."""
    import qmcpy

    d, g = len(space.random_axes), space.grid_size
    start = time.perf_counter()
    integrand = qmcpy.CustomFun(true_measure=qmcpy.Uniform(qmcpy.DigitalNetB2(d, seed=7)),
                                g=lambda u: np.nan_to_num(peer_epc(space, u)).mean(axis=1))
    solution, data = qmcpy.CubQMCNetG(integrand, abs_tol=0.0, rel_tol=relative,
                                      n_limit=2**30).integrate()
    return {"points": int(data.n_total) * g, "seconds": time.perf_counter() - start,
            "estimate": float(solution), "claimed": float(data.bounds_half_width) / solution}


def time_table(space: Space, ref: dict, relative: float = 1e-3) -> dict:
    rows = {"epc_fast Monte Carlo": time_ours(space, "monte_carlo", relative),
            "epc_fast Sobol'": time_ours(space, "sobol", relative),
            "SciPy Sobol' (16 scramblings)": time_scipy(space, relative)}
    try:
        rows["qmcpy CubQMCNetG"] = time_qmcpy(space, relative)
    except ImportError:
        pass
    for row in rows.values():
        row["true"] = abs(row["estimate"] - ref["mean"]) / abs(ref["mean"])
    return rows


# -- report ------------------------------------------------------------------------------------

def markdown(space_name: str, table: dict, times: dict, n_top: int) -> str:
    lines = [f"**{space_name}**: relative RMS error over seeds", "",
             "| points | " + " | ".join(f"{s}: MC / Sobol' / SciPy" for s in STATISTICS) + " |",
             "|---" * (len(STATISTICS) + 1) + "|"]
    for n in sorted(table["sobol"]):
        cells = [" / ".join(f"{table[m][n][s]:.2g}" for m in METHODS) for s in STATISTICS]
        lines.append(f"| 2^{int(math.log2(n))} | " + " | ".join(cells) + " |")
    ratio = fewer_points(table, n_top)
    lines += ["", f"Times fewer points than Monte Carlo for Sobol's error at 2^"
              f"{int(math.log2(n_top))}: " + ", ".join(f"{s} {v:.3g}x" for s, v in ratio.items()),
              "", "| to a mean with 1e-3 relative standard error | points | s | claimed | true |",
              "|---|---|---|---|---|"]
    for name, row in times.items():
        lines.append(f"| {name} | {row['points']:,} | {row['seconds']:.3g} | "
                     f"{row['claimed']:.2g} | {row['true']:.2g} |")
    return "\n".join(lines)


def plot(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(STATISTICS), figsize=(15, 3.8), constrained_layout=True)
    styles = {"README example": "-", "random 8 parameters": "--"}
    colours = {"monte_carlo": "C0", "sobol": "C3", "scipy": "C2"}
    labels = {"monte_carlo": "Monte Carlo", "sobol": "Sobol' (epc_fast)",
              "scipy": "Sobol' (SciPy points)"}
    for ax, s in zip(axes, STATISTICS):
        for space_name, (table, _) in results.items():
            for m in METHODS:
                n = sorted(table[m])
                ax.loglog(n, [table[m][k][s] for k in n], styles[space_name],
                          color=colours[m], marker=".",
                          label=f"{labels[m]}, {space_name}")
        ax.set_title(s)
        ax.set_xlabel("points")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("relative RMS error over seeds")
    axes[-1].legend(fontsize=7)
    fig.savefig(path, dpi=110)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--seeds", type=int, default=None)
    args = parser.parse_args(argv)
    seeds = args.seeds or (4 if args.quick else 20)
    sizes = [1 << m for m in (range(12, 15) if args.quick else range(12, 21))]
    ref_points = 1 << 20 if args.quick else REFERENCE_POINTS
    results = {}
    for name, make in SPACES.items():
        space = make()
        ref = reference(space, ref_points)
        table = error_table(space, ref, sizes, seeds)
        times = time_table(space, ref)
        results[name] = (table, times)
        print(markdown(name, table, times, sizes[-1]), "\n", flush=True)
    if not args.quick:
        plot(results, ROOT / "docs" / "images" / "qmc_accuracy.png")


if __name__ == "__main__":
    main()
