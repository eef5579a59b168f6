"""Measures the luminance MTF and noise gain of a quad Bayer sensor read full size, remosaicked
(epc_fast.simulate.remosaic) and demosaicked by each demosaicker, with the capture simulator,
and writes the table python/epc_fast/data/remosaic_mtf.csv that
epc_fast.cfa.remosaic_mtf_table reads.

The measurement is tools/demosaic_mtf.py's with ``cfa="quad_bayer"`` at binning 1: the MTF is
the mean over noise-free slanted edges (its designs and angles) of the quad capture's e-SFR
over the monochrome capture's, at f p_out = 0, 0.05, ..., 1 cycle/pixel, made non-rising by a
running minimum from 0; the chart is 96 to 99 columns wide, so that the edge takes each of the
four positions against the quad pattern's period of 4 pixels (the Bayer table's 96 and 97
cover the cell's 2). Vertical edges only: the quad pattern, the remosaic (its classifier and
estimates are the same along rows and columns) and the demosaickers are symmetric under
transposition. The noise gain g_d: flat 192 x 192 captures with shot noise only, the
luminance's variance over its mean divided by epc_fast.cfa.DEFAULT_COLOR_NOISE_GAIN, its mean
and standard error over seeds 0-15.

    python tools/remosaic_mtf.py            # ~1 min on one core; writes the CSV
    python tools/remosaic_mtf.py --stdout   # the CSV on stdout instead
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

from epc_fast import cfa  # noqa: E402

_SPEC = importlib.util.spec_from_file_location("demosaic_mtf", ROOT / "tools" / "demosaic_mtf.py")
demosaic_mtf = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(demosaic_mtf)

OUT = ROOT / "python" / "epc_fast" / "data" / "remosaic_mtf.csv"
KNOTS = demosaic_mtf.KNOTS
ANGLES_DEG = demosaic_mtf.ANGLES_DEG
WIDTHS_PX = (96, 97, 98, 99)
ROWS_PX = demosaic_mtf.ROWS_PX
SEEDS = demosaic_mtf.SEEDS
SENSOR = "quad_bayer"


def measure_mtf(designs=demosaic_mtf.DESIGNS, angles=ANGLES_DEG, widths=WIDTHS_PX,
                rows_px=ROWS_PX, knots=KNOTS) -> dict:
    """{demosaicker: array (captures, knots)} of the quad Bayer transfers."""
    return demosaic_mtf.measure_mtf(designs, angles, widths, rows_px, knots, sensor=SENSOR)


def noise_gain(name, seeds=SEEDS) -> tuple:
    """(g_d, its standard error over ``seeds``) of the remosaic and demosaicker ``name``."""
    return demosaic_mtf.noise_gain(name, seeds, sensor=SENSOR)


def mtf50(values, knots=KNOTS) -> float:
    """cycles/pixel, the table's first crossing of 0.5 (linear between knots); nan if none."""
    below = np.flatnonzero(np.asarray(values) < 0.5)
    if below.size == 0:
        return float("nan")
    i = below[0]
    v0, v1 = values[i - 1], values[i]
    return float(knots[i - 1] + (v0 - 0.5) / (v0 - v1) * (knots[i] - knots[i - 1]))


def csv_text(tables: dict, gains: dict, knots=KNOTS) -> str:
    names = list(cfa.DEMOSAICS)
    lines = ["# A quad Bayer sensor read full size, remosaicked (epc_fast.simulate.remosaic) and",
             "# demosaicked: its luminance MTF against f p_out (cycles/pixel), written by",
             "# tools/remosaic_mtf.py: the mean over noise-free slanted-edge captures (edges at "
             + ", ".join(f"{a:g}" for a in ANGLES_DEG) + " degrees,",
             f"# {ROWS_PX} rows by " + ", ".join(map(str, WIDTHS_PX))
             + " columns, 2.8 and 1.4 um pixels at F/1.4, fill factor 0.25,",
             "# 550 nm) of the luminance's e-SFR over the monochrome capture's, made",
             "# non-rising by a running minimum. <name>_std: the captures' standard deviation",
             "# about the mean (their scatter). Noise gain g_d (16 seeds, flat 192 x 192, shot",
             "# noise only; mean +- standard error): "
             + "; ".join(f"{n} {gains[n][0]:.4f} +- {gains[n][1]:.4f}" for n in names) + ".",
             "f_cyc_per_px," + ",".join(names) + "," + ",".join(f"{n}_std" for n in names)]
    for i, f in enumerate(knots):
        lines.append(f"{f:.2f}," + ",".join(f"{tables[n][0][i]:.4f}" for n in names) + ","
                     + ",".join(f"{tables[n][2][i]:.4f}" for n in names))
    return "\n".join(lines) + "\n"


def main() -> None:
    tables = demosaic_mtf.table(measure_mtf())
    gains = {}
    for name, (values, rise, std) in tables.items():
        gains[name] = noise_gain(name)
        bayer = cfa.demosaic_mtf_table(name)
        bayer_values = np.interp(KNOTS, bayer.frequencies, bayer.values)
        print(f"{name}: g_d = {gains[name][0]:.4f} +- {gains[name][1]:.4f}; MTF50 "
              f"{mtf50(values):.3f} cyc/px (Bayer {mtf50(bayer_values):.3f}); the table lies up "
              f"to {rise:.4f} below the mean; captures' std at most {std.max():.4f} (at "
              f"{KNOTS[np.argmax(std)]:.2f} cyc/px)")
        print("  " + " ".join(f"{v:.3f}" for v in values))
    text = csv_text(tables, gains)
    if "--stdout" in sys.argv:
        sys.stdout.write(text)
    else:
        OUT.write_text(text)
        print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
