"""The core is built per x86-64 level (CMakeLists.txt): the fused-multiply-add levels (v3, v4)
give the same bits; the baseline agrees with them to the last bits."""

import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest

from epc_fast.selfcheck import random_designs

from epc_fast import _core

LEVELS = [level for level in ("x86-64", "x86-64-v3", "x86-64-v4")
          if _core.cpu_levels().get(level, level == "x86-64")]

SCRIPT = """
import sys, numpy as np, epc_fast
from epc_fast import _core
from epc_fast.selfcheck import random_designs
kw = random_designs(20000, seed=11)
kw["jitter_um"] = 0.5
r = epc_fast.evaluate(**kw, threads=2)
spectrum = epc_fast.spectra.Spectrum([480.0, 530.0, 580.0], [1, 2, 1])
s = epc_fast.evaluate(**kw, spectrum=spectrum)
# the spectrum's fitted f50 start (f50/spectrum_fit.h): fused levels give it the same bits
start = _core.testing.spectrum_start(spectrum.wavelengths_nm, spectrum.weights)["coefficients"]
np.savez(sys.argv[1], spectrum_start=start,
         **{f"{name}_{k}": getattr(x, k) for name, x in (("mono", r), ("poly", s))
            for k in ("t_mpe_s", "f50_cyc_per_mm", "epc", "status")})
print(_core.isa)
"""

EPS = np.finfo(float).eps
#: The levels with a hardware fused multiply-add, compiled with -ffp-contract=fast.
FUSED = ("x86-64-v3", "x86-64-v4")


def _run(level, tmp_path):
    env = dict(os.environ, EPC_FAST_ISA=level)
    path = tmp_path / f"{level}.npz"
    proc = subprocess.run([sys.executable, "-c", SCRIPT, str(path)], env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == [level]
    with np.load(path) as data:
        return dict(data)


@pytest.mark.skipif(bool(os.environ.get("EPC_FAST_ISA")),
                    reason="EPC_FAST_ISA chooses the module: no dispatch to check")
def test_the_widest_level_the_cpu_runs_is_loaded():
    built = [level for level in LEVELS
             if importlib.util.find_spec(f"epc_fast.{_core.MODULES[level]}") is not None]
    assert _core.isa == built[-1]


@pytest.mark.skipif(len(LEVELS) < 2, reason="this CPU runs only the baseline level")
def test_levels_agree_fused_ones_bit_for_bit(tmp_path):
    results = {level: _run(level, tmp_path) for level in LEVELS}
    # v3 and v4 fuse the same multiply-adds (the fusion is decided before vectorisation) and
    # run the same polynomials: the vector width changes how many lanes run per instruction,
    # never a bit of the result.
    fused = [results[level] for level in FUSED if level in results]
    for other in fused[1:]:
        for key, values in fused[0].items():
            np.testing.assert_array_equal(other[key], values, err_msg=key)
    # The baseline (no fused multiply-add) differs from them in the last bits only. The
    # statuses are equal. T_MPE is a few roundings deep; f50 and EPC amplify T_MPE's last ulp
    # by the blur's condition number kappa (up to ~1e4 near a right-angle shake in these
    # random designs, docs/numerics.md), so their bound is 64 ulp times max(1, kappa).
    base = results["x86-64"]
    for other in fused:
        for scene in ("mono", "poly"):
            np.testing.assert_array_equal(other[f"{scene}_status"], base[f"{scene}_status"])
            ok = base[f"{scene}_status"] == 0
            t_error = np.abs(other[f"{scene}_t_mpe_s"][ok] / base[f"{scene}_t_mpe_s"][ok] - 1)
            assert t_error.max() <= 8 * EPS, scene
            kappa = _blur_condition(np.where(ok, base[f"{scene}_t_mpe_s"], 0.0))[ok]
            for key in ("f50_cyc_per_mm", "epc"):
                a, b = other[f"{scene}_{key}"][ok], base[f"{scene}_{key}"][ok]
                error = np.abs(a / b - 1)
                assert np.all(error <= 64 * EPS * np.maximum(1.0, kappa)), (scene, key, error.max())
                assert np.any(error > 0), "the fused levels should differ in some last bit"


def _blur_condition(t_mpe_s):
    """kappa = 2 theta / sin(2 theta), theta the shake angle during T_MPE (rad), for the OK
    points of SCRIPT's monochromatic and polychromatic calls (the same designs)."""
    kw = random_designs(20000, seed=11)
    theta = np.deg2rad(kw["shake_deg_per_s"]) * t_mpe_s
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(theta > 0, 2.0 * theta / np.sin(2.0 * theta), 1.0)


def test_an_unknown_level_is_refused_with_a_clear_error():
    env = dict(os.environ, EPC_FAST_ISA="x86-64-v9")
    proc = subprocess.run([sys.executable, "-c", "import epc_fast._core"], env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode != 0 and "EPC_FAST_ISA='x86-64-v9'" in proc.stderr
