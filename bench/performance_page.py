"""Engine throughput per core build, as rows of docs/performance.md's table.

For each build (default: every one this CPU runs) a subprocess with ``EPC_FAST_ISA`` set times
the default call, ``epc_fast.evaluate(**random_designs(n, seed=12345), threads=t)``, in float64
and with ``precision="float32"``, on 2 threads and 1, and the NumPy reference
(``backend="reference"``) on fewer points for the ratio. The designs and their seed are the
engine suites' (``engine_suite.py``). Each call returns new arrays, as a user's call does (the
core reuses dropped results' memory from the second call on, ``epc_fast.output_cache``); the
four core calls are taken in turn, round by round, and each one's median time counts, so a
machine whose speed drifts moves all four alike.

The output is paste-ready markdown: the CPU, the command, then one table row per build.

    python bench/performance_page.py                      # every build, 10^7 points
    python bench/performance_page.py --points 1e6 --rounds 3 --isa x86-64-v3
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

BUILDS = ("x86-64-v4", "x86-64-v3", "x86-64")
#: What each build's vectors are, for the table's first column.
BUILD_NAMES = {"x86-64-v4": "x86-64-v4 (AVX-512)", "x86-64-v3": "x86-64-v3 (AVX2)",
               "x86-64": "x86-64 (SSE2, no FMA)"}
CALLS = (("float64", 2), ("float32", 2), ("float64", 1), ("float32", 1))
COLUMNS = ("build", "float64, 2 threads", "float64, 1 thread", "2 threads / 1",
           "float32, 2 threads", "float32, 1 thread", "float32 / float64, 2 threads",
           "float32 / float64, 1 thread", "NumPy reference", "float64, 2 threads / reference")


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo, and its logical CPU count."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return f"unknown CPU, {os.cpu_count()} logical CPUs"
    names = [line.split(":", 1)[1].strip() for line in lines if line.startswith("model name")]
    return f"{names[0] if names else 'unknown CPU'}, {os.cpu_count()} logical CPUs"


def supported_builds() -> list[str]:
    """The builds this CPU runs, widest first (the core's own CPU check)."""
    from epc_fast import _core

    levels = dict(_core.cpu_levels(), **{"x86-64": True})
    return [build for build in BUILDS if levels.get(build, False)]


def measure(points: int, reference_points: int, rounds: int) -> dict:
    """points/s of each call of CALLS and of the reference, in this process's build."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import epc_fast
    from engine_suite import SEED
    from epc_fast import _core
    from epc_fast.selfcheck import random_designs

    designs = random_designs(points, seed=SEED)

    def seconds(precision: str, threads: int) -> float:
        start = time.perf_counter()
        epc_fast.evaluate(**designs, precision=precision, threads=threads)
        return time.perf_counter() - start

    for call in CALLS:  # warm-up: the first call pages in new memory
        seconds(*call)
    times = {call: [] for call in CALLS}
    for r in range(rounds):
        order = CALLS if r % 2 == 0 else CALLS[::-1]
        for call in order:
            times[call].append(seconds(*call))
    small = random_designs(reference_points, seed=SEED)
    start = time.perf_counter()
    epc_fast.evaluate(**small, backend="reference")
    reference_s = time.perf_counter() - start
    return {"isa": _core.isa,
            "points_per_s": {f"{p} {t}": points / statistics.median(times[(p, t)])
                             for p, t in CALLS},
            "reference_points_per_s": reference_points / reference_s}


def _m(rate: float) -> str:
    return f"{rate / 1e6:.3g} M" if rate >= 1e5 else f"{rate / 1e6:.2g} M"


def row(measured: dict) -> str:
    rates = measured["points_per_s"]
    reference = measured["reference_points_per_s"]
    cells = [BUILD_NAMES.get(measured["isa"], measured["isa"]),
             _m(rates["float64 2"]), _m(rates["float64 1"]),
             f"{rates['float64 2'] / rates['float64 1']:.2f}x",
             _m(rates["float32 2"]), _m(rates["float32 1"]),
             f"{rates['float32 2'] / rates['float64 2']:.2f}x",
             f"{rates['float32 1'] / rates['float64 1']:.2f}x",
             _m(reference), f"{rates['float64 2'] / reference:.0f}x"]
    return "| " + " | ".join(cells) + " |"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--isa", nargs="+", choices=BUILDS,
                        help="builds to measure (default: every one this CPU runs)")
    parser.add_argument("--points", type=float, default=1e7, help="points a call (default 1e7)")
    parser.add_argument("--reference-points", type=float, default=1e5,
                        help="points of the NumPy reference's call (default 1e5)")
    parser.add_argument("--rounds", type=int, default=5,
                        help="timed rounds of the four core calls, after a warm-up (default 5)")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    points, reference_points = int(args.points), int(args.reference_points)
    if args.child:
        print(json.dumps(measure(points, reference_points, args.rounds)))
        return 0
    from epc_fast import _core

    builds = args.isa or supported_builds()
    command = "python bench/performance_page.py " + " ".join(
        shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv))
    print(f"CPU: {cpu_model()}; loaded build without EPC_FAST_ISA: {_core.isa}")
    print(f"Command: `{command.strip()}`; {points:,} points "
          f"(`random_designs(n, seed=12345)`), median of {args.rounds} rounds; "
          f"NumPy reference on {reference_points:,} points\n")
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---|" * len(COLUMNS))
    for build in builds:
        done = subprocess.run(
            [sys.executable, __file__, "--child", "--points", str(points),
             "--reference-points", str(reference_points), "--rounds", str(args.rounds)],
            env={**os.environ, "EPC_FAST_ISA": build}, capture_output=True, text=True)
        if done.returncode != 0:
            print(f"| {BUILD_NAMES[build]} | failed: {done.stderr.strip().splitlines()[-1]} |")
            continue
        print(row(json.loads(done.stdout.strip().splitlines()[-1])), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
