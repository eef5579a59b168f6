"""The answers docs/beyond.md gives a camera engineer, "A 50 MP quad-Bayer phone camera": for
the paper's 1/3.2" designs and a 50 MP 1.0 um quad-Bayer sensor (8.16 x 6.12 mm, f/1.9,
5.6 mm, read noise 1.5 e-, 30 dB at the image corner) at 1 to 10,000 lux: EPC along the motion
and in both directions, the readout mode each count picks among full size, 2x2 and 2x2 bursts
(night mode) under a 1/10 s frame cap, and the colour sensor (Malvar's demosaicker, the
default light reference: t = 0.8433 of K's sensor) against the monochrome sensor of its own
bare silicon (at least 1.80 K, docs/beyond.md "A colour sensor").

    python tools/real_camera_answers.py
"""

from __future__ import annotations

import numpy as np

from epc_fast import Status, evaluate
from epc_fast.presets import HIGH_TIER
from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2

LUX = (1.0, 10.0, 100.0, 1_000.0, 10_000.0)
#: s, the longest frame a hand-held phone takes.
FRAME_CAP_S = 0.1
#: The most frames night mode takes.
MAX_FRAMES = 16
#: The modes a phone reads its sensor in: full size, 2x2, and 2x2 bursts under the frame cap.
MODES = [{"binning": 1}, {"binning": 2},
         {"binning": 2, "frames": "auto", "max_frames": MAX_FRAMES}]
MODE_NAMES = ("full size", "2x2", "2x2 burst")
#: e-/(lux s m^2), the monochrome sensor of the colour sensor's bare silicon: at least 1.80 K
#: (tools/cfa_defaults.py, the D5100's channels' largest quantum efficiency at each wavelength).
BARE_SILICON_K = 1.80 * DEFAULT_ELECTRONS_PER_LUX_S_M2
#: The 50 MP 1.0 um quad-Bayer phone sensor (8160 x 6120 pixels), its lens and its readout.
PHONE = dict(pixel_pitch_um=1.0, sensor_width_mm=8.16, sensor_height_mm=6.12, f_number=1.9,
             focal_length_mm=5.6, read_noise_e=1.5, snr_at="corner")


def _cameras() -> dict:
    """{name: (evaluate's keywords, the colour sensor's keywords)}."""
    cameras = {d.name: (d.evaluate_kwargs(), {"cfa": "bayer"}) for d in HIGH_TIER}
    cameras["50 MP 1.0 um"] = (PHONE, {"cfa": "quad_bayer"})
    return cameras


def _picked(kwargs, epc_axes) -> tuple:
    result = evaluate(np.asarray(LUX), **kwargs, modes=MODES, max_exposure_s=FRAME_CAP_S,
                      epc_axes=epc_axes, outputs=("epc", "status", "frames_used"))
    return result.epc, result.mode, result.frames_used, result.status


def _cell(epc, mode, frames, status) -> str:
    if mode < 0 and status == Status.EXPOSURE_LIMIT:  # the first mode's status: full size
        return "over the cap"
    if not np.isfinite(epc):
        return Status(int(status)).name
    name = MODE_NAMES[mode]
    return f"{epc / 1e6:.3g} ({name} x{frames:g})" if mode == 2 else f"{epc / 1e6:.3g} ({name})"


def table() -> str:
    """EPC in Mpixel and the mode picked, per camera, sensor and count."""
    header = "| camera | sensor | count | " + " | ".join(f"{lux:,.0f} lux" for lux in LUX) + " |"
    lines = [header, "|---|---|---|" + "---|" * len(LUX)]
    for name, (kwargs, color) in _cameras().items():
        sensors = ((f"{color['cfa'].replace('_', ' ')}, malvar2004", {**kwargs, **color}),
                   ("monochrome, its bare silicon",
                    {**kwargs, "electrons_per_lux_s_m2": BARE_SILICON_K}))
        for sensor, call in sensors:
            for epc_axes, label in (("motion", "along the motion"), ("both", "both directions")):
                values = _picked(call, epc_axes)
                cells = [_cell(*(v[i] for v in values)) for i in range(len(LUX))]
                lines.append(f"| {name} | {sensor} | {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    print(table())


if __name__ == "__main__":
    main()
