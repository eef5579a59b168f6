"""A Markdown table per benchmark group from a pytest-benchmark JSON file.

    python bench/report.py                       # the committed baseline (bench/baselines)
    python bench/report.py run.json [more.json]  # --benchmark-json=run.json or a saved run

Columns: the benchmark's name, its median in seconds, the points it evaluated per round, its
throughput (M points/s = points / median), its throughput over that of the NumPy reference and
of the Numba peer in the same group (the ratios are of points/s, so that a peer run on a
subsample, such as the reference at 10^7, compares fairly), and the largest relative error of
f50 and EPC against the reference that the benchmark's own check found, as it is and divided
by the point's condition number kappa (engine_suite.blur_condition: the check's tolerance is
rtol times kappa). Points and errors come
from each benchmark's extra_info (engine_suite.py); a group without ``points`` (the scan and
terms suites) gets its medians only, against the fastest of the group.

A paired benchmark (engine_suite.bench_paired: two calls taken in turn, round by round) is
not a row: below its group's table, a second table gives each pair's two medians and the
speed-up of the first over the second per round (median, least and greatest).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

BASELINES = Path(__file__).resolve().parent / "baselines"


def _peer(bench: dict) -> str | None:
    peer = bench.get("extra_info", {}).get("peer")
    if peer:
        return peer
    name = bench["name"].lower()
    return next((p for p in ("reference", "numba") if p in name), None)


def _throughput(bench: dict) -> float | None:
    points = bench.get("extra_info", {}).get("points")
    median = bench["stats"]["median"]
    return points / median if points and median > 0 else None


def _seconds(value: float) -> str:
    return f"{value:.3g}" if value >= 1e-3 else f"{value:.2e}"


def _ratio(mine: float | None, theirs: float | None) -> str:
    if mine is None or theirs is None:
        return "—"
    ratio = mine / theirs
    return f"{ratio:.3g}×" if ratio < 100 else f"{ratio:,.0f}×"


def group_table(benchmarks: list) -> str:
    """One group's rows, fastest first, as Markdown."""
    by_peer = {}
    for bench in benchmarks:
        by_peer.setdefault(_peer(bench), bench)
    reference, numba = by_peer.get("reference"), by_peer.get("numba")
    same = by_peer.get("numba_same_algorithm")
    ref_rate = _throughput(reference) if reference else None
    numba_rate = _throughput(numba) if numba else None
    same_rate = _throughput(same) if same else None

    rows = ["| name | median (s) | points | M points/s | vs reference | vs numba "
            "| vs numba, same algorithm | max rel. error | max rel. error / κ |",
            "|---|---|---|---|---|---|---|---|---|"]
    ordered = sorted(benchmarks, key=lambda b: -(_throughput(b) or 1.0 / b["stats"]["median"]))
    for bench in ordered:
        info = bench.get("extra_info", {})
        rate = _throughput(bench)
        points = info.get("points")
        points_text = f"{points:,}" if points else "—"
        if info.get("scaled"):
            points_text += f" (of {info['of_points']:,})"
        error = info.get("max_rel_error")
        scaled = info.get("max_rel_error_per_condition")
        rows.append("| {} | {} | {} | {} | {} | {} | {} | {} | {} |".format(
            bench["name"], _seconds(bench["stats"]["median"]), points_text,
            f"{rate / 1e6:.3g}" if rate else "—",
            _ratio(rate, ref_rate), _ratio(rate, numba_rate), _ratio(rate, same_rate),
            f"{error:.1e}" if error is not None else "—",
            f"{scaled:.1e}" if scaled is not None else "—"))
    return "\n".join(rows)


def _paired(bench: dict) -> bool:
    return bool(bench.get("extra_info", {}).get("paired"))


def paired_table(benchmarks: list) -> str:
    """The paired benchmarks of a group: both sides' M points/s and the per-round speed-up."""
    rows = ["| pair, taken in turn | rounds | first: M points/s | second: M points/s "
            "| speed-up per round: median | least | greatest |",
            "|---|---|---|---|---|---|---|"]
    for bench in benchmarks:
        info = bench["extra_info"]
        if "speedup_median" not in info:  # benchmarks disabled: no timing
            continue
        rows.append("| {} vs {} | {} | {:.3g} | {:.3g} | {:.3g}× | {:.3g}× | {:.3g}× |".format(
            info["first"], info["second"], info["paired_rounds"],
            info["first_points_per_s"] / 1e6, info["second_points_per_s"] / 1e6,
            info["speedup_median"], info["speedup_min"], info["speedup_max"]))
    return "\n".join(rows)


def plain_table(benchmarks: list) -> str:
    """A group without points (scan, terms): medians, against the fastest."""
    fastest = min(b["stats"]["median"] for b in benchmarks)
    rows = ["| name | median (s) | vs fastest |", "|---|---|---|"]
    for bench in sorted(benchmarks, key=lambda b: b["stats"]["median"]):
        median = bench["stats"]["median"]
        rows.append(f"| {bench['name']} | {_seconds(median)} | {median / fastest:.3g}× |")
    return "\n".join(rows)


def report(data: dict) -> str:
    groups = {}
    for bench in data["benchmarks"]:
        groups.setdefault(bench.get("group") or "(no group)", []).append(bench)
    machine = data.get("machine_info", {})
    commit = data.get("commit_info", {})
    lines = [f"Run of {data.get('datetime', '?')}: {machine.get('cpu', {}).get('brand_raw', '?')}, "
             f"Python {machine.get('python_version', '?')}, "
             f"epc_fast core {machine.get('epc_fast_isa', '?')}, "
             f"commit {str(commit.get('id', '?'))[:10]}{' (dirty)' if commit.get('dirty') else ''}"]
    for name, benchmarks in groups.items():
        paired = [b for b in benchmarks if _paired(b)]
        single = [b for b in benchmarks if not _paired(b)]
        lines += ["", f"### {name}"]
        if single:
            has_points = any(_throughput(b) for b in single)
            lines += ["", group_table(single) if has_points else plain_table(single)]
        if paired:
            lines += ["", paired_table(paired)]
    return "\n".join(lines)


def _default_files() -> list:
    files = sorted(BASELINES.glob("*/*.json"), key=lambda p: p.stat().st_mtime)
    return files[-1:]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", type=Path,
                        help="pytest-benchmark JSON files (default: the newest baseline)")
    args = parser.parse_args(argv)
    files = args.files or _default_files()
    if not files:
        parser.error(f"no JSON given and none in {BASELINES}")
    for i, path in enumerate(files):
        if len(files) > 1:
            print(("\n" if i else "") + f"## {path}\n")
        print(report(json.loads(path.read_text(encoding="utf8"))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
