"""The default call against its strongest Numba peer, interleaved: rounds of 8,192 random
designs (``epc_fast.selfcheck.random_designs``, cached), the core and the peer
(``peers/numba_two_steps.py``) taken in turn in every round, each into preallocated arrays;
per side the median of rounds and the mean of the fastest fifth, and their ratios, on 1 and 2
threads, for the peer's two outputs (f50 and EPC) and for every default output.

    python bench/kernel_ratio.py [--rounds 2000] [--points 8192]
    EPC_FAST_ISA=x86-64-v3 python bench/kernel_ratio.py      # the AVX2 build
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numba  # noqa: E402

import epc_fast  # noqa: E402
from epc_fast import _core  # noqa: E402
from epc_fast.selfcheck import random_designs  # noqa: E402
from peers import numba_two_steps  # noqa: E402

PEER_KEYS = ("illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm",
             "sensor_area_mm2", "read_noise_e", "shake_deg_per_s")


def _fastest_fifth(seconds: np.ndarray) -> float:
    ordered = np.sort(seconds)
    return float(ordered[:max(1, ordered.size // 5)].mean())


def measure(designs: dict, rounds: int, threads: int, outputs) -> dict:
    n = designs["illuminance_lux"].size
    numba.set_num_threads(threads)
    peer_args = [designs[k] for k in PEER_KEYS]
    f50, epc = np.empty(n), np.empty(n)
    if outputs is None:
        out = None
        kwargs = {}
    else:
        out = {"f50_cyc_per_mm": np.empty(n), "epc": np.empty(n)}
        kwargs = {"outputs": outputs, "out": out}
    seconds = {"core": [], "peer": []}
    for round_ in range(rounds + 1):
        order = ("core", "peer") if round_ % 2 == 0 else ("peer", "core")
        for side in order:
            start = time.perf_counter()
            if side == "core":
                result = epc_fast.evaluate(**designs, threads=threads, **kwargs)
            else:
                numba_two_steps.evaluate(*peer_args, f50, epc)
            if round_:
                seconds[side].append(time.perf_counter() - start)
    core = result.f50_cyc_per_mm if out is None else out["f50_cyc_per_mm"]
    ok = np.isfinite(core) & (core > 0)
    error = float(np.max(np.abs(f50[ok] / core[ok] - 1.0)))
    s = {k: np.asarray(v) for k, v in seconds.items()}
    return {"core_median_ns": 1e9 * np.median(s["core"]) / n,
            "peer_median_ns": 1e9 * np.median(s["peer"]) / n,
            "ratio_median": float(np.median(s["peer"]) / np.median(s["core"])),
            "ratio_fastest_fifth": _fastest_fifth(s["peer"]) / _fastest_fifth(s["core"]),
            "peer_max_rel_error": error}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2000)
    parser.add_argument("--points", type=int, default=8192)
    args = parser.parse_args(argv)
    designs = random_designs(args.points, seed=12345)
    designs = {k: np.ascontiguousarray(v) for k, v in designs.items()}
    f50, epc = np.empty(args.points), np.empty(args.points)
    numba_two_steps.evaluate(*[designs[k] for k in PEER_KEYS], f50, epc)  # compile
    print(f"build {_core.isa}, {args.rounds} rounds of {args.points:,} points\n")
    print("| outputs | threads | core ns/point (median) | peer ns/point (median) | "
          "peer/core, median | peer/core, fastest fifth | peer's max rel. error |")
    print("|---|---|---|---|---|---|---|")
    for label, outputs in (("f50, EPC", ("f50_cyc_per_mm", "epc")), ("every default", None)):
        for threads in (1, 2):
            m = measure(designs, args.rounds, threads, outputs)
            print(f"| {label} | {threads} | {m['core_median_ns']:.1f} | "
                  f"{m['peer_median_ns']:.1f} | {m['ratio_median']:.2f}x | "
                  f"{m['ratio_fastest_fifth']:.2f}x | {m['peer_max_rel_error']:.1e} |",
                  flush=True)


if __name__ == "__main__":
    main()
