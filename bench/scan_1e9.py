"""Throughput and peak memory of a Monte Carlo scan against the raw core.

    python bench/scan_1e9.py                    # the issue's target: 10^9 points, 2 threads
    python bench/scan_1e9.py --points 1e7       # a quick check

The scan is the built-in default space (the paper's 1/3.2" designs x log-uniform illuminance
10..1e5 lux x log-normal hand shake, median 4.39 degree/s, sigma 0.5) with the target's
reductions: per-design summary, per-design histogram and per-design quantiles (streamed from a
1000-bins-per-decade histogram at every size, as beyond 2^22 points). It prints:

- the raw core: evaluate on pre-generated chunks of the scan's own points (drawing them is not
  timed), over the first ``--raw-chunks`` chunks, once before and once after the scan;
- the scan, end to end (drawing, core, reductions, merging), and its ratio to the raw core;
- the core's share of the scan's wall time: the same ratio measured inside the one run (the
  time spent in evaluate on the scan's pre-drawn chunks, over the wall time), immune to other
  load on the machine that changes between separate measurements;
- the peak resident memory of the process (ru_maxrss).
"""

from __future__ import annotations

import argparse
import resource
import time

from epc_fast import evaluate
from epc_fast.scan import Histogram, Quantiles, Summary, run
from epc_fast.scan.config import default_config
from epc_fast.scan.runner import DEFAULT_CHUNK_POINTS


def benchmark_space():
    """The scanned space: the built-in default config's."""
    return default_config().space


def benchmark_reductions() -> dict:
    """The target's reductions: per-design summary, histogram and streamed quantiles."""
    return {"summary": Summary(by="design"),
            "histogram": Histogram(1e3, 1e7, 80, by="design"),
            "quantiles": Quantiles((0.05, 0.5, 0.95), by="design", exact_up_to=0)}


def peak_rss_mb() -> float:
    """MB: the process's peak resident set (Linux reports ru_maxrss in kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def raw_core_points_per_s(space, seed: int, chunks: int, threads: int) -> float:
    """points/s of evaluate alone on the scan's first ``chunks`` chunks (after one untimed
    warm-up call: thread start-up and first-touch page faults are not the core's speed)."""
    warm_up = space.points(seed, 0, DEFAULT_CHUNK_POINTS)
    evaluate(**warm_up.parameters, threads=threads)
    elapsed = points = 0
    for chunk in range(chunks):
        drawn = space.points(seed, chunk * DEFAULT_CHUNK_POINTS, (chunk + 1) * DEFAULT_CHUNK_POINTS)
        started = time.perf_counter()
        evaluate(**drawn.parameters, threads=threads)
        elapsed += time.perf_counter() - started
        points += len(drawn)
    return points / elapsed


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=float, default=1e9)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--seed", type=int, default=2009)
    parser.add_argument("--raw-chunks", type=int, default=8,
                        help="chunks of 2^20 points timed for the raw core")
    args = parser.parse_args(argv)
    points = int(args.points)
    space = benchmark_space()
    raw_before = raw_core_points_per_s(space, args.seed, args.raw_chunks, args.threads)
    rss_after_raw = peak_rss_mb()
    result = run(space, points, seed=args.seed, reductions=benchmark_reductions(),
                 threads=args.threads, progress=None)
    raw_after = raw_core_points_per_s(space, args.seed, args.raw_chunks, args.threads)
    raw = 0.5 * (raw_before + raw_after)
    timing = result.timing
    print(f"points            {result.points:,}{' (partial)' if result.partial else ''}")
    print(f"raw core          {raw / 1e6:.3f} M points/s ({args.threads} threads, "
          f"{args.raw_chunks} chunks of {DEFAULT_CHUNK_POINTS}: {raw_before / 1e6:.3f} before "
          f"the scan, {raw_after / 1e6:.3f} after)")
    print(f"scan              {result.points_per_s / 1e6:.3f} M points/s, "
          f"{timing.wall_s:.1f} s")
    print(f"ratio             {result.points_per_s / raw:.3f} of the raw core")
    print(f"core share        {timing.core_s / timing.wall_s:.3f} of the scan's wall time "
          f"(drawing {timing.sampling_s / timing.wall_s:.3f}, "
          f"reducing {timing.reduction_s / timing.wall_s:.3f})")
    print(f"peak RSS          {peak_rss_mb():.0f} MB (after the raw-core pass: "
          f"{rss_after_raw:.0f} MB)")


if __name__ == "__main__":
    main()
