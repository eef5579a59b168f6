"""The accuracy tables: this build's outputs and errors are the committed ones, and a change
is shown as a difference."""

import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from epc_fast.benchcompare.accuracy import TRAILER, check

ROOT = Path(__file__).resolve().parents[2]
TABLES = ROOT / "bench" / "baselines" / "accuracy"
HERE = shlex.quote(sys.executable)


def test_this_build_gives_the_committed_outputs_and_errors():
    pytest.importorskip("mpmath")
    equal, report = check(HERE, ROOT, TABLES)
    assert equal, "\n".join(report)
    assert report[0] == f"reference: same as {TABLES / 'reference.txt'}"


def test_a_changed_output_fails_with_the_difference_shown(tmp_path):
    pytest.importorskip("mpmath")
    for path in TABLES.glob("*.txt"):
        (tmp_path / path.name).write_text(path.read_text())
    table = tmp_path / "x86-64.txt"
    lines = table.read_text().splitlines()
    changed = lines[3].rsplit(" ", 1)[0] + " 0123456789abcdef"
    table.write_text("\n".join([*lines[:3], changed, *lines[4:]]) + "\n")
    equal, report = check(HERE, ROOT, tmp_path, isas=("x86-64",))
    assert not equal
    assert f"-{changed}" in report and f"+{lines[3]}" in report
    assert TRAILER in report[-1]


def test_update_writes_the_tables(tmp_path):
    pytest.importorskip("mpmath")
    equal, report = check(HERE, ROOT, tmp_path, isas=("x86-64",), update=True)
    assert equal and report[1] == f"x86-64: written {tmp_path / 'x86-64.txt'}"
    assert (tmp_path / "x86-64.txt").read_text() == (TABLES / "x86-64.txt").read_text()


def test_every_commit_that_changes_the_tables_declares_it():
    # a change of the outputs or the errors is declared in the commit that makes it: a line
    # starting "Accuracy-change:" in its message (docs/performance.md)
    try:
        log = subprocess.run(["git", "-C", str(ROOT), "log", "--format=%H%x00%B%x01", "--",
                              "bench/baselines/accuracy"], capture_output=True, text=True,
                             timeout=60)
    except OSError:
        pytest.skip("git is not installed")
    if log.returncode != 0 or not log.stdout.strip():
        pytest.skip("not a git checkout with the tables' history")
    undeclared = [entry.split("\0")[0][:12] for entry in log.stdout.split("\1") if entry.strip()
                  and not any(line.startswith(TRAILER) for line in entry.split("\0")[1]
                              .splitlines())]
    assert undeclared == []
