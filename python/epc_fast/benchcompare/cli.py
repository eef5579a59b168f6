"""The arguments and runs of ``epc-fast bench compare``, ``bench counts`` and
``bench accuracy`` (wired into ``epc-fast bench`` by :mod:`epc_fast.commands.bench`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .compare import FULL, QUICK, THRESHOLD
from .sides import TIMEOUT
from .worker import WORKLOADS


def _percent(name: str):
    """An argparse type: a percentage in (0, 100), returned as a fraction."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not 0 < value < 100:
            raise argparse.ArgumentTypeError(f"{name} {text!r}: expected a percentage "
                                             f"between 0 and 100 (exclusive), e.g. 5")
        return value / 100
    return parse


def _positive_seconds(name: str):
    """An argparse type: a finite number of seconds above 0."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not 0 < value < float("inf"):
            raise argparse.ArgumentTypeError(f"{name} {text!r}: expected a number of seconds "
                                             f"above 0, e.g. 600")
        return value
    return parse


def _count(name: str, low: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low:
            raise argparse.ArgumentTypeError(f"{name} {text!r}: expected a whole number >= {low}")
        return value
    return parse


def add_compare(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("sides", nargs="+", metavar="SIDE",
                        help="BASELINE CANDIDATE: each a command line (one argument, split as a "
                        "shell would) that starts a Python with epc_fast installed, e.g. "
                        "'venv/bin/python' or 'env EPC_FAST_ISA=x86-64 python3'; with --ref, "
                        "only CANDIDATE")
    parser.add_argument("--ref", metavar="GIT_REF", default=None,
                        help="the baseline: this commit of --repo, built once into a cached "
                        "venv (~/.cache/epc_fast/bench-ref/COMMIT)")
    parser.add_argument("--repo", type=Path, default=Path("."),
                        help="the git checkout --ref is read from (default: .)")
    parser.add_argument("--quick", action="store_true",
                        help="the short set: smaller workloads, no 10^7 points "
                        "(under a minute on a quiet 2-core machine)")
    parser.add_argument("--rounds", type=_count("--rounds", 3), default=None,
                        help=f"paired rounds (default {FULL[0]}, --quick {QUICK[0]})")
    parser.add_argument("--blocks", type=_count("--blocks", 1), default=None,
                        help=f"blocks of rounds, each in new worker processes (default "
                        f"{FULL[1]}, --quick {QUICK[1]})")
    parser.add_argument("--threshold", type=_percent("--threshold"), default=THRESHOLD, metavar="PERCENT",
                        help=f"fail (exit 1) when a slowdown beyond this is significant "
                        f"(default {THRESHOLD * 100:.0f}%%)")
    parser.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                        help="time a sample by the process's CPU time, all its threads, "
                        "which waiting for a core on a busy machine does not add to (default), "
                        "or by wall time")
    parser.add_argument("--only", action="append", choices=list(WORKLOADS), default=None,
                        help="compare only this workload (repeatable)")
    parser.add_argument("--timeout", type=_positive_seconds("--timeout"), default=TIMEOUT,
                        metavar="SECONDS",
                        help=f"seconds a side may take to answer one request (a block's "
                        f"setup: its designs drawn and each workload run twice; or one "
                        f"sample of a round) before it is killed, its whole process group "
                        f"with it, and the comparison fails naming it (default {TIMEOUT:g})")
    parser.add_argument("--out", type=Path, default=Path("bench-compare"),
                        help="folder for compare.md and compare.json, checked before the first "
                        "round and created if missing; each report is written whole or not at "
                        "all (default: bench-compare)")


def _progress(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def _check_sides(args) -> None:
    """A UsageError for the wrong number of SIDEs or one that is not a command line."""
    from ..jobs.errors import UsageError
    from .sides import split_command

    if args.ref is not None and len(args.sides) != 1:
        raise UsageError(f"with --ref {args.ref}, expected one SIDE (the candidate), got "
                         f"{len(args.sides)}: {args.sides}")
    if args.ref is None and len(args.sides) != 2:
        raise UsageError(f"expected two SIDEs, BASELINE and CANDIDATE, got {len(args.sides)}: "
                         f"{args.sides}")
    names = ("CANDIDATE",) if args.ref is not None else ("BASELINE", "CANDIDATE")
    for name, text in zip(names, args.sides):
        try:
            split_command(text, name)
        except ValueError as exc:
            raise UsageError(str(exc)) from None


def _sides(args) -> tuple[str, str]:
    """The command lines of BASELINE (with --ref, the Python of its build) and CANDIDATE."""
    if args.ref is None:
        return args.sides[0], args.sides[1]
    from .refbuild import ref_python

    return ref_python(args.repo, args.ref, progress=_progress), args.sides[0]


def run_compare(args) -> int:
    from .compare import run_comparison
    from .report import check_out, markdown, write_reports

    _check_sides(args)
    check_out(args.out)  # before --ref's build and the first round
    baseline, candidate = _sides(args)
    comparison = run_comparison(baseline, candidate, quick=args.quick, rounds=args.rounds,
                                blocks=args.blocks, threshold=args.threshold, clock=args.clock,
                                only=args.only, progress=_progress, timeout=args.timeout)
    text = markdown(comparison)
    print(text)
    written = write_reports(args.out, comparison, text)
    print(f"wrote {' and '.join(str(path) for path in written)}")
    return 1 if comparison.failed else 0


def _python_argument(parser) -> None:
    parser.add_argument("--python", default=None, metavar="COMMAND",
                        help="the install measured: a command line that starts its Python "
                        "(default: the Python running this)")
    parser.add_argument("--baselines", type=Path, default=Path("bench") / "baselines",
                        help="the committed tables' folder (default: bench/baselines)")
    parser.add_argument("--update", action="store_true",
                        help="write the tables measured into --baselines instead of checking")


def add_counts(parser: argparse.ArgumentParser) -> None:
    from .counts import COUNTED, DEFAULT_ISAS, PER_CALL, TOLERANCE

    _python_argument(parser)
    parser.add_argument("--isa", action="append", default=None,
                        choices=("x86-64", "x86-64-v3", "x86-64-v4"),
                        help=f"a build counted (repeatable; default: {', '.join(DEFAULT_ISAS)})")
    parser.add_argument("--tolerance", type=_percent("--tolerance"), default=TOLERANCE, metavar="PERCENT",
                        help=f"fail (exit 1) when a count (a point's, or a call's) rises by more "
                        f"than this (default {TOLERANCE * 100:.0f}%%)")
    parser.add_argument("--only", action="append", choices=[*COUNTED, *PER_CALL], default=None,
                        help="count only this workload (repeatable; call: a call's fixed cost)")


def add_accuracy(parser: argparse.ArgumentParser) -> None:
    _python_argument(parser)
    parser.add_argument("--repo", type=Path, default=Path("."),
                        help="the source checkout whose tools/ make the tables (default: .)")


def run_counts(args) -> int:
    import json

    from .counts import (DEFAULT_ISAS, NO_COUNTER, PER_CALL, compare_counts, count_per_point,
                         counter)
    from .sides import this_python

    tool = counter()
    if tool is None:
        raise RuntimeError(NO_COUNTER)
    python = args.python or this_python()
    failed = False
    for isa in args.isa or DEFAULT_ISAS:
        measured = count_per_point(python, isa, tool, args.only, progress=_progress)
        path = args.baselines / "counts" / f"{measured['isa']}.json"
        if args.update:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(measured, indent=1) + "\n")
            print(f"{isa}: wrote {path}")
            continue
        table = json.loads(path.read_text()) if path.exists() else {}
        print(f"{isa}: instructions a point, and a call for "
              f"{', '.join(PER_CALL)} ({tool}), against {path}")
        print("| workload | committed | measured | ratio | verdict |\n|---|---:|---:|---:|---|")
        for name, old, new, ratio, verdict in compare_counts(measured, table, args.tolerance):
            failed |= verdict == "MORE"
            print(f"| {name} | {old if old is not None else '-'} | {new} | "
                  f"{f'{ratio:.4f}' if ratio is not None else '-'} | {verdict} |")
    if not args.update:
        print("FAIL: a count rose beyond the tolerance" if failed else
              f"PASS: no count rose by more than {args.tolerance:.0%}")
    return 1 if failed else 0


def run_accuracy(args) -> int:
    from .accuracy import check
    from .sides import this_python

    equal, report = check(args.python or this_python(), args.repo,
                          args.baselines / "accuracy", update=args.update, progress=_progress)
    print("\n".join(report))
    if not args.update:
        print("PASS: the outputs and errors are the committed ones" if equal else
              "FAIL: the outputs or errors differ from the committed ones")
    return 0 if equal else 1
