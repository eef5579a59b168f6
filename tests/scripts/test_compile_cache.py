"""cmake/compile_cache.py, the build's compile and link cache: a second build of the same
source from headers at another path (a new isolated environment's pybind11) compiles and links
nothing, gives the same bytes and writes the dependency file ninja reads; a changed header,
flag or object builds again."""

import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.scripts import ROOT

LAUNCHER = ROOT / "cmake" / "compile_cache.py"
COMPILER = shutil.which("g++") or shutil.which("c++")

pytestmark = pytest.mark.skipif(COMPILER is None or not LAUNCHER.exists(),
                                reason="no C++ compiler, or cmake/ is not beside the tests")

HEADER = '#pragma once\ninline const char* where() { return __FILE__; }\n' \
         'inline int twice(int x) { return 2 * x; }\n'
SOURCE = '#include <lib.h>\nint api(int x) { return twice(x) + (where()[0] != 0); }\n'


@pytest.fixture()
def tree(tmp_path):
    """A source, the same header at two paths, and a compiler that logs each real run."""
    for name in ("envA", "envB"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "lib.h").write_text(HEADER)
    (tmp_path / "unit.cpp").write_text(SOURCE)
    log = tmp_path / "runs.log"
    compiler = tmp_path / "cxx"
    compiler.write_text(f'#!/bin/sh\ncase " $* " in *" -E "*) ;; *" --version "*) ;; '
                        f'*) echo "$*" >> {log} ;; esac\nexec {COMPILER} "$@"\n')
    compiler.chmod(compiler.stat().st_mode | stat.S_IEXEC)
    return tmp_path


def _runs(tree):
    log = tree / "runs.log"
    return log.read_text().splitlines() if log.exists() else []


def _compile(tree, env, *extra):
    obj, dep = tree / "unit.o", tree / "unit.o.d"
    command = [sys.executable, str(LAUNCHER), str(tree / "cache"), str(tree / "cxx"),
               "-O2", "-fPIC", "-isystem", str(tree / env),
               f"-ffile-prefix-map={tree / env}=lib", *extra,
               "-MD", "-MT", str(obj), "-MF", str(dep), "-o", str(obj), "-c",
               str(tree / "unit.cpp")]
    subprocess.run(command, check=True, cwd=tree)
    return obj.read_bytes(), dep.read_text()


def _link(tree):
    out = tree / "libunit.so"
    command = [sys.executable, str(LAUNCHER), str(tree / "cache"), str(tree / "cxx"),
               "-shared", "-o", str(out), str(tree / "unit.o")]
    subprocess.run(command, check=True, cwd=tree)
    return out


def test_the_same_source_from_headers_at_another_path_is_compiled_once(tree):
    first, _ = _compile(tree, "envA")
    assert len(_runs(tree)) == 1
    (tree / "unit.o").unlink()
    (tree / "unit.o.d").unlink()
    second, dependencies = _compile(tree, "envB")
    assert len(_runs(tree)) == 1  # a hit: the compiler ran only to preprocess
    assert second == first
    # ninja reads the headers of this build, at their new path, from the dependency file
    assert str(tree / "envB" / "lib.h") in dependencies


def test_a_changed_header_or_flag_compiles_again(tree):
    _compile(tree, "envA")
    (tree / "envB" / "lib.h").write_text(HEADER.replace("2 * x", "3 * x"))
    _compile(tree, "envB")
    assert len(_runs(tree)) == 2
    _compile(tree, "envA", "-DSOMETHING=1")
    assert len(_runs(tree)) == 3
    _compile(tree, "envA")  # the first again: a hit
    assert len(_runs(tree)) == 3


def test_a_link_of_the_same_objects_is_done_once_and_keeps_the_modules_mode(tree):
    _compile(tree, "envA")
    first = _link(tree).read_bytes()
    _link(tree).unlink()
    module = _link(tree)
    links = [run for run in _runs(tree) if "-shared" in run]
    assert len(links) == 1 and module.read_bytes() == first
    assert os.access(module, os.X_OK)
    _compile(tree, "envA", "-O0")  # another object: linked again
    _link(tree)
    assert len([run for run in _runs(tree) if "-shared" in run]) == 2


def test_a_cache_that_cannot_be_written_only_costs_the_build(tree):
    (tree / "cache").write_text("a file where the cache's folder would be")
    obj, _ = _compile(tree, "envA")
    assert obj and len(_runs(tree)) == 1
    _compile(tree, "envA")
    assert len(_runs(tree)) == 2


def test_a_command_it_does_not_know_runs_as_it_is(tree):
    # no -o: preprocess to stdout, which the launcher neither keys nor keeps
    done = subprocess.run([sys.executable, str(LAUNCHER), str(tree / "cache"), COMPILER, "-E",
                           "-isystem", str(tree / "envA"), str(tree / "unit.cpp")],
                          capture_output=True, text=True, check=True)
    assert "twice" in done.stdout
    assert not (tree / "cache").exists() or not list(Path(tree / "cache").glob("*.o"))
