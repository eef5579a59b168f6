"""Measures each demosaicker's luminance MTF and noise gain with the capture simulator, and
writes the table python/epc_fast/data/demosaic_mtf.csv that epc_fast.cfa.demosaic_mtf_table
reads.

The MTF: noise-free captures (``Capture.expected_e``) of slanted edges by designs whose optics
pass well beyond 1 cycle/pixel (F/1.4 at 550 nm: the lens's cut-off 1/(lambda F) is 3.6
cycles/pixel at 2.8 um and 1.8 at 1.4 um; fill factor 0.25, so that the pixel's aperture, half
the pitch, has its first zero at 2 cycles/pixel; 1 ms exposure, no jitter: no motion), at
several edge angles and two chart widths (an odd width moves the edge half a pixel against
the Bayer cell). For each, the e-SFR of the Bayer capture's luminance over the e-SFR of the
monochrome capture of the same design and edge is the demosaicker's transfer; the table is
the mean over the captures at each knot f p_out = 0, 0.05, ..., 1 cycle/pixel, made
non-rising by a running minimum from 0 (the script prints the largest rise it removed and the
captures' scatter). Vertical edges only: the RGGB cell and the three demosaickers are
symmetric under transposition, so rows and columns have one transfer.

The noise gain g_d: flat captures with shot noise only (no read noise, dark current or PRNU),
the luminance's variance over its mean (both on the cell's scale) divided by
epc_fast.cfa.DEFAULT_COLOR_NOISE_GAIN, pooled over seeds.

    python tools/demosaic_mtf.py            # ~30 s on one core; writes the CSV
    python tools/demosaic_mtf.py --stdout   # the CSV on stdout instead
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

from epc_fast import cfa, simulate  # noqa: E402

OUT = ROOT / "python" / "epc_fast" / "data" / "demosaic_mtf.csv"
#: cycles/pixel, the table's knots.
KNOTS = np.round(np.arange(0.0, 1.0001, 0.05), 10)
BASE = {"focal_length_mm": 5.6, "sensor_area_mm2": 15.6751, "snr_db": 30.0, "f_number": 1.4,
        "fill_factor": 0.25, "jitter_um": 0.0}
DESIGNS = ({**BASE, "pixel_pitch_um": 2.8}, {**BASE, "pixel_pitch_um": 1.4})
ANGLES_DEG = (5.0, 8.5, -6.5)
WIDTHS_PX = (96, 97)
ROWS_PX = 96
LUX = 1e4
EXPOSURE_S = 1e-3
#: Flat captures for g_d: side in pixels and seeds.
FLAT_PX = 192
SEEDS = tuple(range(16))


def edge_transfer(design, angle_deg, width_px, rows_px=ROWS_PX, knots=KNOTS,
                  sensor="bayer") -> dict:
    """{demosaicker: the e-SFR of the colour capture (``sensor``, a ``cfa`` of
    epc_fast.cfa.CFAS) over the monochrome one at ``knots``} for one edge."""
    chart = simulate.slanted_edge((rows_px, width_px), angle_deg)
    kw = {"illuminance_lux": LUX, "exposure_s": EXPOSURE_S, **design}
    mono = simulate.capture(chart, **kw)
    f_mm = knots / (mono.pitch_um * 1e-3)
    # the e-SFR with bin-width correction, as the table was measured: the bins' sinc(f D) is
    # the same factor in both e-SFRs (one pitch, one oversampling) and cancels in the ratio
    reference = simulate.esfr(mono.expected_e, mono.pitch_um, bin_correction=True).mtf_at(f_mm)
    out = {}
    for name in cfa.DEMOSAICS:
        c = simulate.capture(chart, cfa=sensor, demosaic=name, **kw)
        out[name] = (simulate.esfr(c.expected_e, c.pitch_um, bin_correction=True).mtf_at(f_mm)
                     / reference)
    return out


def measure_mtf(designs=DESIGNS, angles=ANGLES_DEG, widths=WIDTHS_PX, rows_px=ROWS_PX,
                knots=KNOTS, sensor="bayer") -> dict:
    """{demosaicker: array (captures, knots)} of the transfers over every design, angle and
    width."""
    runs = {name: [] for name in cfa.DEMOSAICS}
    for design in designs:
        for angle in angles:
            for width in widths:
                for name, ratio in edge_transfer(design, angle, width, rows_px, knots,
                                                 sensor).items():
                    runs[name].append(ratio)
    return {name: np.array(r) for name, r in runs.items()}


def non_rising(values) -> tuple:
    """(the running minimum of ``values`` from the first, the largest rise it removed)."""
    values = np.asarray(values, dtype=float)
    floor = np.minimum.accumulate(values)
    return floor, float(np.max(values - floor))


def table(runs: dict) -> dict:
    """{demosaicker: (table, the most it lies below the mean, the captures' standard
    deviation at each knot)}: the mean transfer over the captures, 1 at 0, clipped to [0, 1]
    and made non-rising (a demosaicker that sharpens, or whose transfer rises again past the
    Nyquist frequency, loses that gain in the table)."""
    out = {}
    for name, r in runs.items():
        mean = r.mean(axis=0) / r[:, 0].mean()
        floor, _ = non_rising(np.clip(mean, 0.0, 1.0))
        floor[0] = 1.0
        std = r.std(axis=0, ddof=1) if len(r) > 1 else np.zeros(r.shape[1])
        out[name] = (floor, float(np.max(mean - floor)), std)
    return out


def noise_gain(name, seeds=SEEDS, side_px=FLAT_PX, design=DESIGNS[0], sensor="bayer") -> tuple:
    """(g_d, its standard error over the seeds) of demosaicker ``name`` on flat captures with
    shot noise only."""
    shot_only = {**design, "read_noise_e": 0.0, "dark_current_e_per_s": 0.0, "prnu": 0.0}
    chart = simulate.flat(side_px)
    c = simulate.capture(chart, illuminance_lux=LUX, exposure_s=EXPOSURE_S, cfa=sensor,
                         demosaic=name, seed=seeds[0], **shot_only)
    gains = []
    for seed in seeds:
        image = c.redraw(seed).image_e
        gains.append(image.var(ddof=1) / image.mean() / cfa.DEFAULT_COLOR_NOISE_GAIN)
    gains = np.array(gains)
    return float(gains.mean()), float(gains.std(ddof=1) / np.sqrt(gains.size))


def csv_text(tables: dict, knots=KNOTS) -> str:
    names = list(cfa.DEMOSAICS)
    lines = ["# Each demosaicker's luminance MTF against f p_out (cycles/pixel), written by",
             "# tools/demosaic_mtf.py: the mean over noise-free slanted-edge captures (edges at "
             + ", ".join(f"{a:g}" for a in ANGLES_DEG) + " degrees,",
             f"# {ROWS_PX} rows by " + " and ".join(map(str, WIDTHS_PX))
             + " columns, 2.8 and 1.4 um pixels at F/1.4, fill factor 0.25,",
             "# 550 nm) of the Bayer luminance's e-SFR over the monochrome capture's, made",
             "# non-rising by a running minimum. <name>_std: the captures' standard deviation",
             "# about the mean (their scatter).",
             "f_cyc_per_px," + ",".join(names) + "," + ",".join(f"{n}_std" for n in names)]
    for i, f in enumerate(knots):
        lines.append(f"{f:.2f}," + ",".join(f"{tables[n][0][i]:.4f}" for n in names) + ","
                     + ",".join(f"{tables[n][2][i]:.4f}" for n in names))
    return "\n".join(lines) + "\n"


def main() -> None:
    runs = measure_mtf()
    tables = table(runs)
    for name, (values, rise, std) in tables.items():
        g, se = noise_gain(name)
        print(f"{name}: g_d = {g:.4f} +- {se:.4f}; the table lies up to {rise:.4f} below the mean; "
              f"captures' std at most {std.max():.4f} (at {KNOTS[np.argmax(std)]:.2f} cyc/px)")
        print("  " + " ".join(f"{v:.3f}" for v in values))
    text = csv_text(tables)
    if "--stdout" in sys.argv:
        sys.stdout.write(text)
    else:
        OUT.write_text(text)
        print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
