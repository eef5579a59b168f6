"""The package's environment variables (OMP_NUM_THREADS, EPC_FAST_ISA,
EPC_FAST_OUTPUT_CACHE_MB): checked as the arguments they stand for, an error naming the
variable and its value."""

import os
import subprocess
import sys

import pytest


@pytest.mark.parametrize("value, accepted", [("4", True), ("2,1", True), ("1024", True),
                                             ("1025", False), ("0", False), ("many", False)])
def test_omp_num_threads_is_checked_as_threads_is(monkeypatch, value, accepted):
    from epc_fast import _core

    monkeypatch.setenv("OMP_NUM_THREADS", value)
    if accepted:
        assert 1 <= _core.checked_default_threads() <= 1024
    else:
        with pytest.raises(ValueError, match=f"OMP_NUM_THREADS='{value}'"):
            _core.checked_default_threads()


@pytest.mark.parametrize("variable, value, message", [
    ("EPC_FAST_ISA", "x86-64-v9", "EPC_FAST_ISA='x86-64-v9': expected one of"),
    ("EPC_FAST_OUTPUT_CACHE_MB", "1e30", "EPC_FAST_OUTPUT_CACHE_MB='1e30': expected a size"),
    ("EPC_FAST_OUTPUT_CACHE_MB", "-1", "EPC_FAST_OUTPUT_CACHE_MB='-1': expected a size"),
])
def test_the_packages_environment_variables_are_checked_at_import(variable, value, message):
    env = dict(os.environ, **{variable: value})
    proc = subprocess.run([sys.executable, "-c", "import epc_fast._core"], env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and message in proc.stderr.splitlines()[-1]
