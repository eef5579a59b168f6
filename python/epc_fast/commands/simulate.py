"""``epc-fast simulate CONFIG.toml --lux 10 100 1000 --out DIR``: a design review's pictures.

Each design of the config captures, at each light level, a Siemens star of one physical width,
a slanted edge and a flat patch (:mod:`epc_fast.simulate.review`). Everything goes into
``--out`` under the scan's output policy (:class:`epc_fast.scan.output.OutputDirectory`:
checked before the first capture, refused when not empty unless ``--overwrite``, every file
written atomically): ``contact_sheet.png``, ``mtf.png``, ``mtf_across.png``, and the model
beside the simulation in ``agreement.csv`` and ``agreement.md``: the MTF50 along the motion
beside the model's f50 and across it beside f50_across.
"""

from __future__ import annotations

import argparse
import csv
import math
import time

from . import add_output_arguments, duration, whole

NAME = "simulate"
HELP = ("simulate captures of designs from a TOML config (see examples/simulate_designs.toml) "
        "at a few light levels: a contact sheet of a Siemens star, the slanted edges' MTF "
        "against the model's (PNG), and the model's EPC, f50, f50_across and SNR target "
        "beside the measured MTF50 along and across the motion and SNR (CSV, Markdown)")
#: The files the command writes, and what each holds.
FILES = {"contact_sheet.png": "the star as each design captures it at each light level",
         "mtf.png": "the simulated edges' MTF against the model's",
         "mtf_across.png": "the simulated edges' MTF across the motion against the model's",
         "agreement.csv": "the model beside the simulation, one row a design and light",
         "agreement.md": "the same as a table"}
PLOTS = ("contact_sheet.png", "mtf.png", "mtf_across.png")
#: The most light levels (the contact sheet's columns).
MAX_LUX = 12
#: The columns of agreement.csv.
COLUMNS = ("design", "illuminance_lux", "mode", "status", "epc_model", "f50_model_cyc_per_mm",
           "mtf50_sim_cyc_per_mm", "mtf50_over_f50", "f50_across_model_cyc_per_mm",
           "mtf50_across_sim_cyc_per_mm", "mtf50_across_over_f50_across", "snr_target_db",
           "snr_sim_db", "note")


def _lux(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0.0 < value <= 1e6):
        raise argparse.ArgumentTypeError(f"--lux {text!r}: expected an illuminance in lux, "
                                         "above 0 and at most 1e6")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..simulate.config import DEFAULT_LUX

    parser.add_argument("config", help="TOML file (see examples/simulate_designs.toml)")
    parser.add_argument("--lux", type=_lux, nargs="+", default=list(DEFAULT_LUX),
                        metavar="LUX", help="the light levels, the contact sheet's columns "
                        "(default: %(default)s)")
    add_output_arguments(parser, "epc-simulate", "the files this command writes")
    parser.add_argument("--seed", type=whole("--seed", 0, 2**64 - 1),
                        help="override [simulate] seed")
    parser.add_argument("--no-plots", action="store_true",
                        help="skip contact_sheet.png and mtf.png")
    parser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an error")


def _rows(review) -> list[dict]:
    rows = []
    for row in review.cells:
        for cell in row:
            rows.append({
                "design": cell.design, "illuminance_lux": cell.illuminance_lux,
                "mode": cell.mode_text, "status": _status(cell.result),
                "epc_model": cell.epc, "f50_model_cyc_per_mm": cell.f50_model_cyc_per_mm,
                "mtf50_sim_cyc_per_mm": cell.mtf50_cyc_per_mm,
                "mtf50_over_f50": cell.mtf50_fraction,
                "f50_across_model_cyc_per_mm": cell.f50_across_model_cyc_per_mm,
                "mtf50_across_sim_cyc_per_mm": cell.mtf50_across_cyc_per_mm,
                "mtf50_across_over_f50_across": cell.mtf50_across_fraction,
                "snr_target_db": cell.snr_target_db, "snr_sim_db": cell.snr_db,
                "note": _note(cell)})
    return rows


def _note(cell) -> str:
    """Why a cell has no image, or why an MTF50 is not measured ("" when both are)."""
    if cell.why:
        return f"no image: {cell.why}"
    across = f"across: {cell.mtf_across_why}" if cell.mtf_across_why else ""
    return "; ".join(text for text in (cell.mtf_why, across) if text)


def _status(result) -> str:
    import numpy as np

    from ..status import Status

    return Status(int(np.asarray(result.status))).name


def _write_csv(path, rows) -> None:
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        for row in rows:
            writer.writerow([repr(float(v)) if isinstance(v, float) else v
                             for v in (row[c] for c in COLUMNS)])


def _number(value: float, spec: str = ".4g") -> str:
    return "—" if math.isnan(value) else format(value, spec)


def markdown(rows, seed, epc_axes="motion") -> str:
    """agreement.md: the model beside one simulated capture a design and light; ``epc_axes``
    how the designs' EPC counts the resolution ("both": said in the first line)."""
    counted = (' EPC counts both directions, 4 S f50 f50_across (epc_axes = "both").'
               if epc_axes == "both" else "")
    lines = [f"Model against simulated captures (one capture each, seed {seed}): MTF50 of the "
             "slanted edges' e-SFR with bin-width correction along the motion (near vertical) "
             "and across it (near "
             f"horizontal), SNR of the flat patch.{counted}", "",
             "| design | lux | EPC model (pixels) | f50 model (cyc/mm) | MTF50 sim (cyc/mm) | "
             "sim / model | f50 across model (cyc/mm) | MTF50 across sim (cyc/mm) | "
             "sim / model across | SNR target (dB) | SNR sim (dB) | note |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        design = f"{r['design']} ({r['mode']})" if r["mode"] else r["design"]
        lines.append(
            f"| {design} | {r['illuminance_lux']:g} | {r['epc_model']:,.0f} "
            f"| {_number(r['f50_model_cyc_per_mm'])} | {_number(r['mtf50_sim_cyc_per_mm'])} | "
            f"{_number(r['mtf50_over_f50'], '.3f')} "
            f"| {_number(r['f50_across_model_cyc_per_mm'])} "
            f"| {_number(r['mtf50_across_sim_cyc_per_mm'])} "
            f"| {_number(r['mtf50_across_over_f50_across'], '.3f')} | {r['snr_target_db']:g} | "
            f"{_number(r['snr_sim_db'])} | {r['note'].replace('|', '/')} |")
    return "\n".join(lines) + "\n"


def run(args) -> int:
    from ..jobs.extras import PLOT, check_extras
    from ..jobs.errors import UsageError
    from ..jobs.output import OutputDirectory
    from ..jobs.signals import SignalsHeld
    from ..simulate.config import load_simulate_config
    from ..simulate.review import review

    config = load_simulate_config(args.config)
    if args.seed is not None:
        config.settings["seed"] = args.seed
    if len(args.lux) > MAX_LUX:
        raise UsageError(f"--lux: at most {MAX_LUX} light levels, got {len(args.lux)}")
    plots = not args.no_plots
    if plots:
        check_extras([(PLOT, "the simulator's figures", "--no-plots")])
        from ..plotting import save_figure
        from ..simulate.plot import contact_sheet_figure, mtf_figure
    with OutputDirectory(args.out, overwrite=args.overwrite) as out:
        out.prepare({name: what for name, what in FILES.items()
                     if plots or name not in PLOTS})
        start = time.perf_counter()
        result = review(config.designs, args.lux, snr_target=config.snr_target,
                        terms=config.terms, **config.settings)
        rows = _rows(result)
        print(f"{len(config.designs)} design(s) x {len(args.lux)} light level(s) from "
              f"{config.source}, seed {config.settings['seed']}: captured in "
              f"{duration(time.perf_counter() - start)}")
        print()
        text = markdown(rows, config.settings["seed"], result.epc_axes)
        print(text)
        with SignalsHeld() as writing:  # SIGINT and SIGTERM wait for every file
            out.write("agreement.csv", lambda path: _write_csv(path, rows))
            out.write("agreement.md", lambda path: path.write_text(text, encoding="utf-8"))
            if plots:
                sheet = contact_sheet_figure(result)
                out.write("contact_sheet.png", lambda path: save_figure(
                    sheet, path, dpi=110, file_format="png"))
                curves = mtf_figure(result)
                out.write("mtf.png", lambda path: save_figure(curves, path, dpi=110,
                                                              file_format="png"))
                across = mtf_figure(result, direction="across")
                out.write("mtf_across.png", lambda path: save_figure(across, path, dpi=110,
                                                                     file_format="png"))
        for name in out.written:
            print(f"wrote {out.path / name}")
        return writing.exit_code("epc-fast simulate")
