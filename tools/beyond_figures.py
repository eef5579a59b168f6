"""The figures of docs/beyond.md, "Beyond the paper's camera": a 200 MP 0.56 um sensor read
1x1, 2x2 and 4x4 (digital and in charge) against a 50 MP 1.12 um sensor of the same size, with
the readout mode the camera picks; and bursts of 1, 4 and 16 frames.

    python tools/beyond_figures.py [--out docs/images]

It prints the tables docs/beyond.md quotes (EPC at 10, 100, 1,000, 10,000 lux).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from epc_fast import evaluate
from epc_fast.plotting.common import (add_conditions, conditions_lines, figure_class,
                                      save_figure)
from epc_fast.presets import Design

LUX = np.geomspace(1.0, 1e5, 241)
TABLE_LUX = (10.0, 100.0, 1000.0, 10_000.0)
#: A 1/1.3-inch phone format (9.14 x 6.85 mm) behind a 6.3 mm f/1.7 lens, the SNR target of
#: 30 dB met at the image corner; the sensors' noise is a modern phone sensor's.
FORMAT = dict(sensor_width_mm=9.14, sensor_height_mm=6.85, f_number=1.7, focal_length_mm=6.3,
              read_noise_e=1.5, dark_current_e_per_s=5.0, snr_at="corner")
SENSOR_200MP = Design("200 MP 0.56 um", pixel_pitch_um=0.56, full_well_e=6000.0, **FORMAT)
SENSOR_50MP = Design("50 MP 1.12 um", pixel_pitch_um=1.12, full_well_e=16000.0, **FORMAT)
READOUTS = (
    ("200 MP read 1x1", {}),
    ("200 MP 2x2, digital", {"binning": 2}),
    ("200 MP 4x4, digital", {"binning": 4}),
    ("200 MP 4x4, charge", {"binning": 4, "binning_readout": "charge"}),
)
MODES = [{"binning": 1}, {"binning": 2}, {"binning": 4, "binning_readout": "charge"}]
BURSTS = (1, 4, 16)
ALIGNMENT_UM = 0.5


def _epc(design, lux, **extra):
    return np.asarray(evaluate(lux, **{**design.evaluate_kwargs(), **extra}).epc)


def binning_figure():
    Figure = figure_class("the figures of docs/beyond.md")
    fig = Figure(figsize=(7.6, 6.8), layout="constrained")
    ax, strip = fig.subplots(2, 1, height_ratios=(5, 1), sharex=True)
    for (label, readout), style in zip(READOUTS, ("-", "--", "-.", ":")):
        ax.plot(LUX, _epc(SENSOR_200MP, LUX, **readout) / 1e6, style, color="tab:blue",
                lw=1.3, label=label, zorder=3)
    ax.plot(LUX, _epc(SENSOR_50MP, LUX) / 1e6, color="tab:orange", lw=3.0, alpha=0.8,
            label="50 MP read 1x1", zorder=2)
    picked = evaluate(LUX, **SENSOR_200MP.evaluate_kwargs(), modes=MODES)
    ax.plot(LUX, np.asarray(picked.epc) / 1e6, color="black", lw=2.6, alpha=0.35,
            label="200 MP, the mode the camera picks")
    ax.set(xscale="log", yscale="log", ylabel="EPC (Mpixel)", ylim=(1e-3, 300),
           title="A 200 MP 0.56 µm sensor binned, against 50 MP 1.12 µm of the same size")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    names = ["1x1", "2x2 digital", "4x4 charge"]
    colors = ["tab:green", "tab:purple", "tab:red"]
    mode = np.asarray(picked.mode)
    for i, (name, color) in enumerate(zip(names, colors)):
        on = mode == i
        strip.fill_between(LUX, 0, 1, where=on, color=color, alpha=0.7, step="mid",
                           label=name)
    strip.set(yticks=[], xlabel="Illuminance (lux)", xscale="log")
    strip.set_title("mode picked", fontsize=9, loc="left")
    strip.legend(fontsize=8, ncols=3, loc="center right")
    add_conditions(fig, conditions_lines(
        designs=[SENSOR_200MP.name, SENSOR_50MP.name],
        snr_target=[f"30 dB at {SENSOR_200MP.snr_at_text}"],
        scene="illuminance 1 to 100,000 lux; 9.14 x 6.85 mm, 6.3 mm f/1.7; read noise 1.5 e-, "
              "dark current 5 e-/s; hand shake 4.39 deg/s",
        extra=["EPC = 4 S f50^2 on the sensor's area S for every readout"]))
    return fig


def bursts_figure():
    Figure = figure_class("the figures of docs/beyond.md")
    fig = Figure(figsize=(7.6, 5.4), layout="constrained")
    ax = fig.subplots()
    for n, color in zip(BURSTS, ("black", "tab:blue", "tab:red")):
        extra = {} if n == 1 else {"frames": n, "alignment_error_um": ALIGNMENT_UM}
        ax.plot(LUX, _epc(SENSOR_50MP, LUX, **extra) / 1e6, color=color, lw=1.6,
                label=f"{n} frame{'s' if n > 1 else ''}")
        if n > 1:
            ax.plot(LUX, _epc(SENSOR_50MP, LUX, frames=n) / 1e6, color=color, lw=0.9, ls=":",
                    label=f"{n} frames, perfect alignment")
    ax.set(xscale="log", yscale="log", xlabel="Illuminance (lux)", ylabel="EPC (Mpixel)",
           ylim=(1e-3, 100), title="Bursts: the 50 MP 1.12 µm sensor in 1, 4 and 16 frames")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    add_conditions(fig, conditions_lines(
        designs=[SENSOR_50MP.name], snr_target=[f"30 dB at {SENSOR_50MP.snr_at_text}"],
        scene="illuminance 1 to 100,000 lux; 9.14 x 6.85 mm, 6.3 mm f/1.7; read noise 1.5 e- "
              f"a frame; alignment error {ALIGNMENT_UM} um rms a frame; hand shake 4.39 deg/s"))
    return fig


def tables() -> str:
    rows = ["| readout | " + " | ".join(f"{x:,.0f} lux" for x in TABLE_LUX) + " |",
            "|---|" + "---|" * len(TABLE_LUX)]

    def row(label, values):
        rows.append(f"| {label} | " + " | ".join(f"{v / 1e6:.3g}" for v in values) + " |")

    lux = np.array(TABLE_LUX)
    for label, readout in READOUTS:
        row(label, _epc(SENSOR_200MP, lux, **readout))
    picked = evaluate(lux, **SENSOR_200MP.evaluate_kwargs(), modes=MODES)
    rows.append("| 200 MP, the mode the camera picks | " + " | ".join(
        f"{e / 1e6:.3g} ({['1x1', '2x2', '4x4 charge'][m]})"
        for e, m in zip(picked.epc, picked.mode)) + " |")
    row("50 MP read 1x1", _epc(SENSOR_50MP, lux))
    for n in BURSTS[1:]:
        row(f"50 MP, {n} frames ({ALIGNMENT_UM} um alignment)",
            _epc(SENSOR_50MP, lux, frames=n, alignment_error_um=ALIGNMENT_UM))
    return "\n".join(rows)


#: Each readout term on its own, for the paper's 1/3.2" designs (the closing table of
#: docs/beyond.md): the model as the paper has it, then one term at a time.
PAPER_TERMS = (("the paper's model", {}), ("2x2 binning, digital", {"binning": 2}),
               ("2x2 binning, charge, read noise 2 e-", {"binning": 2,
                                                         "binning_readout": "charge",
                                                         "read_noise_e": 2.0}),
               ("4 frames", {"frames": 4}),
               ("4 frames, 0.5 um alignment", {"frames": 4, "alignment_error_um": 0.5}))


def paper_table() -> str:
    from epc_fast.presets import HIGH_TIER

    lux = np.array(TABLE_LUX)
    rows = ["| design | term | " + " | ".join(f"{x:,.0f} lux" for x in TABLE_LUX) + " |",
            "|---|---|" + "---|" * len(TABLE_LUX)]
    for design in HIGH_TIER:
        base = _epc(design, lux)
        for label, extra in PAPER_TERMS:
            values = _epc(design, lux, **extra)
            cells = [f"{v / 1e6:.3g}" + ("" if not extra else f" ({v / b:.2f}x)")
                     for v, b in zip(values, base)]
            rows.append(f"| {design.name} | {label} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/images"))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    save_figure(binning_figure(), args.out / "beyond_binning.png")
    save_figure(bursts_figure(), args.out / "beyond_bursts.png")
    print(tables())
    print()
    print(paper_table())


if __name__ == "__main__":
    main()
