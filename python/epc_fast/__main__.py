"""Command line: ``epc-fast`` or ``python -m epc_fast``.

With no sub-command it runs the main job on built-in defaults: it prints the build
(:func:`epc_fast.build_info`: version, core level, OpenMP, threads), checks the core against the NumPy reference on random points, and evaluates
the paper's 1/3.2" designs over illuminance. Sub-commands live in :mod:`epc_fast.commands`.

An error ends the command with one line on stderr, ``epc-fast COMMAND: error: ...``, and exit
code 2 for a usage error (a config, an option, an output directory) or 1 for any other;
``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from . import __version__, build_info, evaluate
from .commands import discover
from .commands.scan import print_default_scan
from .presets import HIGH_TIER
from .selfcheck import self_check

ILLUMINANCES_LUX = (100.0, 300.0, 1000.0, 3000.0, 10000.0, 100000.0)
#: The usage text's description, plain text as argparse prints it.
DESCRIPTION = ("The effective pixel count (EPC) of camera designs. With no command: the build, "
               "a self-check against the NumPy reference, the paper's 1/3.2\" designs over "
               "illuminance and a default scan.")


def _info() -> None:
    print(build_info())


class _Version(argparse.Action):
    """``--version``: the version, then the loaded build in one line (the core loaded only
    when asked)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="print the version and the loaded build (core level, OpenMP, threads)"):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"epc_fast {__version__}")
        print(build_info().core_text())
        parser.exit()


def _design_table() -> None:
    lux = np.asarray(ILLUMINANCES_LUX)
    print('\nEPC in pixels of the paper\'s 1/3.2" designs (30 dB met at the image corner, '
          f'{HIGH_TIER[0].field_angle_deg:.2f} deg):')
    print(f"{'design':<16}{'pixels':>11}" + "".join(f"{x:>11,g}" for x in lux) + "  lux")
    for design in HIGH_TIER:
        epc = evaluate(lux, **design.evaluate_kwargs()).epc
        print(f"{design.name:<16}{design.pixel_count:>11,.0f}"
              + "".join(f"{e:>11,.0f}" for e in epc))


def main_job(args) -> int:
    """The default run: build info, self-check, the paper's design table, a default scan."""
    _info()
    report = self_check(args.check_points)
    print(report.summary())
    _design_table()
    print_default_scan()
    return 0 if report.passed else 1


def build_parser(commands: dict) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="epc-fast", description=DESCRIPTION)
    parser.add_argument("--version", action=_Version)
    parser.add_argument("--check-points", type=int, default=20000,
                        help="random points for the core-vs-reference self-check (main job)")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, module in commands.items():
        module.add_arguments(sub.add_parser(name, help=module.HELP, description=module.HELP))
    return parser


def _one_line(error: BaseException) -> str:
    """The error's message on one line; its type's name when the message is empty or the
    error is not one of the package's usage errors."""
    from .jobs.errors import UsageError

    text = " ".join(str(error).split())
    if isinstance(error, UsageError):
        return text
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


def main(argv=None) -> int:
    commands = discover()
    args = build_parser(commands).parse_args(argv)
    prog = "epc-fast" + (f" {args.command}" if args.command else "")
    try:
        if args.command is None:
            return main_job(args)
        return commands[args.command].run(args)
    except KeyboardInterrupt:
        if args.debug:
            raise
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except Exception as error:
        from .jobs.errors import UsageError

        if args.debug:
            raise
        print(f"{prog}: error: {_one_line(error)}", file=sys.stderr)
        return 2 if isinstance(error, UsageError) else 1


if __name__ == "__main__":
    sys.exit(main())
