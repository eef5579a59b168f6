"""The scene the optimiser's tests search over, and the check that a refusal names what it
refuses."""

import pytest

from epc_fast import scan
from epc_fast.presets import HIGH_TIER

#: The paper's 1/3.2" 1.75 um design: its format, lens and corner SNR target; the pitch is what
#: the tests optimise.
DESIGN = HIGH_TIER[2]
PITCH = {"pixel_pitch_um": (0.8, 4.0)}


def scene(**more):
    """Log-uniform 10..100,000 lux (and whatever else ``more`` draws) on the 1/3.2" design."""
    return scan.Space(design=[DESIGN], illuminance_lux=scan.LogUniform(10, 1e5), **more)


def shaky_scene():
    """Light and a log-normal hand shake: the EPC of different draws cross as the pitch
    changes, so no single draw decides a quantile."""
    return scene(shake_deg_per_s=scan.LogNormal(median=4.39, sigma=0.5))


def check_raises(error, text, call):
    """call() raises `error`, and its message holds `text`."""
    with pytest.raises(error) as caught:
        call()
    assert text in str(caught.value), str(caught.value)
