"""The table of docs/beyond.md, "Each term counted in both directions": each term's EPC gain
over the paper's model for the paper's 1/3.2" 1.4 um and 2.8 um designs (30 dB at the image
corner, shot noise only), under the paper's count along the motion and counted in both
directions (epc_axes="both"; docs/model.md, "Resolution in both directions").

    python tools/beyond_axes_table.py
"""

from __future__ import annotations

import numpy as np

from epc_fast import evaluate
from epc_fast.presets import HIGH_TIER

LUX = (10.0, 100.0, 1_000.0, 10_000.0)
#: Each term as evaluate's keywords.
TERMS = {
    "2x2 binning, digital": {"binning": 2.0},
    "4 frames": {"frames": 4.0},
    "4 frames, 0.5 um alignment": {"frames": 4.0, "alignment_error_um": 0.5},
    "wavefront error 0.07 waves": {"wavefront_rms_waves": 0.07},
    "denoising sigma 1": {"denoise_sigma_px": 1.0},
    "Bayer, malvar2004": {"cfa": "bayer", "demosaic": "malvar2004"},
}
#: The denoising sigmas searched for the best one, output pixels.
SIGMAS = np.round(np.arange(0.0, 5.0001, 0.05), 2)


def _epc(design, epc_axes, **extra):
    return np.asarray(evaluate(np.asarray(LUX), **design.evaluate_kwargs(), **extra,
                               epc_axes=epc_axes).epc)


def _best_denoising(design, epc_axes) -> tuple:
    epc = np.stack([_epc(design, epc_axes, denoise_sigma_px=s) for s in SIGMAS])
    best = np.argmax(epc, axis=0)
    return epc[best, np.arange(len(LUX))], SIGMAS[best]


def table() -> str:
    lines = ["| design | term | " + " | ".join(f"{lux:,.0f} lux" for lux in LUX) + " |",
             "|---|---|" + "---|" * len(LUX)]
    for design in (HIGH_TIER[3], HIGH_TIER[0]):
        plain = {axes: _epc(design, axes) for axes in ("motion", "both")}
        rows = {name: {axes: (_epc(design, axes, **kw), None) for axes in plain}
                for name, kw in TERMS.items()}
        rows["the best denoising"] = {axes: _best_denoising(design, axes) for axes in plain}
        for name, by_axes in rows.items():
            cells = []
            for i in range(len(LUX)):
                parts = []
                for axes in ("motion", "both"):
                    value, sigma = by_axes[axes]
                    text = f"{value[i] / plain[axes][i]:.3g}x"
                    parts.append(text if sigma is None else f"{text} (sigma {sigma[i]:g})")
                cells.append(" / ".join(parts))
            lines.append(f"| {design.name} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    print(table())


if __name__ == "__main__":
    main()
