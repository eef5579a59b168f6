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
    return settings


def _designs(setting):
    designs = random_designs(POINTS, SEED)
    if setting.startswith("corner"):  # snr_at="corner" needs the sensor's width and height
        area = designs.pop("sensor_area_mm2")
        designs["sensor_width_mm"] = np.sqrt(area * 4 / 3)
        designs["sensor_height_mm"] = np.sqrt(area * 3 / 4)
    return designs


def digest_lines():
    """'setting output sha256' of every output array of every setting."""
    lines = [f"# isa {_core.isa}"]
    for setting, kwargs in _settings().items():
        result = epc_fast.evaluate(**_designs(setting), threads=2, **kwargs)
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
