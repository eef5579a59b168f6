"""portable_math: elementary functions the same bits on every CPU, a few ulp from mpmath; and
what is made from them (the random designs, the corner's field angle, evaluate's outputs for
both) unchanged when NumPy's AVX-512 code is turned off, as on a CPU without AVX-512."""

import hashlib
import os
import subprocess
import sys

import numpy as np
import pytest

from epc_fast.portable_math import arctan_deg, exp10

mpmath = pytest.importorskip("mpmath")


def _exact(function, values):
    with mpmath.workprec(120):
        return np.array([float(function(mpmath.mpf(float(v)))) for v in values])


@pytest.mark.parametrize("low, high, rtol", [
    # the rounding of u·log2(10) to float64 (relative 2**-53 of up to 16.6, times ln 2)
    (0.0, 5.0, 2e-15),
    # the same rounding of up to 1,000 (|u| <= 300): ~60 times as large
    (-300.0, 300.0, 1e-13),
])
def test_exp10_is_within_its_stated_error_of_mpmath(low, high, rtol):
    u = np.random.default_rng(7).uniform(low, high, 3000)
    exact = _exact(lambda x: mpmath.power(10, x), u)
    assert np.max(np.abs(exp10(u) / exact - 1.0)) <= rtol


def test_exp10_of_integers_and_its_edges():
    assert np.allclose(exp10([0.0, 1.0, 2.0, 5.0, -1.0]), [1, 10, 100, 1e5, 0.1], rtol=2e-15,
                       atol=0)
    assert np.isnan(exp10(np.nan))
    assert exp10(-np.inf) == 0.0


def test_arctan_deg_is_within_eight_ulp_of_mpmath():
    # each of the two argument halvings rounds a square root, a sum and a quotient; the series
    # and the scaling to degrees add a few more roundings: 5 ulp measured, 8 allowed
    rng = np.random.default_rng(8)
    x = np.concatenate([rng.uniform(0, 1, 2000), 10 ** rng.uniform(-12, 12, 2000),
                        -rng.uniform(0, 3, 500)])
    exact = _exact(lambda v: mpmath.degrees(mpmath.atan(v)), x)
    assert np.max(np.abs(arctan_deg(x) - exact) / np.spacing(np.abs(exact))) <= 8


def test_arctan_deg_of_its_edges():
    got = arctan_deg([0.0, -0.0, 1.0, np.inf, -np.inf, np.nan, 1e300])
    assert got[0] == 0.0 and np.signbit(got[1])
    assert got[2] == pytest.approx(45.0, rel=4e-16)
    assert list(got[3:5]) == [90.0, -90.0] and np.isnan(got[5]) and got[6] == 90.0


_DIGEST = """
import hashlib, numpy as np, epc_fast
from epc_fast.selfcheck import random_designs
from epc_fast.sensor import corner_field_angle_deg
d = random_designs(4000, 20261127)
area = d.pop("sensor_area_mm2")
d["sensor_width_mm"], d["sensor_height_mm"] = np.sqrt(area * 4 / 3), np.sqrt(area * 3 / 4)
r = epc_fast.evaluate(**d, snr_at="corner", threads=1)
arrays = [*d.values(), corner_field_angle_deg(d["sensor_width_mm"], d["sensor_height_mm"],
                                              d["focal_length_mm"]), r.epc, r.t_mpe_s]
print(hashlib.sha256(b"".join(np.ascontiguousarray(a).tobytes() for a in arrays)).hexdigest())
"""


def _numpy_simd_above_avx2():
    from numpy._core._multiarray_umath import __cpu_dispatch__  # noqa: PLC0415

    return [f for f in __cpu_dispatch__ if f.startswith(("AVX512", "X86_V4"))]


def test_designs_and_corner_outputs_are_the_same_bits_without_numpys_avx512_code():
    try:
        wider = _numpy_simd_above_avx2()
    except ImportError:
        pytest.skip("this NumPy does not list its dispatched features")
    if not wider:
        pytest.skip("this NumPy has no code above AVX2 to turn off")
    digests = []
    for disabled in ("", " ".join(wider)):
        env = dict(os.environ, NPY_DISABLE_CPU_FEATURES=disabled)
        done = subprocess.run([sys.executable, "-c", _DIGEST], env=env, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        digests.append(done.stdout.strip())
    assert digests[0] == digests[1]
    assert len(digests[0]) == len(hashlib.sha256().hexdigest())
