"""The optics and processing figures of docs/beyond.md, "Beyond the paper's camera": the best
denoising strength at each light level, a Bayer sensor with each demosaicker against the
monochrome one, and a designed lens's MTF table against the aberration-free lens, for the
paper's 1/3.2" designs.

    python tools/beyond_optics_figures.py [--out docs/images]

It prints the tables docs/beyond.md quotes (EPC at 10, 100, 1,000, 10,000 lux, each term on
against the paper's model).
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
from pathlib import Path

import numpy as np

from epc_fast import evaluate, spectra
from epc_fast.cfa import DEMOSAICS
from epc_fast.plotting.common import (add_conditions, conditions_lines, figure_class,
                                      save_figure)
from epc_fast.presets import HIGH_TIER

LUX = np.geomspace(1.0, 1e5, 121)
TABLE_LUX = (10.0, 100.0, 1000.0, 10_000.0)
#: sigma (output pixels) searched for the best denoising at each light level
SIGMAS = np.round(np.arange(0.0, 10.0001, 0.05), 2)
#: The designed lens: the pupil's MTF (epc_fast.simulate.pupil, FFT of a pupil) with this rms
#: defocus at the design's f-number and 550 nm, tabulated at 20 frequencies up to its cut-off,
#: as a lens maker's data sheet or an optical design program gives it.
LENS_DEFOCUS_WAVES = 0.07
LENS_POINTS = 20
WHAT = "the figures of docs/beyond.md"


def _kwargs(design):
    return design.evaluate_kwargs()


@functools.lru_cache(maxsize=1)
def bare_silicon_k() -> float:
    """e-/(lux s m^2): the least K of the Nikon D5100's silicon without its filters, the
    monochrome sensor of the colour sensor's own silicon (tools/cfa_defaults.py; the Bayer
    sensor's t is against K's sensor, QE 0.7 on 480..580 nm only)."""
    path = Path(__file__).resolve().parent / "cfa_defaults.py"
    spec = importlib.util.spec_from_file_location("cfa_defaults", path)
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool.bare_silicon_at_least() * spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2


def designed_lens_table(f_number: float, wavelength_nm: float = 550.0):
    """(frequencies_cyc_per_mm, mtf): the designed lens's table (LENS_DEFOCUS_WAVES of
    defocus), LENS_POINTS frequencies from 0 to the cut-off, the last at MTF 0."""
    from epc_fast.simulate.pupil import diffraction_transfer

    cutoff = 1.0 / (wavelength_nm * 1e-6 * f_number)
    f = np.linspace(0.0, cutoff, LENS_POINTS)
    mtf = diffraction_transfer(f, f_number, [wavelength_nm], [1.0], LENS_DEFOCUS_WAVES)
    mtf = np.minimum.accumulate(np.clip(mtf, 0.0, 1.0))  # a data sheet's falling curve
    mtf[0], mtf[-1] = 1.0, 0.0
    return f, mtf


def best_denoising(design, lux):
    """(sigma, EPC): the denoising sigma of SIGMAS with the highest EPC at each ``lux``."""
    grid = evaluate(np.asarray(lux)[:, None], **_kwargs(design), denoise_sigma_px=SIGMAS).epc
    best = np.argmax(grid, axis=1)
    return SIGMAS[best], grid[np.arange(grid.shape[0]), best]


def terms(design):
    """(label, evaluate keywords) of each term on its own, for ``design``."""
    lens = designed_lens_table(_kwargs(design)["f_number"])
    return [("the paper's model", {}),
            (f"wavefront error {LENS_DEFOCUS_WAVES} waves (Shannon's ATF)",
             {"wavefront_rms_waves": LENS_DEFOCUS_WAVES}),
            (f"designed lens table ({LENS_DEFOCUS_WAVES} waves defocus)", {"lens_mtf": lens}),
            ("denoising sigma 1", {"denoise_sigma_px": 1.0}),
            ("monochrome, the Bayer sensor's bare silicon",
             {"electrons_per_lux_s_m2": bare_silicon_k()}),
            *[(f"Bayer, {name}", {"cfa": "bayer", "demosaic": name}) for name in DEMOSAICS]]


def _scene(design) -> str:
    return (f"illuminance 1 to 100,000 lux; the paper's {design.name}: shot noise only, "
            "hand shake 4.39 deg/s")


def denoise_figure(design=HIGH_TIER[3]):
    Figure = figure_class(WHAT)
    fig = Figure(figsize=(7.6, 6.8), layout="constrained")
    ax, strip = fig.subplots(2, 1, height_ratios=(3, 1), sharex=True)
    for sigma, style in zip((0.0, 0.5, 1.0, 2.0), ("-", "--", "-.", ":")):
        ax.plot(LUX, evaluate(LUX, **_kwargs(design), denoise_sigma_px=sigma).epc / 1e6, style,
                color="tab:blue", lw=1.3, label=f"sigma {sigma:g} px")
    sigma, epc = best_denoising(design, LUX)
    ax.plot(LUX, epc / 1e6, color="black", lw=2.6, alpha=0.35, label="the best sigma")
    ax.set(xscale="log", yscale="log", ylabel="EPC (Mpixel)", ylim=(1e-5, 10),
           title=f"Denoising the paper's {design.name} design")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    strip.plot(LUX, sigma, color="black")
    strip.set(xscale="log", xlabel="Illuminance (lux)", ylabel="best sigma (px)")
    strip.grid(True, which="both", alpha=0.3)
    add_conditions(fig, conditions_lines(designs=[design.name],
                                         snr_target=[f"30 dB at {design.snr_at_text}, after the filter"],
                                         scene=_scene(design)))
    return fig


def bayer_figure(design=HIGH_TIER[3]):
    Figure = figure_class(WHAT)
    fig = Figure(figsize=(7.6, 5.4), layout="constrained")
    ax = fig.subplots()
    ax.plot(LUX, evaluate(LUX, **_kwargs(design)).epc / 1e6, color="black", lw=2.0,
            label="monochrome (the paper's model: K's sensor)")
    ax.plot(LUX, evaluate(LUX, **_kwargs(design), electrons_per_lux_s_m2=bare_silicon_k()).epc
            / 1e6, color="black", lw=1.3, ls="--",
            label="monochrome, the Bayer sensor's bare silicon")
    for name, color in zip(DEMOSAICS, ("tab:blue", "tab:orange", "tab:green")):
        ax.plot(LUX, evaluate(LUX, **_kwargs(design), cfa="bayer", demosaic=name).epc / 1e6,
                color=color, lw=1.3, label=f"Bayer, {name}")
    ax.set(xscale="log", yscale="log", xlabel="Illuminance (lux)", ylabel="EPC (Mpixel)",
           ylim=(1e-5, 10), title=f"A Bayer sensor against the monochrome {design.name} design")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    bare = bare_silicon_k() / spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2
    add_conditions(fig, conditions_lines(
        designs=[design.name], snr_target=[f"30 dB at {design.snr_at_text}, on the luminance"],
        scene=_scene(design) + "; the Nikon D5100's filters and colour correction (epc_fast.cfa), "
              f"its bare silicon at least {bare:.2f} K"))
    return fig


def lens_figure(design=HIGH_TIER[3]):
    Figure = figure_class(WHAT)
    fig = Figure(figsize=(7.6, 6.2), layout="constrained")
    ax, mtf_ax = fig.subplots(1, 2, width_ratios=(3, 2))
    f_number = _kwargs(design)["f_number"]
    table = designed_lens_table(f_number)
    ax.plot(LUX, evaluate(LUX, **_kwargs(design)).epc / 1e6, color="black", lw=2.0,
            label="aberration-free lens")
    ax.plot(LUX, evaluate(LUX, **_kwargs(design), lens_mtf=table).epc / 1e6, color="tab:red",
            lw=1.3, label="designed lens (table)")
    ax.plot(LUX, evaluate(LUX, **_kwargs(design), wavefront_rms_waves=LENS_DEFOCUS_WAVES).epc
            / 1e6, color="tab:red", lw=1.0, ls=":", label="Shannon's ATF, same rms")
    ax.set(xscale="log", yscale="log", xlabel="Illuminance (lux)", ylabel="EPC (Mpixel)",
           ylim=(1e-5, 10), title="EPC")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    f = np.linspace(0.0, table[0][-1], 400)
    from epc_fast.reference import mtf_diffraction

    mtf_ax.plot(f, mtf_diffraction(f, 550.0, f_number), color="black", label="aberration-free")
    mtf_ax.plot(*table, "o", color="tab:red", ms=3.5, label="the table")
    mtf_ax.set(xlabel="cycles/mm", ylabel="lens MTF", title=f"The lens at f/{f_number:g}")
    mtf_ax.grid(True, alpha=0.3)
    mtf_ax.legend(fontsize=8)
    add_conditions(fig, conditions_lines(
        designs=[design.name], snr_target=[f"30 dB at {design.snr_at_text}"],
        scene=_scene(design) + f"; the lens: a pupil with {LENS_DEFOCUS_WAVES} waves rms of "
              f"defocus at 550 nm, tabulated at {LENS_POINTS} frequencies"))
    return fig


def paper_table() -> str:
    lux = np.array(TABLE_LUX)
    rows = ["| design | term | " + " | ".join(f"{x:,.0f} lux" for x in TABLE_LUX) + " |",
            "|---|---|" + "---|" * len(TABLE_LUX)]
    for design in HIGH_TIER:
        base = evaluate(lux, **_kwargs(design)).epc
        for label, extra in terms(design):
            values = evaluate(lux, **_kwargs(design), **extra).epc
            cells = [f"{v / 1e6:.3g}" + ("" if not extra else f" ({v / b:.2f}x)")
                     for v, b in zip(values, base)]
            rows.append(f"| {design.name} | {label} | " + " | ".join(cells) + " |")
        sigma, values = best_denoising(design, lux)
        rows.append(f"| {design.name} | the best denoising | " + " | ".join(
            f"{v / 1e6:.3g} ({v / b:.2f}x, sigma {s:g})" for v, b, s in zip(values, base, sigma))
            + " |")
    return "\n".join(rows)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/images"))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    save_figure(denoise_figure(), args.out / "beyond_denoise.png")
    save_figure(bayer_figure(), args.out / "beyond_bayer.png")
    save_figure(lens_figure(), args.out / "beyond_lens.png")
    print(paper_table())


if __name__ == "__main__":
    main()
