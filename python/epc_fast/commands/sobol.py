"""``epc-fast sobol [CONFIG.toml]``: the Sobol' indices of a scan config's space alone.

The config's ``[sobol]`` table (:mod:`epc_fast.scan.config.indices`; its defaults when there is
none) says how; its ``[reductions]`` are not run. The indices go into ``--out`` as sobol.csv
and sobol.md under the scan's output policy (:class:`epc_fast.scan.output.OutputDirectory`):
checked before any evaluation, every file written atomically. ``epc-fast scan`` writes the same
two files after a scan whose config has a ``[sobol]`` table.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

from . import add_output_arguments, duration, whole

NAME = "sobol"
HELP = ("apportion the variance of EPC among a scan config's random parameters: Sobol' "
        "indices (its [sobol] table; the sensitivity extra) in sobol.csv and sobol.md")


def _power_of_two(text: str) -> int:
    """An argparse type: a power of 2 in [16, 2^23], in digits (``4096``)."""
    from ..scan.indices import MAX_BOOTSTRAP_VALUES, MIN_POINTS

    value = int(text) if text.isdigit() else 0
    if value < MIN_POINTS or value > MAX_BOOTSTRAP_VALUES or value & (value - 1):
        raise argparse.ArgumentTypeError(f"--points {text!r}: expected a power of 2 between "
                                         f"{MIN_POINTS} and {MAX_BOOTSTRAP_VALUES:,}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..api import MAX_THREADS

    parser.add_argument("config", nargs="?", help="TOML scan config (see "
                        "examples/scan_designs.toml); default: the built-in one")
    add_output_arguments(parser, "epc-sobol", "sobol.csv and sobol.md")
    parser.add_argument("--points", type=_power_of_two,
                        help="override [sobol] points: base points of Saltelli's design")
    parser.add_argument("--seed", type=whole("--seed", 0, 2**64 - 1),
                        help="override [sobol] seed")
    parser.add_argument("--threads", type=whole("--threads", 1, MAX_THREADS),
                        help="core threads (default: [scan] threads, OMP_NUM_THREADS or every "
                        "core)")
    parser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an error")


def settings(config, points=None, seed=None):
    """The config's :class:`~epc_fast.scan.config.indices.SobolConfig` (its defaults, seeded with
    the scan's seed, when it has no ``[sobol]`` table), with the command line's overrides,
    checked against its space."""
    from ..scan.config.indices import SobolConfig

    sobol = config.sobol or SobolConfig(seed=config.seed)
    overrides = {k: v for k, v in (("points", points), ("seed", seed)) if v is not None}
    return dataclasses.replace(sobol, **overrides).check(config.space)


def compute(config, sobol, threads, command: str = NAME):
    """The indices and their wall time in seconds. The arguments are checked already: a
    ValueError here is the space's (points that are not OK, an output without variance), a
    ConfigError naming [sobol] of ``command``'s config."""
    from ..jobs.errors import ConfigError
    from ..scan.indices import sobol_indices

    start = time.perf_counter()
    try:
        result = sobol_indices(config.space, **sobol.kwargs(), threads=threads)
    except ValueError as error:
        raise ConfigError(f"{command} config [sobol]: {error}") from None
    return result, time.perf_counter() - start


def report(result, seconds: float) -> str:
    """The headline (with the wall time) and the table, as printed."""
    return f"{result.headline()}: {duration(seconds)}\n{result.markdown()}"


def write_indices(out, result) -> None:
    """sobol.csv (full precision) and sobol.md (the headline and the table), atomically."""
    from ..jobs import table_formats

    columns = result.table()
    out.write("sobol.csv", lambda path: table_formats.write_csv(path, columns))
    out.write("sobol.md", lambda path: path.write_text(
        f"{result.headline()}\n\n{table_formats.markdown(columns)}\n", encoding="utf-8"))


def run(args) -> int:
    from .._validation import threads_of
    from ..jobs.extras import SENSITIVITY, check_extras
    from ..jobs.output import OutputDirectory
    from ..jobs.schema import config_of
    from ..jobs.signals import SignalsHeld
    from ..scan.config import default_config, load_config
    from ..scan.config.indices import SOBOL_FILES

    with config_of(NAME):
        config = load_config(args.config, NAME) if args.config else default_config(NAME)
        sobol = settings(config, args.points, args.seed)
    threads = threads_of(args.threads or config.threads)  # before anything is written
    check_extras([(SENSITIVITY, "Sobol' indices", "")])
    with OutputDirectory(args.out, overwrite=args.overwrite) as out:
        out.prepare(dict.fromkeys(SOBOL_FILES, "the Sobol' indices"))
        result, seconds = compute(config, sobol, threads)
        print(report(result, seconds))
        with SignalsHeld() as writing:  # SIGINT and SIGTERM wait for both files
            write_indices(out, result)
        for name in out.written:
            print(f"wrote {out.path / name}")
        return writing.exit_code("epc-fast sobol")
