"""``epc-fast bench --out DIR``: speed against accuracy of the engine's knobs; ``epc-fast bench
compare BASELINE CANDIDATE``: a paired timing of two installs; ``bench counts`` and ``bench
accuracy``: instruction counts and accuracy tables against committed ones
(:mod:`epc_fast.benchcompare`).

Each setting of :func:`epc_fast.tradeoff.default_settings` (solvers, tolerances, precision,
spectral samples) is measured for the relative error of f50 against the NumPy reference and
for points/s on 1 and 2 threads; the table is printed and written as trade.md and trade.csv,
with trade.png (points/s against error, the Pareto front drawn).
"""

from __future__ import annotations

import argparse
import fnmatch
import os
import sys
from pathlib import Path

NAME = "bench"
HELP = ("speed against accuracy: f50 error (vs the NumPy reference) and points/s of each "
        "solver, tolerance, precision and spectral setting; trade.md, trade.csv, trade.png")

COMPARE_HELP = ("a paired comparison of two installs: the same workloads in both, in "
                "alternating rounds; each one's time ratio with a 95 percent interval; exit 1 "
                "when a slowdown beyond the threshold is significant")

COUNTS_HELP = ("instructions a point of each workload (perf or valgrind), against the "
               "committed table of each build; exit 1 when one rose by more than the tolerance")
ACCURACY_HELP = ("errors against mpmath and a digest of evaluate's outputs per build, against "
                 "the committed tables; exit 1 with the difference when either changed")

#: (throughput points, rounds, error points): the full run and --quick.
FULL = (1_000_000, 3, 100_000)
QUICK = (20_000, 1, 5_000)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=Path("bench-results"),
                        help="folder to write into, created if missing (default: bench-results)")
    parser.add_argument("--quick", action="store_true",
                        help=f"a smoke run: {QUICK[0]:,} timed points, {QUICK[1]} round, "
                        f"{QUICK[2]:,} compared with the reference")
    parser.add_argument("--points", type=float, default=None,
                        help=f"random designs timed (default: {FULL[0]:,})")
    parser.add_argument("--rounds", type=int, default=None,
                        help=f"timed rounds per thread count, after one warm-up; their median "
                        f"counts (default: {FULL[1]})")
    parser.add_argument("--error-points", type=float, default=None,
                        help=f"random designs compared with the reference (default: "
                        f"{FULL[2]:,}; the reference takes ~1 s per 10^5)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random designs")
    parser.add_argument("--only", action="append", metavar="PATTERN", default=None,
                        help="measure only settings whose name matches this shell pattern "
                        "(repeatable; 'default' is always measured, the speed-ups' base)")
    parser.add_argument("--no-plot", action="store_true", help="skip trade.png")
    from ..benchcompare import cli

    sub = parser.add_subparsers(dest="bench_command", metavar="SUBCOMMAND")
    cli.add_compare(sub.add_parser("compare", help=COMPARE_HELP, description=COMPARE_HELP))
    cli.add_counts(sub.add_parser("counts", help=COUNTS_HELP, description=COUNTS_HELP))
    cli.add_accuracy(sub.add_parser("accuracy", help=ACCURACY_HELP, description=ACCURACY_HELP))


def _sizes(args) -> tuple[int, int, int]:
    """(throughput points, rounds, error points): --quick or the full run, then overrides."""
    points, rounds, error_points = QUICK if args.quick else FULL
    if args.points is not None:
        points = int(args.points)
    if args.rounds is not None:
        rounds = args.rounds
    if args.error_points is not None:
        error_points = int(args.error_points)
    if points < 1 or rounds < 1 or error_points < 1:
        raise SystemExit("epc-fast bench: --points, --rounds and --error-points must be >= 1")
    return points, rounds, error_points


def _selected(settings, patterns):
    if not patterns:
        return list(settings)
    from ..tradeoff import BASELINE

    return [s for s in settings if s.name == BASELINE
            or any(fnmatch.fnmatchcase(s.name, p) for p in patterns)]


def _usable_settings(patterns) -> tuple[list, list[str]]:
    """The settings to measure, and a note for each one (or group) left out."""
    from ..tradeoff import default_settings, evaluate_parameters, rejection, split_by_knobs

    kept, skipped = split_by_knobs(_selected(default_settings(), patterns),
                                   evaluate_parameters())
    notes = []
    by_knobs = {}
    for setting, missing in skipped:
        by_knobs.setdefault(tuple(missing), []).append(setting.name)
    for missing, names in by_knobs.items():
        knobs = ", ".join(f"{k}=" for k in missing)
        notes.append(f"skipped (this build's evaluate() takes no {knobs}): {', '.join(names)}")
    usable = []
    for setting in kept:
        reason = rejection(setting)
        if reason is None:
            usable.append(setting)
        else:
            notes.append(f"skipped {setting.name} (evaluate() refuses it: {reason})")
    return usable, notes


def _header(points, rounds, error_points, seed) -> str:
    from .. import __version__, _core

    return (f"epc_fast {__version__} ({_core.isa}, OpenMP "
            f"{'on' if _core.openmp_enabled() else 'off'}): f50 error vs the NumPy reference "
            f"on {error_points:,} random designs; points/s on {points:,} random designs, "
            f"median of {rounds} round{'s' if rounds > 1 else ''} after a warm-up; seed {seed}")


#: Load average (1 min) per CPU above which the speeds are flagged as noisy.
BUSY_LOAD_PER_CPU = 0.25


def _load_average() -> float | None:
    """The 1-minute load average, None where the system does not say."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def _warnings(measurements, load_before) -> list[str]:
    """Status mismatches (there should be none), and a machine busy with other work before
    the run (the load average after it counts the run itself)."""
    lines = [f"WARNING: {m.setting.name}: {m.accuracy.status_mismatches:,} points' status "
             f"differs from the reference's (should be 0)"
             for m in measurements if m.accuracy.status_mismatches]
    cpus = os.cpu_count() or 1
    if load_before is not None and load_before > BUSY_LOAD_PER_CPU * cpus:
        lines.append(f"WARNING: the machine was busy before the run (1-minute load average "
                     f"{load_before:.2f} on {cpus} CPUs): the speeds are noisy, compare them "
                     f"only within one run")
    return lines


def _front_note(measurements, front) -> str:
    names = ", ".join(measurements[i].setting.name for i in front)
    return (f"* on the Pareto front ({names}): no other monochromatic setting has both a "
            f"max error as small and as many points/s on 2 threads, and one of them better "
            f"(polychromatic settings solve another model and are left out)")


def _progress(line: str) -> None:
    sys.stdout.flush()
    print(line, file=sys.stderr, flush=True)


def _write_plot(measurements, front, path: Path, title: str, conditions=None) -> bool:
    from ..plotting import save_figure
    from ..tradeoff import plot_tradeoff

    try:
        figure = plot_tradeoff(measurements, front, title=title, conditions=conditions)
    except ImportError as exc:
        print(f"no plot: {exc}")
        return False
    save_figure(figure, path)
    return True


def run(args) -> int:
    from ..benchcompare import cli

    runs = {"compare": cli.run_compare, "counts": cli.run_counts, "accuracy": cli.run_accuracy}
    return runs.get(getattr(args, "bench_command", None), run_tradeoff)(args)


def run_tradeoff(args) -> int:
    from .. import __version__
    from ..jobs.table_formats import markdown, write_csv
    from ..tradeoff import csv_columns, front_of, markdown_columns, measure

    load_before = _load_average()
    points, rounds, error_points = _sizes(args)
    settings, notes = _usable_settings(args.only)
    header = _header(points, rounds, error_points, args.seed)
    print(header)
    for note in notes:
        print(note)
    measurements = measure(settings, throughput_points=points, error_points=error_points,
                           rounds=rounds, seed=args.seed, progress=_progress)
    front = front_of(measurements)
    table = markdown(markdown_columns(measurements, front))
    footer = [_front_note(measurements, front), *_warnings(measurements, load_before)]
    print()
    print(table)
    print()
    for line in footer:
        print(line)

    args.out.mkdir(parents=True, exist_ok=True)
    md = args.out / "trade.md"
    md.write_text("\n\n".join([header, *notes, table, *footer]) + "\n", encoding="utf-8")
    write_csv(args.out / "trade.csv", csv_columns(measurements, front))
    written = [md, args.out / "trade.csv"]
    from .. import _core

    # the build and the CPUs name what the speeds were measured on
    title = (f"epc_fast {__version__} on {_core.isa}, {os.cpu_count()} CPUs: speed against "
             f"accuracy (f50 error on {error_points:,} points, speed on {points:,})")
    from ..plotting.common import conditions_lines

    conditions = conditions_lines(
        scene=f"random designs: f50 error on {error_points:,}, speed on {points:,}, median of "
              f"{rounds} round{'s' if rounds > 1 else ''} after a warm-up",
        seed=args.seed, extra=[f"{os.cpu_count()} CPUs, OpenMP "
                               f"{'on' if _core.openmp_enabled() else 'off'}"])
    if not args.no_plot and _write_plot(measurements, front, args.out / "trade.png", title,
                                        conditions):
        written.append(args.out / "trade.png")
    for path in written:
        print(f"wrote {path}")
    return 0
