"""``--ref``: a commit resolved in a checkout, and a venv kept per commit (not built here: a
build takes minutes; bench/README.md gives the command that does)."""

import os
import re
import subprocess
from pathlib import Path

import pytest

from epc_fast.benchcompare import refbuild
from epc_fast.jobs.errors import UsageError

ROOT = Path(__file__).resolve().parents[2]


def _git_checkout():
    try:
        done = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"],
                              capture_output=True, text=True, timeout=60)
    except OSError:
        pytest.skip("git is not installed")
    if done.returncode != 0:
        pytest.skip("not a git checkout")
    return done.stdout.strip()


def test_a_ref_resolves_to_its_full_commit():
    head = _git_checkout()
    assert re.fullmatch(r"[0-9a-f]{40}", head)
    assert refbuild.resolve(ROOT, "HEAD") == head


def test_a_ref_that_names_no_commit_is_a_usage_error_naming_it():
    _git_checkout()
    with pytest.raises(UsageError, match="--ref 'no-such-branch-42'"):
        refbuild.resolve(ROOT, "no-such-branch-42")


def test_a_cached_venv_is_reused_without_a_build(tmp_path, monkeypatch):
    head = _git_checkout()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    python = tmp_path / "epc_fast" / "bench-ref" / head / "venv" / "bin" / "python"
    python.parent.mkdir(parents=True)
    python.write_text("")
    said = []
    command = refbuild.ref_python(ROOT, "HEAD", progress=said.append)
    assert command == f"env -u PYTHONPATH {python}"
    assert said == [f"--ref HEAD: commit {head[:12]}, cached in {python.parents[1]}"]


def test_the_cache_follows_xdg_cache_home(monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert refbuild.cache_root() == tmp_path / "epc_fast" / "bench-ref"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert refbuild.cache_root() == Path(os.path.expanduser("~")) / ".cache" / "epc_fast" / \
        "bench-ref"
