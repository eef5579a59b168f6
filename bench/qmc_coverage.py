"""Are the scan's standard errors honest? Over 100 seeds of 2^20 points of the README's
example space, how often the true error (against a reference of 2^30 Sobol' points) lies
within 2 reported standard errors, for the mean EPC, the median, the 5% quantile and the
fraction below 2 Mpixel, under Sobol' sampling (16 replicates) and Monte Carlo (the mean's and
fraction's variance, the quantiles' order statistics) (docs/scan.md).

    python bench/qmc_coverage.py [--seeds 100] [--points-log2 20] [--reference-log2 30]
"""

from __future__ import annotations

import argparse

import numpy as np

from epc_fast.scan import FractionBelow, Quantiles, Summary, run
from qmc_accuracy import STATISTICS, readme_space

BINS_PER_DECADE = 20_000  # the reference's streamed quantiles: bins 0.0115% wide


def _statistics(result) -> dict:
    q = result["q"]
    error = q.standard_error
    return {"mean": (result["summary"].mean[0], result["summary"].mean_error[0]),
            "median": (q.estimate[0, 1], error[0, 1]), "q5": (q.estimate[0, 0], error[0, 0]),
            "P(EPC < 2 Mpixel)": (result["below"].fraction[0],
                                  result["below"].standard_error[0])}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--points-log2", type=int, default=20)
    parser.add_argument("--reference-log2", type=int, default=30)
    args = parser.parse_args(argv)
    space = readme_space()
    reference = run(space, 1 << args.reference_log2, seed=2**64 - 1, sampling="sobol",
                    replicates=16, progress=False, reductions={
                        "summary": Summary(), "below": FractionBelow(2e6),
                        "q": Quantiles((0.05, 0.5), exact_up_to=0,
                                       bins_per_decade=BINS_PER_DECADE)})
    truth = {name: value for name, (value, _) in _statistics(reference).items()}
    reductions = {"summary": Summary(), "below": FractionBelow(2e6),
                  "q": Quantiles((0.05, 0.5), exact_up_to=1 << 30)}
    print(f"{args.seeds} seeds of 2^{args.points_log2} points against 2^{args.reference_log2}:\n")
    print("| sampling | " + " | ".join(STATISTICS) + " |")
    print("|---" * (len(STATISTICS) + 1) + "|")
    for sampling, replicates in (("sobol", 16), ("monte_carlo", 1)):
        inside = {name: 0 for name in STATISTICS}
        ratio = {name: [] for name in STATISTICS}
        for seed in range(args.seeds):
            result = run(space, 1 << args.points_log2, seed=seed, sampling=sampling,
                         replicates=replicates, reductions=reductions, progress=False)
            for name, (value, error) in _statistics(result).items():
                inside[name] += abs(value - truth[name]) <= 2 * error
                ratio[name].append(abs(value - truth[name]) / error)
        print(f"| {sampling} | " + " | ".join(
            f"{inside[n]} of {args.seeds} (median error / s.e. {np.median(ratio[n]):.2f})"
            for n in STATISTICS) + " |", flush=True)


if __name__ == "__main__":
    main()
