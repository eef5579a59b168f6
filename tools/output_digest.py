"""A digest of evaluate's outputs over fixed random designs, one line per setting and output.

Two builds, or a build before and after a change that should not alter a single bit, print the
same lines. Run it once per instruction-set level (EPC_FAST_ISA=x86-64, x86-64-v3, x86-64-v4):
the levels differ from each other (fused multiply-add), a level never from itself.

    EPC_FAST_ISA=x86-64-v3 python tools/output_digest.py > v3.txt
"""

from __future__ import annotations

import hashlib

import numpy as np

import epc_fast
from epc_fast import _core
from epc_fast.selfcheck import random_designs

POINTS = 20_000
SEED = 20261127


F50_EPC = ("f50_cyc_per_mm", "epc")


def _settings():
    spectrum = ([450.0, 550.0, 650.0], [0.25, 0.5, 0.25])
    settings = {
        "default": {},
        "shares+elasticities": {"outputs": ("epc", "f50_cyc_per_mm", "status", "cause",
                                            "share_diffraction", "share_pixel", "share_motion",
                                            "share_jitter", "elasticities")},
        "bisection": {"f50_solver": "bisection"},
        "brent": {"f50_solver": "brent", "t_mpe_solver": "brent"},
        "float32": {"precision": "float32"},
        "spectrum": {"spectrum": spectrum},
        "corner": {"snr_at": "corner", "jitter_um": 0.3, "dark_current_e_per_s": 5.0,
                   "prnu": 0.01, "full_well_e": 6000.0},
    }
    # f50 and EPC alone (the exposure's other values not formed): the same bits as above
    settings.update({f"{name}:f50+epc": dict(settings[name], outputs=F50_EPC)
                     for name in ("default", "corner", "float32")})
    settings.update(_real_camera_settings())
    return settings


LENS = ([0.0, 50.0, 100.0, 150.0, 200.0, 250.0, 300.0], [1.0, 0.88, 0.74, 0.60, 0.47, 0.36, 0.27])
LENS_FINE = (np.linspace(0.0, 400.0, 64), np.exp(-np.linspace(0.0, 400.0, 64) / 250.0))
MODES = [{"binning": 1}, {"binning": 2}, {"binning": 2, "frames": 4}]
SHARES = ("epc", "f50_cyc_per_mm", "status", "share_lens", "share_demosaic", "share_denoise",
          "share_aberration", "elasticities")


def _real_camera_settings():
    """The real-camera terms, alone and together (a phone: Bayer, a lens table, denoising and
    three readout modes), in float64 and float32."""
    bayer = {"cfa": "bayer", "demosaic": "malvar2004"}
    phone = {**bayer, "lens_mtf": LENS, "denoise_sigma_px": 1.0, "modes": MODES}
    settings = {
        "binning": {"binning": 2},
        "burst": {"frames": 4, "alignment_error_um": 0.3},
        "wavefront": {"wavefront_rms_waves": 0.05},
        "denoise 1": {"denoise_sigma_px": 1.0},
        "denoise 3": {"denoise_sigma_px": 3.0},
        "denoise per point": {"denoise_sigma_px": "per point"},
        "lens table": {"lens_mtf": LENS},
        "lens table 64": {"lens_mtf": LENS_FINE},
        "lens tables": {"lens_mtf": [LENS, LENS_FINE], "lens": "per point"},
        "bayer": bayer,
        "bayer menon": {"cfa": "bayer", "demosaic": "menon2007"},
        "quad bayer": {"cfa": "quad_bayer", "demosaic": "malvar2004"},
        "modes": {"modes": MODES},
        "both": {"epc_axes": "both"},
        "night": {"modes": [{"binning": 1}, {"binning": 2, "frames": "auto", "max_frames": 16}],
                  "max_exposure_s": 0.1},
        "phone": phone,
        "phone both": {**phone, "epc_axes": "both"},
        "phone shares": {**bayer, "lens_mtf": LENS, "denoise_sigma_px": 1.0, "outputs": SHARES},
    }
    settings["phone float32"] = dict(phone, precision="float32")
    return settings


def _designs(setting, kwargs):
    designs = random_designs(POINTS, SEED)
    rng = np.random.default_rng(SEED)
    if kwargs.get("denoise_sigma_px") == "per point":
        kwargs["denoise_sigma_px"] = rng.uniform(0.0, 5.0, POINTS)
    if kwargs.get("lens") == "per point":
        kwargs["lens"] = rng.integers(0, 2, POINTS)
    if setting.startswith("corner"):  # snr_at="corner" needs the sensor's width and height
        area = designs.pop("sensor_area_mm2")
        designs["sensor_width_mm"] = np.sqrt(area * 4 / 3)
        designs["sensor_height_mm"] = np.sqrt(area * 3 / 4)
    return designs


def digest_lines():
    """'setting output sha256' of every output array of every setting."""
    lines = [f"# isa {_core.isa}"]
    for setting, kwargs in _settings().items():
        kwargs = dict(kwargs)
        result = epc_fast.evaluate(**_designs(setting, kwargs), threads=2, **kwargs)
        arrays = {name: np.ascontiguousarray(value) for name, value in vars(result).items()
                  if isinstance(value, np.ndarray)}
        arrays.update({f"{group}.{key}": np.ascontiguousarray(value)
                       for group in ("elasticities",)
                       for key, value in (getattr(result, group, None) or {}).items()})
        for name in sorted(arrays):
            sha = hashlib.sha256(arrays[name].tobytes()).hexdigest()[:16]
            lines.append(f"{setting} {name} {arrays[name].dtype} {sha}")
    return lines


if __name__ == "__main__":
    print("\n".join(digest_lines()))
