"""``epc-fast paper --out DIR``: the paper's three figures, what limits each of their designs,
and the paper's statements table; with ``--simulate``, the statements also checked on simulated
captures."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

NAME = "paper"
HELP = ("reproduce the paper (Xiao et al., SPIE 7250, 2009): fig1-3.png, what limits each "
        "design in fig1-3_limits.png, statements.csv and statements.md (with --simulate, the "
        "statements also checked on simulated captures)")
#: What ``epc-fast paper`` prints when it does not simulate: what it skipped and how to run it.
SKIPPED = ("  not checked on simulated captures: add --simulate to check them as the paper "
           "did (about 20 s)")


def add_arguments(parser) -> None:
    parser.add_argument("--out", type=Path, default=Path("figures"),
                        help="folder to write into, created if missing (default: figures)")
    parser.add_argument("--backend", choices=("core", "reference"), default="core",
                        help="the compiled core or the NumPy reference (default: core)")
    from ..api import MAX_THREADS
    from . import whole

    parser.add_argument("--threads", type=whole("--threads", 1, MAX_THREADS), default=None,
                        help="core threads (default: OMP_NUM_THREADS or every core)")
    parser.add_argument("--simulate", action=argparse.BooleanOptionalAction, default=False,
                        help="also check the statements on simulated captures, as the paper "
                             "did (about 20 s; default: --no-simulate)")


def run(args) -> int:
    from ..paper import FIGURES, markdown_table, simulated_markdown_table, statements, write_csv

    args.out.mkdir(parents=True, exist_ok=True)
    table = statements(backend=args.backend, threads=args.threads, simulate=args.simulate)
    write_csv(table, args.out / "statements.csv")
    text = markdown_table(table)
    if args.simulate:
        text += "\nChecked on simulated captures:\n\n" + simulated_markdown_table(table)
    else:
        text += "\nNot checked on simulated captures: `epc-fast paper --simulate` checks them.\n"
    (args.out / "statements.md").write_text(text, encoding="utf-8")
    held = [s for s in table if s.holds is not None]
    print(f"{args.out / 'statements.csv'}: {len(table)} statements, "
          f"{sum(s.holds for s in held)} of {len(held)} with a paper value hold")
    for s in held:
        if not s.holds:
            print(f"  does not hold: {s.id} ({s.kind}), deviation {s.deviation:+.1%}")
    if args.simulate:
        checked = [s for s in table if s.simulated_holds is not None]
        print(f"  on simulated captures: {sum(s.simulated_holds for s in checked)} of "
              f"{len(checked)} with a paper value hold")
    else:
        print(SKIPPED)

    try:
        from ..plotting import (plot_epc_over_illuminance, plot_limits_over_illuminance,
                                save_figure)

        options = dict(backend=args.backend, threads=args.threads)
        for figure in FIGURES:
            epc = plot_epc_over_illuminance(figure.designs, title=figure.title, **options)
            limits = plot_limits_over_illuminance(figure.designs, title=figure.limits_title,
                                                  **options)
            for name, drawn in ((figure.name, epc), (figure.limits_name, limits)):
                path = args.out / f"{name}.png"
                save_figure(drawn, path)
                print(path)
    except ImportError as exc:
        print(f"epc-fast paper: {exc}", file=sys.stderr)
        return 1
    return 0
