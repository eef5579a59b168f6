"""Shared inputs for the benchmarks: the same random designs for every backend in a group."""

import numpy as np
import pytest


def designs(n: int, seed: int = 12345) -> dict:
    """``n`` phone-camera designs over the physical domain, shot-noise scene with shake."""
    rng = np.random.default_rng(seed)
    return {
        "illuminance_lux": 10 ** rng.uniform(0, 5, n),
        "pixel_pitch_um": rng.uniform(0.8, 3.0, n),
        "f_number": rng.uniform(1.4, 8.0, n),
        "focal_length_mm": rng.uniform(2.0, 20.0, n),
        "sensor_area_mm2": rng.uniform(1.0, 40.0, n),
        "shake_deg_per_s": rng.uniform(0.5, 10.0, n),
    }


@pytest.fixture(scope="session")
def designs_1e6():
    return designs(10**6)
