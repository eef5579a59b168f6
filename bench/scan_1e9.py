"""Throughput and peak memory of a Monte Carlo scan against the raw core and the peers.

    python bench/scan_1e9.py                          # 10^9 points, 2 threads
    python bench/scan_1e9.py --points 2e7 --peers     # a quick run, with the peers and scaling
    EPC_FAST_ISA=x86-64-v3 python bench/scan_1e9.py --points 2e7   # the AVX2 build

The scan is the built-in default space (the paper's 1/3.2" designs x log-uniform illuminance
10..1e5 lux x log-normal hand shake, median 4.39 degree/s, sigma 0.5) with per-design summary,
streamed 5/50/95% quantiles (from the histogram of 512 bins an octave at every size) and the
fraction below 2 Mpixel. It prints the machine (CPU, the loaded core build, threads, the
command), then:

- the raw core: ``evaluate`` on pre-drawn arrays of the scan's own points with the outputs the
  scan needs (status and EPC), chunks of 2^20, drawing not timed; the best of three passes;
- the scan end to end (drawing, evaluating, reducing and merging in the fused pass), its
  ratio to the raw core, and the process's peak resident memory after it (measured before the
  raw core's arrays are drawn);
- with ``--peers``: the scan on one thread (the 2-thread scaling), the draws' floor (the same
  points drawn and evaluated with one overall fraction below as the only reduction), the NumPy
  path (NumPy draws and reductions around ``evaluate``), and the Numba peer (one ``prange``
  loop that draws, evaluates and reduces: ``bench/peers/numba_scan_peer.py``), each on
  ``--peer-points``, the best of ``--repeats`` rounds that run every measure in turn.
"""

from __future__ import annotations

import argparse
import platform
import resource
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from epc_fast import _core, evaluate
from epc_fast.scan import FractionBelow, Quantiles, Summary, run
from epc_fast.scan.config import default_config
from epc_fast.scan.running.core_plan import CorePlan

#: Points per chunk of the raw core's pre-drawn arrays.
RAW_CHUNK = 1 << 20


def benchmark_space():
    """The scanned space: the built-in default config's."""
    return default_config().space


def benchmark_reductions() -> dict:
    """Per-design summary, streamed quantiles and fraction below 2 Mpixel."""
    return {"summary": Summary(by="design"),
            "quantiles": Quantiles((0.05, 0.5, 0.95), by="design", exact_up_to=0),
            "below": FractionBelow(2e6, by="design")}


def floor_reductions() -> dict:
    """The least a scan folds: one fraction below 2 Mpixel over all points (the draws' floor:
    the scan's points drawn and evaluated, next to nothing reduced)."""
    return {"below": FractionBelow(2e6)}


def cpu_name() -> str:
    """The CPU's model name (Linux), else the platform's processor string."""
    try:
        with open("/proc/cpuinfo") as handle:
            for line in handle:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def machine_lines(threads: int) -> list[str]:
    """What the figures were measured on: CPU, core build, threads and the command."""
    return [f"cpu               {cpu_name()}",
            f"core build        {_core.isa} (EPC_FAST_ISA forces one)",
            f"threads           {threads}",
            f"command           {shlex.join([sys.executable.split('/')[-1], *sys.argv])}"]


def peak_rss_mb() -> float:
    """MB: the process's peak resident set (Linux reports ru_maxrss in kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def raw_core_points_per_s(space, seed: int, chunks: int, threads: int) -> float:
    """points/s of evaluate alone on the scan's first ``chunks`` chunks of RAW_CHUNK points,
    drawn beforehand, computing the outputs the scan's reductions read (status and EPC): the
    best of three passes, after an untimed call (thread start-up, first-touch page faults)."""
    plan = CorePlan(space, seed)
    drawn = [plan.points(k * RAW_CHUNK, (k + 1) * RAW_CHUNK).parameters for k in range(chunks)]
    evaluate(**drawn[0], threads=threads, outputs=("status", "epc"))
    best = 0.0
    for _ in range(3):
        started = time.perf_counter()
        for parameters in drawn:
            evaluate(**parameters, threads=threads, outputs=("status", "epc"))
        best = max(best, chunks * RAW_CHUNK / (time.perf_counter() - started))
    return best


def scan_points_per_s(space, points: int, seed: int, threads: int, backend: str = "core"):
    """(points/s, result) of one scan end to end."""
    result = run(space, points, seed=seed, reductions=benchmark_reductions(), threads=threads,
                 progress=False, backend=backend)
    return result.points_per_s, result


def best_of_rounds(measures: dict, rounds: int) -> dict:
    """{name: the highest points/s of ``rounds`` calls} of each measure, called in turn round
    after round, so that the machine's drift over the rounds reaches every measure alike (a
    measure giving None, as the Numba peer without Numba, stays None)."""
    best = dict.fromkeys(measures)
    for _ in range(rounds):
        for name, measure in measures.items():
            value = measure()
            if value is not None:
                best[name] = value if best[name] is None else max(best[name], value)
    return best


def numba_peer_points_per_s(points: int, seed: int, threads: int):
    """points/s of the Numba peer (compiled first), or None without Numba."""
    try:
        sys.path.insert(0, str(Path(__file__).parent))
        from peers import numba_scan_peer
    except ImportError:
        return None
    numba_scan_peer.warm_up(threads=threads)
    started = time.perf_counter()
    numba_scan_peer.scan(points, seed=seed, threads=threads)
    return points / (time.perf_counter() - started)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=float, default=1e9)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--seed", type=int, default=2009)
    parser.add_argument("--raw-chunks", type=int, default=8,
                        help="chunks of 2^20 points timed for the raw core")
    parser.add_argument("--peers", action="store_true",
                        help="also time 1 thread, the NumPy path and the Numba peer")
    parser.add_argument("--peer-points", type=float, default=2**24)
    parser.add_argument("--repeats", type=int, default=3,
                        help="rounds of the --peers measures; each gives its best")
    args = parser.parse_args(argv)
    points = int(args.points)
    space = benchmark_space()
    for line in machine_lines(args.threads):
        print(line)
    run(space, 4 * RAW_CHUNK, seed=args.seed, reductions=benchmark_reductions(),
        threads=args.threads, progress=False)  # warm-up: threads, caches, the plan
    speed, result = scan_points_per_s(space, points, args.seed, args.threads)
    rss_scan = peak_rss_mb()  # before the raw core's pre-drawn arrays
    raw = raw_core_points_per_s(space, args.seed, args.raw_chunks, args.threads)
    print(f"points            {result.points:,}{' (partial)' if result.partial else ''}")
    print(f"raw core          {raw / 1e6:.1f} M points/s (evaluate on pre-drawn arrays, "
          f"status and EPC, {args.raw_chunks} chunks of 2^20)")
    print(f"scan              {speed / 1e6:.1f} M points/s, {result.timing.wall_s:.1f} s "
          f"(summary, streamed quantiles, fraction below; per design)")
    print(f"scan / raw core   {speed / raw:.2f}")
    print(f"peak RSS          {rss_scan:.0f} MB (the process, after the scan)")
    if not args.peers:
        return
    peer_points = int(args.peer_points)
    measures = {
        "one": lambda: scan_points_per_s(space, peer_points, args.seed, 1)[0],
        "two": lambda: scan_points_per_s(space, peer_points, args.seed, args.threads)[0],
        "floor": lambda: run(space, peer_points, seed=args.seed, reductions=floor_reductions(),
                             threads=args.threads, progress=False).points_per_s,
        "numpy": lambda: scan_points_per_s(space, peer_points, args.seed, args.threads,
                                           "numpy")[0],
        "numba": lambda: numba_peer_points_per_s(peer_points, args.seed, args.threads),
    }
    best = best_of_rounds(measures, args.repeats)
    one, two, floor, numpy_path, numba = (best[k] for k in measures)
    print(f"at {peer_points:,} points, the best of {args.repeats} rounds:")
    print(f"  scan, 1 thread  {one / 1e6:.1f} M points/s ({args.threads} threads: "
          f"{two / 1e6:.1f}, {two / one:.2f}x)")
    print(f"  draws' floor    {floor / 1e6:.1f} M points/s ({floor / raw:.2f} of the raw core: "
          f"drawing and evaluating, one overall fraction below)")
    print(f"  NumPy path      {numpy_path / 1e6:.1f} M points/s (the scan is "
          f"{two / numpy_path:.1f}x)")
    if numba is not None:
        print(f"  Numba peer      {numba / 1e6:.1f} M points/s (the scan is {two / numba:.1f}x)")
    print(f"numpy             {np.__version__}")


if __name__ == "__main__":
    main()
