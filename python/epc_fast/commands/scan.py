"""``epc-fast scan [CONFIG.toml]``: a design-space scan, its summary table and plots."""

from __future__ import annotations

import argparse
from pathlib import Path

NAME = "scan"
HELP = ("scan a design space from a TOML config (default: the built-in one) and write its "
        "summary table (CSV, markdown) and plots")

#: Tables with more rows than this are written to files only.
MAX_PRINTED_ROWS = 24
#: Points of the default scan the main job runs.
MAIN_JOB_POINTS = 200_000
#: Columns of the main job's compact table: EPC columns are shown in megapixels.
MAIN_JOB_EPC_COLUMNS = ("mean", "q5", "q50", "q95")
MAIN_JOB_FRACTION_COLUMN = "P(epc < 2e+06)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", nargs="?", help="TOML file (see examples/scan_designs.toml); "
                        "default: the built-in config (--show-config prints it)")
    parser.add_argument("--out", default="epc-scan", help="output directory (default: %(default)s)")
    parser.add_argument("--points", type=float, help="override [scan] points")
    parser.add_argument("--seed", type=int, help="override [scan] seed")
    parser.add_argument("--threads", type=int, help="core threads per chunk")
    parser.add_argument("--chunk-points", type=int, help="points per chunk (a multiple of 65536)")
    parser.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:8786): run "
                        "the chunks on that cluster (needs the dask extra)")
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--show-config", action="store_true",
                        help="print the built-in config and exit")


def _config(args):
    from ..scan.config import default_config, load_config

    config = load_config(args.config) if args.config else default_config()
    if args.points is not None:
        config.points = int(args.points)
    for name in ("seed", "threads", "chunk_points"):
        if getattr(args, name) is not None:
            setattr(config, name, getattr(args, name))
    return config


def _client(address):
    if address is None:
        return None
    try:
        from distributed import Client
    except ImportError:
        raise ImportError("--scheduler needs dask.distributed: pip install 'epc-fast[dask]'"
                          ) from None
    return Client(address)


def headline(result, source: str) -> str:
    """One line: points, config, seed, time and throughput (and whether it was interrupted)."""
    done = f"{result.points:,} of {result.points_requested:,}" if result.partial else \
        f"{result.points:,}"
    return (f"scan of {done} points ({source}), seed {result.seed}: "
            f"{result.timing.wall_s:.1f} s, {result.points_per_s / 1e6:.2f} M points/s"
            + (" -- INTERRUPTED, partial results" if result.partial else ""))


def _quantile_notes(result) -> list[str]:
    return [f"{name}: {r.error_statement()}" for name, r in result.results.items()
            if hasattr(r, "error_statement")]


def _write_outputs(result, out: Path, plots: bool) -> list[Path]:
    from ..scan import tables

    written = []
    for grouping, columns in tables.grouped_tables(result).items():
        stem = out / tables.file_stem(grouping)
        tables.write_csv(stem.with_suffix(".csv"), columns)
        stem.with_suffix(".md").write_text(tables.markdown(columns) + "\n")
        written += [stem.with_suffix(".csv"), stem.with_suffix(".md")]
    for name, columns in tables.top_k_columns(result).items():
        tables.write_csv(out / f"{name}.csv", columns)
        written.append(out / f"{name}.csv")
    if plots:
        written += _write_plots(result, out)
    return written


def _write_plots(result, out: Path) -> list[Path]:
    from ..scan import plots
    from ..scan.histograms import HistogramResult, QuantilesResult

    written = []
    for name, r in result.results.items():
        path = out / f"{name}.png"
        if isinstance(r, HistogramResult):
            plots.plot_distributions(r, path)
        elif isinstance(r, QuantilesResult) and plots.bands_parameter(r):
            plots.plot_bands(r, path)
        else:
            continue
        written.append(path)
    return written


def run(args) -> int:
    from ..scan import run as run_scan
    from ..scan import tables
    from ..scan.config import DEFAULT_CONFIG

    if args.show_config:
        print(DEFAULT_CONFIG, end="")
        return 0
    config = _config(args)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    client = _client(args.scheduler)
    try:
        result = run_scan(config.space, **config.run_kwargs(),
                          progress=False if args.no_progress else None,
                          parquet=None if config.parquet is None else out / config.parquet,
                          client=client)
    finally:
        if client is not None:
            client.close()
    print(headline(result, config.source))
    print(config.space.describe())
    for grouping, columns in tables.grouped_tables(result).items():
        if len(next(iter(columns.values()))) <= MAX_PRINTED_ROWS:
            print(f"\nby {grouping}:\n{tables.markdown(columns)}")
    print()
    for note in _quantile_notes(result):
        print(note)
    for path in _write_outputs(result, out, plots=not args.no_plots):
        print(f"wrote {path}")
    return 130 if result.partial else 0


def print_default_scan(points: int = MAIN_JOB_POINTS) -> None:
    """The main job's scan: the built-in config on ``points`` points, a compact table."""
    from ..scan import run as run_scan
    from ..scan import tables
    from ..scan.config import default_config

    config = default_config()
    config.points = points
    result = run_scan(config.space, **config.run_kwargs(), progress=False)
    summary = tables.grouped_tables(result)["design"]
    compact = {"design": summary["design"],
               **{f"{c} (Mpx)": [v / 1e6 for v in summary[c]] for c in MAIN_JOB_EPC_COLUMNS},
               "P(EPC < 2 Mpx)": summary[MAIN_JOB_FRACTION_COLUMN]}
    print("\nDefault scan (epc-fast scan --show-config): EPC over log-uniform 10..100,000 lux "
          "and log-normal hand shake (median 4.39 deg/s):")
    print(headline(result, config.source))
    print(tables.markdown(compact))
