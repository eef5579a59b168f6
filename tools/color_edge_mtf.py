"""Measures the Bayer luminance's MTF50 of a saturated blue-yellow edge against a grey edge's,
for each demosaicker, with the capture simulator: the figures of docs/model.md's "The colour
filter array" ("Colour").

The demosaickers' MTF tables (epc_fast.cfa.demosaic_mtf_table, tools/demosaic_mtf.py) are
measured on grey edges: after white balance the three channels carry one signal, and a
demosaicker that interpolates one channel from another's detail (Malvar's gradient
correction, Menon's directional interpolation) finds it there. On a coloured edge the channels
step by different amounts, in opposite directions between blue and yellow.

Each edge is a noise-free monochrome capture (``Capture.expected_e``: the optics, the pixel's
aperture, a 1 ms exposure without motion) of a slanted edge, with the Bayer development's
border of scene round it, made the fraction E (0 to 1) of the way from its dark to its light
side. Its white-balanced channels are then a + (b - a) E with a, b the sides' reflectances in
each channel: grey 0.1 to 0.4 in all three, blue (0.02, 0.02, 0.4) to yellow (0.4, 0.4, 0.02)
(R, G, B). The RGGB mosaic of them is demosaicked and its luminance taken as the simulator's
Bayer capture does it (epc_fast.simulate.bayer: the same development; on the grey edge this is
that capture, to rounding), the border cropped, and the luminance's e-SFR (ISO 12233's, as a
lab computes it) gives MTF50. Each figure is the mean over edges at 5, 8.5 and -6.5 degrees on
charts 96 rows by 96 and 97 columns, as tools/demosaic_mtf.py measures.

Designs: the two of tools/demosaic_mtf.py, whose optics pass far beyond 1 cycle/pixel (F/1.4,
fill factor 0.25), so that the demosaicker limits, and the paper's 1/3.2" 1.4 um design behind
its own lens (f/2.8), a camera's case.

    python tools/color_edge_mtf.py     # ~1 min on one core; prints the Markdown table
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

from epc_fast import cfa, presets, simulate  # noqa: E402
from epc_fast.simulate.bayer import BORDER_PX, bayer  # noqa: E402

BASE = {"focal_length_mm": 5.6, "sensor_area_mm2": 15.6751, "snr_db": 30.0, "f_number": 1.4,
        "fill_factor": 0.25, "jitter_um": 0.0}
#: (name, evaluate keywords)
DESIGNS = (("2.8 um, F/1.4, fill 0.25", {**BASE, "pixel_pitch_um": 2.8}),
           ("1.4 um, F/1.4, fill 0.25", {**BASE, "pixel_pitch_um": 1.4}),
           ('1/3.2" 1.4 um (its f/2.8 lens)', presets.HIGH_TIER[3].evaluate_kwargs()))
ANGLES_DEG = (5.0, 8.5, -6.5)
WIDTHS_PX = (96, 97)
ROWS_PX = 96
LUX = 1e4
EXPOSURE_S = 1e-3
#: 1: the chart's reflectances, dark and light side, and the white-balanced (R, G, B) of the
#: coloured edge's two sides.
GREY = (0.1, 0.4)
BLUE = (0.02, 0.02, 0.4)
YELLOW = (0.4, 0.4, 0.02)


def _rggb(shape) -> np.ndarray:
    """Each pixel's channel index (0 R, 1 G, 2 B) in the RGGB cell from the top-left pixel."""
    channel = np.ones(shape, dtype=int)
    channel[0::2, 0::2] = 0
    channel[1::2, 1::2] = 2
    return channel


def edge_fraction(design, angle_deg, width_px, rows_px=ROWS_PX):
    """(E, pitch_um): the noise-free edge image, 0 on the dark side and 1 on the light one,
    with BORDER_PX output pixels of scene round the chart, and the output pitch."""
    b = BORDER_PX
    kw = {"illuminance_lux": LUX, "exposure_s": EXPOSURE_S, **design}
    chart = simulate.slanted_edge((rows_px + 2 * b, width_px + 2 * b), angle_deg,
                                  low=GREY[0], high=GREY[1])
    edge = simulate.capture(chart, **kw)
    flat = simulate.capture(simulate.flat(32, reflectance=GREY[1]), **kw)
    electrons_per_reflectance = float(np.mean(flat.expected_e)) / GREY[1]
    fraction = (edge.expected_e / electrons_per_reflectance - GREY[0]) / (GREY[1] - GREY[0])
    return fraction, edge.pitch_um


def luminance(fraction, dark, light, demosaic) -> np.ndarray:
    """The developed luminance (the border cropped) of the white-balanced channels
    dark + (light - dark) * fraction, each sampled at its RGGB pixels."""
    planes = [dark[c] + (light[c] - dark[c]) * fraction for c in range(3)]
    balanced = np.choose(_rggb(fraction.shape), planes)
    b = BORDER_PX
    return bayer(demosaic).developed(balanced)[b:-b, b:-b]


def measure(designs=DESIGNS, angles=ANGLES_DEG, widths=WIDTHS_PX, rows_px=ROWS_PX) -> list:
    """[(design name, demosaicker, grey MTF50, blue-yellow MTF50)], MTF50 in cycles/pixel, each
    the mean over the edges."""
    out = []
    for name, design in designs:
        edges = [edge_fraction(design, a, w, rows_px) for a in angles for w in widths]
        for demosaic in cfa.DEMOSAICS:
            figures = []
            for dark, light in ((GREY[:1] * 3, GREY[1:] * 3), (BLUE, YELLOW)):
                figures.append(np.mean([
                    simulate.mtf50(luminance(e, dark, light, demosaic), p) * p * 1e-3
                    for e, p in edges]))
            out.append((name, demosaic, *figures))
    return out


def markdown(rows) -> str:
    lines = ["| design | demosaicker | grey edge MTF50 (cycles/pixel) | blue-yellow edge MTF50 "
             "| change |", "|---|---|---:|---:|---:|"]
    for name, demosaic, grey, colour in rows:
        lines.append(f"| {name} | {demosaic} | {grey:.3f} | {colour:.3f} | "
                     f"{colour / grey - 1:+.0%} |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(markdown(measure()))
