"""A quick check of the compiled core against the NumPy reference on random design points."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .api import evaluate
from .portable_math import exp10
from .status import Status

#: Relative agreement asked of T_MPE, f50 and EPC on OK points: both backends resolve f50 to
#: ~1e-14 (the core's default f50_rtol) and T_MPE to a few ulp, so 1e-12 leaves room.
TOLERANCE = 1e-12


@dataclass
class SelfCheck:
    points: int
    statuses_equal: bool
    max_rel_error: float

    @property
    def passed(self) -> bool:
        return self.statuses_equal and self.max_rel_error <= TOLERANCE

    def summary(self) -> str:
        verdict = "passed" if self.passed else "FAILED"
        return (f"self-check {verdict}: core vs reference on {self.points} random points, "
                f"statuses {'equal' if self.statuses_equal else 'DIFFER'}, "
                f"max relative error {self.max_rel_error:.1e} (limit {TOLERANCE:g})")


def random_designs(n: int, seed: int = 0) -> dict:
    """Keyword arguments for :func:`evaluate`: ``n`` phone-camera designs and scenes.

    The same bits on every CPU (:func:`epc_fast.portable_math.exp10`): the accuracy tables'
    digests hold them.
    """
    rng = np.random.default_rng(seed)
    return {
        "illuminance_lux": exp10(rng.uniform(0, 5, n)),
        "pixel_pitch_um": rng.uniform(0.8, 3.0, n),
        "f_number": rng.uniform(1.4, 8.0, n),
        "focal_length_mm": rng.uniform(2.0, 20.0, n),
        "sensor_area_mm2": rng.uniform(1.0, 40.0, n),
        "read_noise_e": np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0, 5, n)),
        "shake_deg_per_s": rng.uniform(0.0, 10.0, n),
    }


def self_check(n: int = 20000, seed: int = 0) -> SelfCheck:
    """Run both backends on ``n`` random designs and compare."""
    kwargs = random_designs(n, seed)
    core = evaluate(**kwargs)
    ref = evaluate(**kwargs, backend="reference")
    ok = ref.status == Status.OK
    worst = 0.0
    for name in ("t_mpe_s", "f50_cyc_per_mm", "epc"):
        a, b = getattr(core, name)[ok], getattr(ref, name)[ok]
        if a.size:
            worst = max(worst, float(np.max(np.abs(a / b - 1.0))))
    return SelfCheck(n, bool(np.array_equal(core.status, ref.status)), worst)
