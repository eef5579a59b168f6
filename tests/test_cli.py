"""The command line: build info, the self-check and the paper's design table."""

import subprocess
import sys

from epc_fast.__main__ import main
from epc_fast.selfcheck import self_check


def test_main_job_prints_build_self_check_and_design_table(capsys):
    assert main(["--check-points", "2000"]) == 0
    out = capsys.readouterr().out
    assert "epc_fast " in out
    assert "OpenMP: " in out and "threads: " in out
    assert "self-check passed" in out
    # The four 1/3.2" designs, one line each.
    assert sum(line.startswith('1/3.2"') for line in out.splitlines()) == 4


def test_self_check_finds_the_core_and_reference_in_agreement():
    report = self_check(3000, seed=7)
    assert report.statuses_equal
    # Both backends bisect f50 to ~1e-14 relative; 1e-12 is the stated agreement.
    assert report.max_rel_error <= 1e-12
    assert report.passed


def test_python_dash_m_runs_the_main_job():
    proc = subprocess.run([sys.executable, "-m", "epc_fast", "--check-points", "500"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "self-check passed" in proc.stdout
