"""Where ``epc-fast bench compare`` writes its reports: ``--out`` is checked before the first
round (a file, a folder that cannot be written, a report's name taken by a folder), and
compare.md and compare.json are each written whole or not at all (a full disk leaves the
previous file, or none, and no temporary file)."""

import errno
import json
import os
import pathlib
import shlex
import sys

import pytest

from epc_fast.__main__ import main

#: A side that answers every request at once with the same made-up times.
FAKE_SIDE = '''
import json, sys
build = {"version": "0.0", "isa": "fake", "openmp": False, "python": "3", "numpy": "2",
         "executable": sys.executable, "module": "fake"}
for line in sys.stdin:
    request = json.loads(line)
    if request["op"] == "quit":
        break
    if request["op"] == "setup":
        reply = {"build": build, "seconds": {name: 0.001 for name in request["workloads"]},
                 "unavailable": {}}
    else:
        reply = {"seconds": 0.001, "cpu_seconds": 0.001}
    print(json.dumps(reply), flush=True)
'''


@pytest.fixture
def side(tmp_path):
    script = tmp_path / "fake_side.py"
    script.write_text(FAKE_SIDE)
    return f"{shlex.quote(sys.executable)} {shlex.quote(str(script))}"


def _compare(side, out):
    return main(["bench", "compare", "--only", "default-1e4", "--rounds", "3", "--blocks", "1",
                 "--out", str(out), side, side])


def _refused_before_the_first_round(capsys, *words):
    err = capsys.readouterr().err
    assert "block 1" not in err  # no side was started
    assert all(word in err for word in words), err
    assert err.count("\n") == 1


def test_an_out_that_is_a_file_is_refused_before_the_first_round(side, tmp_path, capsys):
    out = tmp_path / "compare-here"
    out.write_text("a file\n")
    assert _compare(side, out) == 2
    _refused_before_the_first_round(capsys, f"--out {str(out)!r}", "is not a folder")
    assert out.read_text() == "a file\n"


def test_an_out_under_a_file_is_refused_before_the_first_round(side, tmp_path, capsys):
    (tmp_path / "file").write_text("")
    assert _compare(side, tmp_path / "file" / "out") == 2
    _refused_before_the_first_round(capsys, "--out", "cannot create it: Not a directory")


def test_a_read_only_out_is_refused_before_the_first_round(side, tmp_path, capsys,
                                                           monkeypatch):
    # Tests run as root, which writes through permission bits: every open for writing in the
    # folder fails as on a read-only file system.
    out = tmp_path / "out"
    out.mkdir()
    real_open = os.open

    def read_only_open(path, flags, *args, **kwargs):
        if str(path).startswith(str(out)) and flags & (os.O_WRONLY | os.O_RDWR):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(path))
        return real_open(path, flags, *args, **kwargs)

    monkeypatch.setattr(os, "open", read_only_open)
    assert _compare(side, out) == 2
    _refused_before_the_first_round(capsys, f"--out {str(out)!r}",
                                    "is not writable: Read-only file system")
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("name", ["compare.md", "compare.json"])
def test_a_report_name_taken_by_a_folder_is_refused_before_the_first_round(name, side, tmp_path,
                                                                           capsys):
    (tmp_path / "out" / name).mkdir(parents=True)
    assert _compare(side, tmp_path / "out") == 2
    _refused_before_the_first_round(capsys, "--out", f"{name} is a folder")


@pytest.mark.parametrize("name", ["compare.md", "compare.json"])
def test_a_full_disk_leaves_the_previous_reports_and_names_the_file(name, side, tmp_path,
                                                                    capsys, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    for previous in ("compare.md", "compare.json"):
        (out / previous).write_text("previous\n")
    real_write_text = pathlib.Path.write_text

    def fill_the_disk(self, text, *args, **kwargs):
        if name not in self.name:
            return real_write_text(self, text, *args, **kwargs)
        with open(self, "w") as handle:
            handle.write(text[:len(text) // 2])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(pathlib.Path, "write_text", fill_the_disk)
    assert _compare(side, out) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"cannot write {out / name}: No space left on device" in err
    assert (out / name).read_text() == "previous\n"  # never a torn report
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "compare.md"]


def test_the_reports_replace_the_previous_ones_whole(side, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "compare.json").write_text("previous\n")
    assert _compare(side, out) == 0
    assert json.loads((out / "compare.json").read_text())["passed"] is True
    assert (out / "compare.md").read_text().startswith("# epc-fast bench compare: **PASS**")
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "compare.md"]
