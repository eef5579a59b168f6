"""Compares two builds of tools/stage_costs.cpp stage by stage, their runs alternating.

A shared machine's speed can drift by half within an hour, so one build's run against the
other's an hour later says little. This runs A, B, A, B, ... `pairs` times (the same arguments) and
prints, for each build, the least and the median of its totals and the least of every stage:
a change shows in the stage it touches, the others should agree.

    g++ <flags of stage_costs.cpp's header> -I cpp/include tools/stage_costs.cpp -o /tmp/a
    g++ <the same> -I /tmp/changed/include tools/stage_costs.cpp -o /tmp/b
    python tools/stage_ab.py /tmp/a /tmp/b [8192 300 float64] [--pairs 12]

docs/performance.md ("Where the kernel's time goes") describes its use.
"""
from __future__ import annotations

import argparse
import re
import statistics
import subprocess

STAGES = ("gather", "exposure", "f50 start", "f50 solve", "scatter")


def parse(text: str) -> dict:
    """ns a point in all (`total`) and per stage from one stage_costs printout."""
    found = {"total": float(re.search(r"([0-9.]+) ns a point in all", text).group(1))}
    for name, value in re.findall(rf"^\s+({'|'.join(STAGES)})\s+(-?[0-9.]+) ns", text, re.M):
        found[name] = float(value)
    missing = [s for s in STAGES if s not in found]
    if missing:
        raise ValueError(f"stage_costs printed no {', '.join(missing)}:\n{text}")
    return found


def compare(binaries, pairs: int, args) -> dict:
    """{binary: {"totals": [ns, ...], stage: least ns}} over `pairs` alternating runs."""
    if pairs < 1:
        raise ValueError(f"pairs: must be >= 1, got {pairs}")
    if len(set(map(str, binaries))) != len(binaries):
        raise ValueError(f"binaries: must be different paths, got {binaries!r}")
    runs = {b: [] for b in binaries}
    for _ in range(pairs):
        for b in binaries:
            out = subprocess.run([str(b), *map(str, args)], check=True, capture_output=True,
                                 text=True).stdout
            runs[b].append(parse(out))
    return {b: {"totals": [r["total"] for r in rs],
                **{s: min(r[s] for r in rs) for s in STAGES}} for b, rs in runs.items()}


def report(results: dict) -> str:
    lines = []
    for b, r in results.items():
        stages = "  ".join(f"{s} {r[s]:.2f}" for s in STAGES)
        lines.append(f"{b}: total least {min(r['totals']):.2f} median "
                     f"{statistics.median(r['totals']):.2f} ns; least by stage: {stages}")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--pairs", type=int, default=12)
    parser.add_argument("args", nargs="*", default=["8192", "300", "float64"],
                        help="stage_costs' arguments: points, rounds, precision")
    options = parser.parse_args(argv)
    print(report(compare((options.a, options.b), options.pairs, options.args)))


if __name__ == "__main__":
    main()
