"""``epc-fast optimize CONFIG.toml``: the design parameters that maximise an objective of EPC
over a scene distribution, with their Monte Carlo uncertainty, and the objective's curve.

Everything goes into ``--out`` under the scan's output policy
(:class:`epc_fast.scan.output.OutputDirectory`: checked before the first draw, refused when
not empty unless ``--overwrite``, every file written atomically): ``optimum.json`` (the result
and the config), ``optimum.md`` (a table), ``curve.csv`` (the objective along each parameter,
the others at the optimum) and ``curve.png`` (the same, with its band and the optimum).
"""

from __future__ import annotations

import argparse
import csv
import json

from . import add_output_arguments, duration, whole

NAME = "optimize"
HELP = ("maximise an objective of EPC (mean, quantile, probability) over design parameters "
        "from a TOML config (see examples/optimize_pitch.toml); write the optimum with its "
        "uncertainty (JSON, Markdown) and the objective's curve (CSV, PNG)")
#: The files the command writes, and what each holds.
FILES = {"optimum.json": "the optimum, its uncertainty and the config",
         "optimum.md": "the optimum as a table",
         "curve.csv": "the objective along each optimised parameter",
         "curve.png": "the objective's curve with its band and the optimum"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..api import MAX_THREADS
    from ..optimize.config import MAX_OPTIMIZE_POINTS

    parser.add_argument("config", help="TOML file (see examples/optimize_pitch.toml)")
    add_output_arguments(parser, "epc-optimize", "the files this command writes")
    parser.add_argument("--points", type=whole("--points", 1, MAX_OPTIMIZE_POINTS),
                        help="override [optimize] points (1e7 is accepted)")
    parser.add_argument("--seed", type=whole("--seed", 0, 2**64 - 1),
                        help="override [optimize] seed")
    parser.add_argument("--threads", type=whole("--threads", 1, MAX_THREADS),
                        help="core threads")
    parser.add_argument("--no-plot", action="store_true", help="skip curve.png")
    parser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an error")


def _config(args):
    from ..optimize.config import load_optimize_config

    config = load_optimize_config(args.config)
    for name in ("points", "seed", "threads"):
        if getattr(args, name) is not None:
            setattr(config, name, getattr(args, name))
    return config


def _write_curves(path, curves) -> None:
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["parameter", "value", "objective", "standard_error"])
        for curve in curves:
            for row in zip(curve.values, curve.objective, curve.standard_error):
                writer.writerow([curve.parameter] + [repr(float(v)) for v in row])


def _document(optimum, config) -> dict:
    from .. import __version__, _core

    return {"format": "epc_fast optimum 1", "epc_fast_version": __version__,
            "core_isa": _core.isa, "config_source": config.source, "config": config.text,
            **optimum.as_dict()}


def run(args) -> int:
    import numpy as np

    from .._validation import threads_of
    from ..optimize import Problem
    from ..jobs.extras import OPTIMIZE, PLOT, check_extras
    from ..jobs.output import OutputDirectory
    from ..jobs.signals import SignalsHeld

    config = _config(args)
    threads_of(config.threads)  # the threads (or OMP_NUM_THREADS), before anything is written
    plot = not args.no_plot
    check_extras([(OPTIMIZE, "the optimiser", "")]
                 + [(PLOT, "the optimiser's curve plot", "--no-plot")] * plot)
    if plot:
        from ..optimize.plot import curve_figure
        from ..plotting import save_figure
        from ..plotting.common import space_conditions
    with OutputDirectory(args.out, overwrite=args.overwrite) as out:
        out.prepare({name: what for name, what in FILES.items() if plot or name != "curve.png"})
        problem = Problem(**config.problem_kwargs())
        optimum = problem.maximize(**config.search_kwargs())
        curves = [problem.curve(name, np.linspace(low, high, config.curve_points), at=optimum.x)
                  for name, (low, high) in config.bounds.items()]
        print(f"optimum of {optimum.objective.label} over {optimum.points:,} draws "
              f"({config.source}), seed {optimum.seed}: {duration(optimum.wall_s)}, "
              f"{optimum.evaluations} candidates on every draw, {optimum.batch_evaluations} on "
              f"{optimum.batches} batches")
        print(problem.describe())
        print()
        print(optimum.markdown())
        text = json.dumps(_document(optimum, config), indent=1) + "\n"
        with SignalsHeld() as writing:  # SIGINT and SIGTERM wait for every file
            out.write("optimum.json", lambda path: path.write_text(text, encoding="utf-8"))
            out.write("optimum.md", lambda path: path.write_text(optimum.markdown() + "\n",
                                                                 encoding="utf-8"))
            out.write("curve.csv", lambda path: _write_curves(path, curves))
            if plot:
                figure = curve_figure(curves, optimum, conditions=space_conditions(
                    problem.space, points=optimum.points, seed=optimum.seed,
                    skip=tuple(config.bounds), extra=[f"Objective: {optimum.objective.label}, "
                                                      f"held: {optimum.held}"]))
                out.write("curve.png", lambda path: save_figure(figure, path, dpi=120,
                                                                file_format="png"))
        print()
        for name in out.written:
            print(f"wrote {out.path / name}")
        return writing.exit_code("epc-fast optimize")
