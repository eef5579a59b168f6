"""A paired comparison of two installs: the same workloads in both, in alternating rounds.

Both sides run as worker sessions (:mod:`epc_fast.benchcompare.sides`) side by side, new ones
for each block of rounds: a process's own luck (where its arrays landed, whether it got huge
pages) can make one side a few percent slower for as long as it lives, and fresh processes
draw it anew, so that the interval (:mod:`epc_fast.benchcompare.ratios`) counts it. Each
workload is timed once per round on each side, the two back to back, the side that goes first
alternating from one workload and round to the next, so that neither side always meets a
warmer cache or a quieter moment. A sample is read from the process's CPU time by default:
on a machine that other work keeps busy, a process waiting for a core is not running, and its
wall time counts the wait while its CPU time does not. A sample is ``reps`` calls in a row,
``reps`` chosen from the slower side's second call so that a sample lasts at least
``min_sample_s``; the same ``reps`` on both sides.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

from .ratios import Ratio, paired_ratio
from .sides import TIMEOUT, Side
from .worker import WORKLOADS

#: (rounds, blocks, shortest sample in seconds, seed) of the full comparison and of --quick.
FULL = (30, 6, 0.10, 2026)
QUICK = (30, 6, 0.05, 2026)
#: The clocks a sample can be read from: the process's CPU time (all its threads), which a
#: busy machine's other processes leave alone while they wait for a core, or wall time.
CLOCKS = {"cpu": "cpu_seconds", "wall": "seconds"}
#: Default slowdown beyond which a significant one fails the comparison.
THRESHOLD = 0.05


def workload_points(quick: bool) -> dict:
    """{workload: points} of the full set or the short one."""
    return {name: (quick_n if quick else full_n)
            for name, (full_n, quick_n, _, _) in WORKLOADS.items()
            if not (quick and quick_n is None)}


@dataclass
class Workload:
    """One workload's paired times (seconds a call, one per round) and their ratio."""

    name: str
    points: int
    threads: int
    reps: int
    baseline_s: list = field(default_factory=list)
    candidate_s: list = field(default_factory=list)
    blocks: list = field(default_factory=list)
    ratio: Ratio | None = None


@dataclass
class Comparison:
    """What a comparison measured: both sides' builds and commands, each workload, the
    workloads one side cannot run, and the conditions."""

    baseline: dict
    candidate: dict
    threshold: float
    workloads: list
    unavailable: dict
    conditions: dict

    def verdicts(self) -> dict:
        return {w.name: w.ratio.verdict(self.threshold) for w in self.workloads}

    @property
    def failed(self) -> bool:
        """A slowdown beyond the threshold is significant in some workload."""
        return "slower" in self.verdicts().values()


def load_average() -> float | None:
    try:
        return round(os.getloadavg()[0], 2)
    except (AttributeError, OSError):
        return None


def _reps(first_call_s: float, min_sample_s: float) -> int:
    return max(1, math.ceil(min_sample_s / max(first_call_s, 1e-9)))


def _start_block(baseline, candidate, points, seed, say, block, timeout):
    """Both sides' worker sessions for one block of rounds, set up, and their answers; on any
    failure both sides are ended."""
    sides = []
    try:
        sides.append(Side("BASELINE", baseline, timeout))
        sides.append(Side("CANDIDATE", candidate, timeout))
        setups = {}
        for side in sides if block % 2 == 0 else sides[::-1]:
            say(f"block {block + 1}: {side.name} draws its designs, runs each workload twice")
            setups[side.name] = side.setup(points, seed)
    except BaseException:
        for side in sides:
            side.kill()
            side.close()
        raise
    return sides, setups["BASELINE"], setups["CANDIDATE"]


def run_comparison(baseline: str, candidate: str, *, quick: bool = False,
                   rounds: int | None = None, blocks: int | None = None,
                   threshold: float = THRESHOLD, clock: str = "cpu", only=None,
                   progress=None, timeout: float = TIMEOUT) -> Comparison:
    """Times every workload (or those named in ``only``) ``rounds`` times on both sides, in
    ``blocks`` blocks of rounds, each block with new worker processes on both sides, by
    ``clock`` (:data:`CLOCKS`). A side that takes more than ``timeout`` seconds to answer a
    request (its setup, or one sample) is killed, the other side ended, and a RuntimeError
    names it (:class:`~epc_fast.benchcompare.sides.Side`)."""
    if clock not in CLOCKS:
        raise ValueError(f"clock {clock!r}: expected one of {', '.join(CLOCKS)}")
    full_rounds, full_blocks, min_sample_s, seed = QUICK if quick else FULL
    rounds = full_rounds if rounds is None else rounds
    blocks = min(rounds, full_blocks if blocks is None else blocks)
    points = workload_points(quick)
    if only:
        points = {name: n for name, n in points.items() if name in only}
    say = progress or (lambda line: None)
    started, load_before = time.perf_counter(), load_average()
    workloads, unavailable, done = None, {}, 0
    for block in range(blocks):
        (base, cand), b, c = _start_block(baseline, candidate, points, seed, say, block,
                                          timeout)
        try:
            if workloads is None:  # the first block decides what runs and how many calls
                unavailable = {name: {"BASELINE": b["unavailable"].get(name),
                                      "CANDIDATE": c["unavailable"].get(name)}
                               for name in points
                               if name in b["unavailable"] or name in c["unavailable"]}
                workloads = [Workload(name, n, WORKLOADS[name][2],
                                      _reps(max(b["seconds"][name], c["seconds"][name]),
                                            min_sample_s))
                             for name, n in points.items() if name not in unavailable]
                builds = (b["build"], c["build"])
            count = rounds * (block + 1) // blocks - done
            for r in range(done, done + count):
                for k, w in enumerate(workloads):
                    order = (base, cand) if (r + k) % 2 == 0 else (cand, base)
                    for side in order:
                        seconds = side.sample(w.name, w.reps)[CLOCKS[clock]]
                        (w.baseline_s if side is base else w.candidate_s).append(seconds)
                    w.blocks.append(block)
                say(f"round {r + 1}/{rounds} done")
            done += count
        except BaseException:
            base.kill()
            cand.kill()
            raise
        finally:
            base.close()
            cand.close()
    for w in workloads:
        w.ratio = paired_ratio(w.baseline_s, w.candidate_s, w.blocks)
    conditions = {"clock": clock, "rounds": rounds, "blocks": blocks, "quick": quick, "seed": seed,
                  "min_sample_s": min_sample_s, "cpus": os.cpu_count(),
                  "load_before": load_before, "load_after": load_average(),
                  "seconds": round(time.perf_counter() - started, 1)}
    return Comparison({"command": baseline, **builds[0]}, {"command": candidate, **builds[1]},
                      threshold, workloads, unavailable, conditions)
