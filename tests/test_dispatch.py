"""The core is built per x86-64 level (CMakeLists.txt); every level gives the same bits."""

import importlib.util
import os
import subprocess
import sys

import pytest

from epc_fast import _core

LEVELS = [level for level in ("x86-64", "x86-64-v3", "x86-64-v4")
          if _core.cpu_levels().get(level, level == "x86-64")]

SCRIPT = """
import hashlib, epc_fast
from epc_fast import _core
from epc_fast.selfcheck import random_designs
kw = random_designs(20000, seed=11)
kw["jitter_um"] = 0.5
r = epc_fast.evaluate(**kw, threads=2)
s = epc_fast.evaluate(**kw, spectrum=epc_fast.spectra.Spectrum([480.0, 530.0, 580.0], [1, 2, 1]))
digest = hashlib.sha1(b"".join(getattr(x, k).tobytes() for x in (r, s)
                               for k in ("t_mpe_s", "f50_cyc_per_mm", "epc", "status")))
print(_core.isa, digest.hexdigest())
"""


def _run(level):
    env = dict(os.environ, EPC_FAST_ISA=level)
    proc = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.split()


def test_the_widest_level_the_cpu_runs_is_loaded():
    built = [level for level in LEVELS
             if importlib.util.find_spec(f"epc_fast.{_core.MODULES[level]}") is not None]
    assert _core.isa == built[-1]


@pytest.mark.skipif(len(LEVELS) < 2, reason="this CPU runs only the baseline level")
def test_every_level_computes_bit_identical_results():
    # No fused multiply-add (-ffp-contract=off), IEEE division and sqrt, the same polynomials:
    # wider vectors change only how many lanes run per instruction, never a bit of the result.
    results = {level: _run(level) for level in LEVELS}
    digests = {digest for _, digest in results.values()}
    assert {isa for isa, _ in results.values()} == set(LEVELS)
    assert len(digests) == 1, results


def test_an_unknown_level_is_refused_with_a_clear_error():
    env = dict(os.environ, EPC_FAST_ISA="x86-64-v9")
    proc = subprocess.run([sys.executable, "-c", "import epc_fast._core"], env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode != 0 and "EPC_FAST_ISA='x86-64-v9'" in proc.stderr
