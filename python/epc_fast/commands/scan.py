"""``epc-fast scan [CONFIG.toml]``: a design-space scan, its summary table and plots, and
the Sobol' indices of its space when the config has a ``[sobol]`` table (computed first, on
their own points: :mod:`epc_fast.commands.sobol`).

Everything the scan writes goes into ``--out`` under the policy of
:class:`epc_fast.scan.output.OutputDirectory` (checked before the first point, every file
written atomically), with a ``manifest.json`` updated after every merged chunk. SIGINT and
SIGTERM stop the scan between chunks; the prefix done is written everywhere, marked partial.
An error between chunks (a full disk, a failed chunk) ends it the same way, with exit code 1.
While the results and the manifest are written, both signals are held, then obeyed.
"""

from __future__ import annotations

import argparse
import sys

from . import add_output_arguments, duration, whole

NAME = "scan"
HELP = ("scan a design space from a TOML config (default: the built-in one) and write its "
        "summary table (CSV, markdown), plots and, with a [sobol] table, its Sobol' indices")

#: Tables with more rows than this are written to files only.
MAX_PRINTED_ROWS = 24
#: Points of the default scan the main job runs.
MAIN_JOB_POINTS = 200_000
#: Columns of the main job's compact table (EPC in pixels).
MAIN_JOB_EPC_COLUMNS = ("mean", "q5", "q50", "q95")
MAIN_JOB_FRACTION_COLUMN = "P(epc < 2e+06)"
#: Exit codes of a scan stopped by SIGINT and SIGTERM (128 + the signal's number).
EXIT_INTERRUPTED = {"SIGINT": 130, "SIGTERM": 143}
#: Exit code of a scan that could not go on (e.g. its cluster lost every worker).
EXIT_ABORTED = 1


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..api import MAX_THREADS
    from ..scan.config.bounds import MAX_CHUNK_POINTS, MAX_POINTS
    from ..scan.sampling.space import BLOCK_POINTS

    parser.add_argument("config", nargs="?", help="TOML file (see examples/scan_designs.toml); "
                        "default: the built-in config (--show-config prints it)")
    add_output_arguments(parser, "epc-scan", "the files this scan writes")
    parser.add_argument("--points", type=whole("--points", 1, MAX_POINTS),
                        help="override [scan] points (1e9 is accepted)")
    parser.add_argument("--seed", type=whole("--seed", 0, 2**64 - 1), help="override [scan] seed")
    parser.add_argument("--threads", type=whole("--threads", 1, MAX_THREADS),
                        help="core threads per chunk")
    parser.add_argument("--chunk-points", type=whole("--chunk-points", BLOCK_POINTS,
                                                      MAX_CHUNK_POINTS, BLOCK_POINTS),
                        help="points per chunk (a multiple of 65536)")
    parser.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:8786): run "
                        "the chunks on that cluster (needs the dask extra)")
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--show-config", action="store_true",
                        help="print the built-in config and exit")
    parser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an error")


def _config(args):
    from ..scan.config import default_config, load_config

    config = load_config(args.config) if args.config else default_config()
    for name in ("points", "seed", "threads", "chunk_points"):
        if getattr(args, name) is not None:
            setattr(config, name, getattr(args, name))
    if args.points is not None:  # the sampling's rules on the points given here
        from ..jobs.errors import ConfigError
        from ..scan.running.runner import sampled_scan

        try:
            sampled_scan(config.space, config.points, config.reductions, config.sampling,
                         config.replicates)
        except (TypeError, ValueError) as error:
            raise ConfigError(f"--points {config.points}: {error}") from None
    return config


def _overrides(args) -> dict:
    return {name: getattr(args, name) for name in ("points", "seed", "threads", "chunk_points")
            if getattr(args, name) is not None}


def _client(address):
    if address is None:
        return None
    try:
        from distributed import Client
    except ImportError:
        raise ImportError("--scheduler needs dask.distributed: pip install 'epc-fast[dask]'"
                          ) from None
    return Client(address)


def headline(result, source: str, failure=None) -> str:
    """One line: points, config, seed, time and throughput, and how a partial scan stopped:
    ``-- FAILED: <the error>; partial results`` when ``failure`` (the error that ended it) is
    given, else ``-- INTERRUPTED, partial results``."""
    done = f"{result.points:,} of {result.points_requested:,}" if result.partial else \
        f"{result.points:,}"
    sampling = result.sampling
    how = "" if not sampling.sobol and sampling.replicates == 1 else (
        f", {'Sobol' if sampling.sobol else 'Monte Carlo'} in {sampling.replicates} replicates")
    ending = ""
    if failure is not None:
        ending = f" -- FAILED: {_one_line(failure)}; partial results"
    elif result.partial:
        ending = " -- INTERRUPTED, partial results"
    return (f"scan of {done} points ({source}), seed {result.seed}{how}: "
            f"{duration(result.timing.wall_s)}, {result.points_per_s / 1e6:.2f} M points/s"
            + ending)


def target_lines(result, reductions) -> list[str]:
    """Where a scan with targets stopped and why: every target held, or which did not."""
    targets = {name: r.target for name, r in (reductions or {}).items()
               if getattr(r, "target", None) is not None}
    if not targets:
        return []
    if not result.unmet_targets:
        return [f"every target held at {result.points:,} of at most "
                f"{result.points_requested:,} points: "
                + "; ".join(f"{name}: {target}" for name, target in targets.items())]
    return [f"NOT every target held at {result.points:,} points:"] + [
        f"  {line}" for line in result.unmet_targets]



def _quantile_notes(result) -> list[str]:
    return [f"{name}: {r.error_statement()}" for name, r in result.results.items()
            if hasattr(r, "error_statement")]


def _write_outputs(result, out, plots: bool, log_y: bool = False) -> None:
    """Every table, top-k list and plot of ``result``, each written atomically in ``out``."""
    from ..jobs.table_formats import markdown, write_csv
    from ..scan import tables

    # a partial scan says so in every file: a last column, a line above the table, the title
    note = tables.partial_note(result)
    above = f"**{note}**\n\n" if note else ""
    for grouping, columns in tables.grouped_tables(result).items():
        stem = tables.file_stem(grouping)
        out.write(stem + ".csv",
                  lambda path: write_csv(path, tables.marked_partial(columns, result)))
        out.write(stem + ".md",
                  lambda path: path.write_text(above + markdown(columns) + "\n"))
    for name, columns in tables.histogram_tables(result).items():
        out.write(f"{name}.csv",
                  lambda path: write_csv(path, tables.marked_partial(columns, result)))
        out.write(f"{name}.md",
                  lambda path: path.write_text(above + markdown(columns) + "\n"))
    for name, columns in tables.top_k_columns(result).items():
        out.write(f"{name}.csv",
                  lambda path: write_csv(path, tables.marked_partial(columns, result)))
    if plots:
        _write_plots(result, out, note, log_y)


def _write_plots(result, out, partial: str = "", log_y: bool = False) -> None:
    from ..scan import plot
    from ..scan.reductions.histograms import HistogramResult, QuantilesResult
    from ..scan.reductions.summaries import FractionBelowResult

    below = [r for r in result.results.values() if isinstance(r, FractionBelowResult)]
    for name, r in result.results.items():
        if isinstance(r, HistogramResult):
            out.write(f"{name}.png",
                      lambda path: plot.plot_distributions(
                          r, path, below, partial, conditions=plot.scan_conditions(result)))
        elif isinstance(r, QuantilesResult) and plot.bands_parameter(r):
            conditions = plot.scan_conditions(result, skip=(plot.bands_parameter(r),))
            out.write(f"{name}.png", lambda path: plot.plot_bands(
                r, path, below, partial, conditions=conditions,
                pixel_counts=plot.scan_pixel_counts(result.space), log_y=log_y))


def _planned(config, plots: bool) -> dict:
    from ..jobs.errors import OutputError
    from ..jobs.output.manifest import MANIFEST_NAME
    from ..scan.output import plan_outputs

    planned = plan_outputs(config.space, config.reductions, plots, config.parquet,
                           sobol=config.sobol is not None)
    if set(planned) == {MANIFEST_NAME}:
        raise OutputError("this scan writes no result: its reductions have no table, and "
                          + ("--no-plots drops their plots" if not plots else "no plot")
                          + "; add a summary, quantiles, fraction_below or top_k reduction"
                          + (", or drop --no-plots" if not plots else ""))
    return planned


def _parquet_bytes(config) -> int:
    from ..jobs.output import PARQUET_BYTES_PER_VALUE
    from ..scan.running.chunk import OUTPUTS

    if config.parquet is None:
        return 0
    columns = 3 + len(config.space.varying_parameters) + len(OUTPUTS)
    return config.points * columns * PARQUET_BYTES_PER_VALUE


def _parquet_files(out, config) -> list[str]:
    from ..scan.running.parquet import committed_parts

    if config.parquet is None:
        return []
    return [f"{config.parquet}/{name}" for name in committed_parts(out.path / config.parquet)]


def run(args) -> int:
    from .._validation import threads_of
    from ..jobs.extras import check_extras
    from ..jobs.output import OutputDirectory
    from ..jobs.output.manifest import write_manifest
    from ..jobs.signals import SignalsHeld, StopSignals
    from ..scan import run as run_scan
    from ..scan.config import DEFAULT_CONFIG
    from ..scan.config.needs import scan_extras
    from ..scan.output import new_manifest
    from ..scan.running.aborted import ScanAborted
    from .sobol import compute

    if args.show_config:
        print(DEFAULT_CONFIG, end="")
        return 0
    config = _config(args)
    if args.scheduler is None:  # the threads (or OMP_NUM_THREADS), before anything is written
        threads_of(config.threads)
    plots = not args.no_plots
    planned = _planned(config, plots)
    check_extras(scan_extras(config, planned, cluster=args.scheduler is not None))
    # SIGINT and SIGTERM are held from before the lock to the manifest's last write, and stop
    # the scan only between them (StopSignals): the directory is made ready and the results
    # are written whole, and every signal leaves a manifest that says how the scan ended.
    writing, stops = SignalsHeld(), StopSignals()
    with writing, OutputDirectory(args.out, overwrite=args.overwrite) as out:
        out.prepare(planned, config.parquet, _parquet_bytes(config))
        manifest = new_manifest(config, _overrides(args), config.points)
        write_manifest(out.path, manifest)
        if writing.name is not None:  # a signal since the lock was taken
            return _interrupted_before_the_first_point(out, manifest, writing.name)

        def on_chunk(done: int) -> None:
            manifest["points_done"] = done
            manifest["files"] = _parquet_files(out, config)
            write_manifest(out.path, manifest)

        client = failure = sobol = None
        try:
            try:
                with stops:
                    client = _client(args.scheduler)
                    if config.sobol is not None:
                        sobol = compute(config, config.sobol, config.threads, NAME)
                    parquet = None if config.parquet is None else out.path / config.parquet
                    result = run_scan(config.space, **config.run_kwargs(),
                                      progress=False if args.no_progress else None,
                                      parquet=parquet, client=client, on_chunk=on_chunk)
            finally:
                if client is not None:
                    client.close()
        except ScanAborted as error:
            if error.result is None:
                manifest.update(state="failed", stopped_by=_stopped_by(error))
                write_manifest(out.path, manifest)
                raise
            failure, result = error, error.result
        except KeyboardInterrupt:  # before the scan's first point: the cluster, [sobol] indices
            return _interrupted_before_the_first_point(out, manifest, stops.name)
        except BaseException as error:
            result = getattr(error, "scan_result", None)
            if result is None:
                manifest.update(state="failed", stopped_by=_stopped_by(error))
                write_manifest(out.path, manifest)
                raise
            failure = error
        _finish(config, out, manifest, result, sobol, failure, stops, plots)
        if failure is not None:
            print(f"epc-fast scan: error: {_one_line(failure)}; the {result.points:,} points "
                  "merged before it are written, marked partial", file=sys.stderr)
            return EXIT_ABORTED
        if result.partial:
            return EXIT_INTERRUPTED[stops.name]
        if writing.name is not None:
            print(f"epc-fast scan: {writing.name} while the results were written: every file "
                  "is written whole, the scan is complete", file=sys.stderr)
            return EXIT_INTERRUPTED[writing.name]
        return 0


def _interrupted_before_the_first_point(out, manifest: dict, name: str) -> int:
    """Record a scan stopped by the signal ``name`` before its first point; its exit code."""
    from ..jobs.output.manifest import write_manifest

    manifest.update(state="interrupted", stopped_by=name)
    write_manifest(out.path, manifest)
    print("epc-fast scan: interrupted before the first point", file=sys.stderr)
    return EXIT_INTERRUPTED[name]


def _one_line(error) -> str:
    """An error that ended the scan, on one line: a lost cluster's message, else the error's
    type and message."""
    from ..scan.running.aborted import ScanAborted

    text = " ".join(str(error).split())
    if isinstance(error, ScanAborted):
        return text
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


def _stopped_by(error) -> str:
    """The manifest's ``stopped_by`` for an error."""
    from ..scan.running.aborted import ScanAborted

    return str(error) if isinstance(error, ScanAborted) else f"{type(error).__name__}: {error}"


def _finish(config, out, manifest, result, sobol, failure, stops, plots) -> None:
    """Print the results, write every table, plot and the manifest; an error while writing is
    recorded in the manifest (state ``failed``, the files written so far) and raised."""
    from ..jobs import table_formats
    from ..jobs.output.manifest import write_manifest
    from ..scan import tables
    from .sobol import report, write_indices

    try:
        print(headline(result, config.source, failure))
        for line in target_lines(result, config.reductions):
            print(line)
        print(config.space.describe())
        units = tables.grouping_units(result)
        for grouping, columns in tables.grouped_tables(result).items():
            if len(next(iter(columns.values()))) <= MAX_PRINTED_ROWS:
                unit = f" ({units[grouping]})" if grouping in units else ""
                print(f"\nby {grouping}{unit}:\n{table_formats.markdown(columns)}")
        for name, columns in tables.histogram_tables(result).items():
            if len(columns["points"]) <= MAX_PRINTED_ROWS:
                unit = tables.OUTPUT_UNITS.get(result[name].of)
                print(f"\nby {name}" + (f" ({result[name].of} in {unit})" if unit else "")
                      + f":\n{table_formats.markdown(columns)}")
        if sobol is not None:
            print(f"\n{report(*sobol)}")
        print()
        for note in _quantile_notes(result):
            print(note)
        _write_outputs(result, out, plots=plots, log_y=config.log_y)
        if sobol is not None:
            write_indices(out, sobol[0])
    except BaseException as error:
        stopped_by = _stopped_by(error)
        if failure is not None:  # the scan's own error first: what went wrong after follows
            stopped_by = f"{_stopped_by(failure)}; then, writing the results: {stopped_by}"
            print(f"epc-fast scan: error: {_one_line(failure)}; the {result.points:,} points "
                  "merged before it are written in part, marked partial", file=sys.stderr)
        manifest.update(points_done=result.points, partial=result.partial, state="failed",
                        stopped_by=stopped_by, files=out.written + _parquet_files(out, config))
        write_manifest(out.path, manifest)
        raise
    stopped_by = (_stopped_by(failure) if failure is not None
                  else stops.name if result.partial else None)
    state = ("failed" if failure is not None else "interrupted" if result.partial
             else "complete")
    manifest.update(points_done=result.points, partial=result.partial, state=state,
                    stopped_by=stopped_by, files=out.written + _parquet_files(out, config),
                    sampling=result.sampling.method, replicates=result.sampling.replicates,
                    unmet_targets=list(result.unmet_targets))
    write_manifest(out.path, manifest)
    for name in out.written + ["manifest.json"]:
        print(f"wrote {out.path / name}")
    parts = _parquet_files(out, config)
    if parts:
        print(f"wrote {out.path / config.parquet} ({len(parts)} Parquet parts, points 0 to "
              f"{result.points - 1:,})")

def print_default_scan(points: int = MAIN_JOB_POINTS) -> None:
    """The main job's scan: the built-in config on ``points`` points, a compact table (EPC in
    pixels, as everywhere)."""
    from ..jobs import table_formats
    from ..scan import run as run_scan
    from ..scan import tables
    from ..scan.config import default_config

    config = default_config()
    config.points = points
    result = run_scan(config.space, **config.run_kwargs(), progress=False)
    summary = tables.grouped_tables(result)["design"]
    compact = {"design": summary["design"],
               **{f"{c} (pixels)": summary[c] for c in MAIN_JOB_EPC_COLUMNS},
               "P(EPC < 2,000,000)": summary[MAIN_JOB_FRACTION_COLUMN]}
    print("\nDefault scan (epc-fast scan --show-config): EPC over log-uniform 10..100,000 lux "
          "and log-normal hand shake (median 4.39 deg/s), 30 dB met at the image corner:")
    print(headline(result, config.source))
    print(table_formats.markdown(compact))
