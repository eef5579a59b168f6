"""A scan never loses or clobbers data: everything inside --out, nothing replaced without
--overwrite, files written whole, a manifest that says how far the scan got, interruption
(SIGINT, SIGTERM, SIGKILL) leaving a consistent prefix, output failures found before the work.
"""

import csv
import errno
import json
import os
import pathlib
import signal
import subprocess
import sys
import time
import types

import pytest

import epc_fast.scan.output
import epc_fast.scan.running.runner
from epc_fast.__main__ import main
from epc_fast.jobs.atomic import atomic_write

CONFIG = """\
[scan]
points = 200_000
seed = 7

[design]
presets = ["HIGH_TIER"]

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }

[reductions.summary]
kind = "summary"
by = "design"
"""
CHUNK = 65536


def _config(tmp_path, extra="", name="scan.toml"):
    path = tmp_path / name
    path.write_text(CONFIG + extra)
    return path


def _cli(capsys, *args):
    code = main(["scan", *map(str, args), "--no-progress"])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def _manifest(directory):
    return json.loads((directory / "manifest.json").read_text())


class _Chunks:
    """The scan's chunk task (draw, evaluate, reduce, write Parquet), counting its calls; the
    ``stop_at``-th finishes its work then raises KeyboardInterrupt, as Ctrl-C arriving before
    its merge would."""

    def __init__(self, stop_at=None):
        self.calls = 0
        self.stop_at = stop_at
        self.reduce_chunk = epc_fast.scan.running.runner.reduce_chunk

    def __call__(self, *args, **kwargs):
        self.calls += 1
        outcome = self.reduce_chunk(*args, **kwargs)
        if self.calls == self.stop_at:
            raise KeyboardInterrupt
        return outcome


@pytest.fixture
def chunks(monkeypatch):
    counter = _Chunks()
    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", counter)
    return counter


# --- everything stays inside --out --------------------------------------------------------

@pytest.mark.parametrize("extra, key", [
    ('[reductions."/tmp/x"]\nkind = "top_k"\n', "reduction's name = '/tmp/x'"),
    ('[reductions."../up"]\nkind = "top_k"\n', "reduction's name = '../up'"),
    ('[output]\nparquet = "../../x"\n', "parquet = '../../x'"),
    ('[output]\nparquet = "/tmp/points"\n', "parquet = '/tmp/points'"),
])
def test_a_name_that_leaves_out_is_refused_before_any_work(tmp_path, capsys, chunks,
                                                             extra, key):
    out = tmp_path / "deep" / "er" / "out"
    code, _, err = _cli(capsys, _config(tmp_path, extra), "--out", out)
    assert code == 2 and key in err and "no / or .." in err
    assert chunks.calls == 0 and not (tmp_path / "deep").exists()
    assert not os.path.exists("/tmp/x.csv") or os.path.getmtime("/tmp/x.csv") < time.time() - 60


def test_a_reduction_named_like_a_table_is_refused_not_clobbering_it(tmp_path, capsys,
                                                                     chunks):
    extra = '[reductions.summary_by_design]\nkind = "top_k"\n'
    code, _, err = _cli(capsys, _config(tmp_path, extra), "--out", tmp_path / "out")
    assert code == 2 and chunks.calls == 0
    assert "would both write summary_by_design.csv" in err


def test_a_directory_that_is_not_empty_is_refused_without_overwrite(tmp_path, capsys,
                                                                    chunks):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary_by_design.csv").write_text("mine\n")
    code, _, err = _cli(capsys, _config(tmp_path), "--out", out)
    assert code == 2 and chunks.calls == 0
    assert "not empty" in err and "--overwrite replaces summary_by_design.csv" in err
    assert (out / "summary_by_design.csv").read_text() == "mine\n"


def test_overwrite_replaces_only_this_scans_files_and_never_follows_a_symlink(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("keep me\n")
    outside = tmp_path / "precious.csv"
    outside.write_text("precious\n")
    (out / "summary_by_design.csv").symlink_to(outside)
    code, _, _ = _cli(capsys, _config(tmp_path), "--out", out, "--overwrite")
    assert code == 0
    assert outside.read_text() == "precious\n"
    assert not (out / "summary_by_design.csv").is_symlink()
    assert len(_rows(out / "summary_by_design.csv")) == 4
    assert (out / "notes.txt").read_text() == "keep me\n"
    assert set(_manifest(out)["files"]) == {"summary_by_design.csv", "summary_by_design.md"}


def test_a_parquet_directory_that_is_a_symlink_is_refused(tmp_path, capsys, chunks):
    pytest.importorskip("pyarrow")
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "points").symlink_to(elsewhere)
    code, _, err = _cli(capsys, _config(tmp_path, '[output]\nparquet = "points"\n'), "--out",
                        out, "--overwrite")
    assert code == 2 and "symlink is not followed" in err and chunks.calls == 0
    assert not list(elsewhere.iterdir())


# --- failures found before the first point ------------------------------------------------

def test_a_full_disk_is_found_before_the_first_point(tmp_path, capsys, monkeypatch, chunks):
    usage = types.SimpleNamespace(total=10**9, used=10**9 - 4096, free=4096)
    fake_shutil = types.SimpleNamespace(disk_usage=lambda path: usage)
    monkeypatch.setattr(epc_fast.jobs.output.directory, "shutil", fake_shutil)
    code, _, err = _cli(capsys, _config(tmp_path), "--out", tmp_path / "out")
    assert code == 2 and chunks.calls == 0
    assert "4.1 KB free" in err and "this scan writes up to" in err


def test_a_read_only_directory_is_found_before_the_first_point(tmp_path, capsys, monkeypatch,
                                                               chunks):
    # Tests run as root, which writes through permission bits: the probe's open fails as on a
    # read-only file system.
    def read_only_open(path, flags, mode=0o777):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(path))

    fake_os = types.SimpleNamespace(**{**vars(os), "open": read_only_open})
    monkeypatch.setattr(epc_fast.jobs.atomic, "os", fake_os)
    code, _, err = _cli(capsys, _config(tmp_path), "--out", tmp_path / "out")
    assert code == 2 and chunks.calls == 0
    assert "is not writable: Read-only file system" in err


def test_a_parquet_scan_asking_more_than_the_free_space_is_refused(tmp_path, capsys, monkeypatch,
                                                                   chunks):
    pytest.importorskip("pyarrow")
    usage = types.SimpleNamespace(total=10**12, used=0, free=10**9)
    monkeypatch.setattr(epc_fast.jobs.output.directory, "shutil",
                        types.SimpleNamespace(disk_usage=lambda path: usage))
    code, _, err = _cli(capsys, _config(tmp_path, '[output]\nparquet = "points"\n'), "--out",
                        tmp_path / "out", "--points", "1e9")
    assert code == 2 and "Parquet" in err and chunks.calls == 0


# --- files written whole -----------------------------------------------------------------

def test_a_full_disk_while_writing_leaves_the_previous_file_and_no_temporary(tmp_path):
    target = tmp_path / "table.md"
    target.write_text("previous\n")

    def write_then_fill(path):
        with open(path, "w") as handle:
            handle.write("| half a tab")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with pytest.raises(OSError, match="No space left"):
        atomic_write(target, write_then_fill)
    assert target.read_text() == "previous\n"
    assert [p.name for p in tmp_path.iterdir()] == ["table.md"]


def test_a_parquet_part_that_fails_midway_is_never_under_a_part_name(tmp_path, monkeypatch):
    pq = pytest.importorskip("pyarrow.parquet")
    from epc_fast.scan import Space, run
    from epc_fast.presets import HIGH_TIER

    real_write = pq.write_table
    calls = []

    def write_half_then_die(table, path, **kwargs):
        calls.append(path)
        if len(calls) == 2:
            with open(path, "wb") as handle:
                handle.write(b"PAR1 truncated")
            raise KeyboardInterrupt
        return real_write(table, path, **kwargs)

    monkeypatch.setattr(pq, "write_table", write_half_then_die)
    space = Space(design=HIGH_TIER, illuminance_lux=1000.0)
    result = run(space, 3 * CHUNK, seed=1, chunk_points=CHUNK, progress=False,
                 parquet=tmp_path / "points")
    assert result.partial and result.points == CHUNK
    names = sorted(p.name for p in (tmp_path / "points").iterdir())
    assert names == ["part-000000000000.parquet"]
    assert pq.read_table(tmp_path / "points").num_rows == CHUNK


# --- interruption: one consistent prefix everywhere, and a manifest that says so ---------

def test_ctrl_c_leaves_parquet_tables_and_manifest_on_the_same_prefix(tmp_path, capsys,
                                                                      monkeypatch):
    pq = pytest.importorskip("pyarrow.parquet")
    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", _Chunks(stop_at=3))
    out = tmp_path / "out"
    code, stdout, _ = _cli(capsys, _config(tmp_path, '[output]\nparquet = "points"\n'),
                           "--out", out, "--chunk-points", CHUNK)
    assert code == 130 and "INTERRUPTED" in stdout
    table = pq.read_table(out / "points")
    counted = sum(int(r["points"]) for r in _rows(out / "summary_by_design.csv"))
    manifest = _manifest(out)
    assert table.num_rows == counted == manifest["points_done"] == 2 * CHUNK
    assert table.column("point").to_pylist() == list(range(2 * CHUNK))
    assert manifest["partial"] is True and manifest["state"] == "interrupted"
    assert manifest["stopped_by"] == "SIGINT"
    assert "points/part-000000000000.parquet" in manifest["files"]
    assert not [p for p in (out / "points").iterdir() if p.name.startswith(".")]


def test_a_complete_scan_has_a_manifest_of_what_it_wrote(tmp_path, capsys):
    import epc_fast

    out = tmp_path / "out"
    assert _cli(capsys, _config(tmp_path), "--out", out, "--seed", "11")[0] == 0
    manifest = _manifest(out)
    assert manifest["state"] == "complete" and manifest["partial"] is False
    assert manifest["points_done"] == manifest["points_requested"] == 200_000
    assert manifest["seed"] == 11 and manifest["overrides"] == {"seed": 11}
    assert manifest["epc_fast_version"] == epc_fast.__version__
    assert manifest["config"] == (tmp_path / "scan.toml").read_text()
    assert all((out / name).is_file() for name in manifest["files"])


def _scan_process(config, out, *extra):
    return subprocess.Popen([sys.executable, "-m", "epc_fast", "scan", str(config), "--out",
                             str(out), "--no-progress", "--no-plots", "--chunk-points",
                             str(CHUNK), *extra], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _wait_for_chunks(process, out, chunks, timeout=120, seed=7):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            manifest = _manifest(out)
            if manifest["points_done"] >= chunks * CHUNK and manifest["seed"] == seed:
                return
        except (OSError, ValueError):
            pass
        assert process.poll() is None, process.communicate()
        time.sleep(0.05)
    pytest.fail("the scan did not get going")


def test_sigterm_stops_between_chunks_and_writes_the_prefix(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    config = _config(tmp_path, '[output]\nparquet = "points"\n')
    out = tmp_path / "out"
    process = _scan_process(config, out, "--points", "2e7")
    _wait_for_chunks(process, out, 2)
    process.send_signal(signal.SIGTERM)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 143, stderr
    manifest = _manifest(out)
    done = manifest["points_done"]
    assert manifest["state"] == "interrupted" and manifest["stopped_by"] == "SIGTERM"
    assert 2 * CHUNK <= done < 20_000_000 and f"scan of {done:,} of" in stdout
    assert sum(int(r["points"]) for r in _rows(out / "summary_by_design.csv")) == done
    assert pq.read_table(out / "points").num_rows == done


def test_a_rerun_into_a_killed_scans_directory_says_what_it_found(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    config = _config(tmp_path, '[output]\nparquet = "points"\n')
    out = tmp_path / "out"
    process = _scan_process(config, out, "--points", "2e7")
    _wait_for_chunks(process, out, 2)
    process.kill()
    process.communicate(timeout=60)
    # What was renamed into place is whole and a prefix of the points.
    table = pq.read_table(out / "points")
    assert table.column("point").to_pylist() == list(range(table.num_rows))
    assert table.num_rows >= _manifest(out)["points_done"] >= 2 * CHUNK
    code, _, err = _cli(capsys, config, "--out", out)
    assert code == 2 and "a scan that did not finish" in err
    assert "it was killed (no run holds this directory's lock)" in err
    assert "still running" not in err
    assert "--overwrite" in err
    code, _, _ = _cli(capsys, config, "--out", out, "--overwrite", "--no-plots")
    assert code == 0 and pq.read_table(out / "points").num_rows == 200_000
    assert not [p for p in out.rglob(".*")]


def test_sigterm_stops_scan_run_between_chunks_with_a_partial_result(tmp_path):
    script = tmp_path / "scan.py"
    script.write_text(f"""
import sys
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import LogUniform, Space, run

def progress(done, total):
    print(done, flush=True)

space = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5))
result = run(space, 10**8, seed=1, chunk_points={CHUNK}, progress=progress)
print("partial", result.partial, result.points, int(result["summary"].points.sum()), flush=True)
""")
    process = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    assert int(process.stdout.readline()) == CHUNK
    process.send_signal(signal.SIGTERM)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 0, stderr
    _, partial, points, summed = stdout.splitlines()[-1].split()
    assert partial == "True" and int(points) == int(summed) and int(points) % CHUNK == 0


def test_a_failed_cluster_writes_the_prefix_marked_partial_and_says_so(tmp_path, capsys,
                                                                       monkeypatch):
    import epc_fast.scan
    from epc_fast.scan.running.aborted import ScanAborted

    real_run = epc_fast.scan.run

    def run_losing_the_cluster(*args, **kwargs):
        def lose_after_two_chunks(done, total):
            if done >= 2 * CHUNK:
                raise ScanAborted("the Dask cluster failed the scan's tasks (CancelledError: "
                                  "no message), after 131,072 points were merged")
        return real_run(*args, **{**kwargs, "progress": lose_after_two_chunks})

    monkeypatch.setattr(epc_fast.scan, "run", run_losing_the_cluster)
    out = tmp_path / "out"
    code, stdout, err = _cli(capsys, _config(tmp_path), "--out", out, "--chunk-points", CHUNK)
    assert code == 1 and "INTERRUPTED" not in stdout
    assert stdout.splitlines()[0].endswith(
        "-- FAILED: the Dask cluster failed the scan's tasks (CancelledError: no message), after "
        "131,072 points were merged; partial results")
    assert err == ("epc-fast scan: error: the Dask cluster failed the scan's tasks "
                   "(CancelledError: no message), after 131,072 points were merged; the 131,072 "
                   "points merged before it are written, marked partial\n")
    manifest = _manifest(out)
    assert manifest["state"] == "failed" and manifest["partial"] is True
    assert manifest["points_done"] == 2 * CHUNK and "Dask cluster" in manifest["stopped_by"]
    assert sum(int(r["points"]) for r in _rows(out / "summary_by_design.csv")) == 2 * CHUNK


def test_a_full_disk_while_writing_a_table_leaves_no_truncated_table(tmp_path, capsys,
                                                                     monkeypatch):
    real_write_text = pathlib.Path.write_text

    def fill_the_disk_on_markdown(self, text, *args, **kwargs):
        if ".md" not in self.name:
            return real_write_text(self, text, *args, **kwargs)
        with open(self, "w") as handle:
            handle.write(text[:len(text) // 2])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(pathlib.Path, "write_text", fill_the_disk_on_markdown)
    out = tmp_path / "out"
    code, _, err = _cli(capsys, _config(tmp_path), "--out", out)
    assert code == 1 and "No space left on device" in err and err.count("\n") == 1
    assert not (out / "summary_by_design.md").exists()
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]


def test_ctrl_c_before_the_first_merge_writes_an_empty_top_k_table(tmp_path, capsys,
                                                                   monkeypatch):
    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", _Chunks(stop_at=1))
    out = tmp_path / "out"
    code, stdout, err = _cli(capsys, _config(tmp_path, '[reductions.best]\nkind = "top_k"\n'
                                             'k = 3\n'), "--out", out, "--no-plots")
    assert code == 130 and "INTERRUPTED" in stdout and "Traceback" not in err, err
    with open(out / "best.csv", newline="") as handle:
        assert list(csv.reader(handle)) == [["point", "epc", "design", "illuminance_lux",
                                             "pixel_pitch_um", "partial: points done"]]
    assert [int(r["points"]) for r in _rows(out / "summary_by_design.csv")] == [0] * 4
    manifest = _manifest(out)
    assert manifest["state"] == "interrupted" and manifest["points_done"] == 0
    assert "best.csv" in manifest["files"]


# --- one writer per --out ------------------------------------------------------------------

def test_a_second_run_into_a_busy_out_is_refused_naming_the_holder_and_a_dead_ones_is_taken_over(
        tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    config = _config(tmp_path, '[output]\nparquet = "points"\n')
    out = tmp_path / "out"
    first = _scan_process(config, out, "--points", "2e7", "--overwrite")
    try:
        _wait_for_chunks(first, out, 2)
        second = subprocess.run([sys.executable, "-m", "epc_fast", "scan", str(config), "--out",
                                 str(out), "--overwrite", "--no-progress", "--seed", "1"],
                                capture_output=True, text=True, timeout=120)
        assert second.returncode == 2 and second.stdout == "", second.stderr
        assert second.stderr.count("\n") == 1 and "another run writes here" in second.stderr
        assert f"pid {first.pid} on " in second.stderr and " since 20" in second.stderr
        assert first.poll() is None
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=120)
    finally:
        first.kill()
    assert first.returncode == 143
    manifest = _manifest(out)
    assert manifest["seed"] == 7 and manifest["state"] == "interrupted"
    table = pq.read_table(out / "points")
    assert table.column("point").to_pylist() == list(range(manifest["points_done"]))
    assert not [p for p in out.rglob(".*")]  # the lock file is gone with its run
    # A run killed with its lock held leaves the lock file; the next run takes it over.
    killed = _scan_process(config, out, "--points", "2e7", "--overwrite", "--seed", "5")
    try:
        _wait_for_chunks(killed, out, 1, seed=5)
    finally:
        killed.kill()
        killed.communicate(timeout=60)
    assert (out / ".epc-fast.lock").exists()
    code, _, err = _cli(capsys, config, "--out", out, "--overwrite", "--no-plots")
    assert code == 0 and "took over the lock" in err and f"pid {killed.pid} on " in err
    assert pq.read_table(out / "points").num_rows == 200_000
    assert not [p for p in out.rglob(".*")]


def test_an_interrupted_scan_removes_only_the_parquet_files_it_wrote(tmp_path, monkeypatch):
    pq = pytest.importorskip("pyarrow.parquet")
    from epc_fast.presets import HIGH_TIER
    from epc_fast.scan import Space, run

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", _Chunks(stop_at=2))
    points = tmp_path / "points"
    others = ["part-000000196608.parquet", ".ready-part-000000262144.parquet",
              ".part-000000327680.parquet.0a1b2c.tmp"]

    def another_run_writes_beside(done):
        for name in others:
            (points / name).write_bytes(b"another run's")

    space = Space(design=HIGH_TIER, illuminance_lux=1000.0)
    result = run(space, 4 * CHUNK, seed=1, chunk_points=CHUNK, progress=False, parquet=points,
                 on_chunk=another_run_writes_beside)
    assert result.partial and result.points == CHUNK
    assert sorted(p.name for p in points.iterdir()) == sorted(
        ["part-000000000000.parquet", *others])
    assert pq.read_table(points / "part-000000000000.parquet").num_rows == CHUNK


# --- every way a run ends leaves the tables of its prefix and a true manifest --------------

TOP_K = '[reductions.best]\nkind = "top_k"\nk = 3\n'
TABLES = ["best.csv", "manifest.json", "summary_by_design.csv", "summary_by_design.md"]


@pytest.mark.parametrize("signame, code", [("SIGTERM", 143), ("SIGINT", 130)])
def test_a_signal_while_the_tables_are_written_costs_no_file(tmp_path, signame, code):
    config = _config(tmp_path, TOP_K)
    out = tmp_path / "out"
    script = tmp_path / "signalled.py"
    script.write_text(f"""
import os, signal, sys
import epc_fast.jobs.table_formats as table_formats
from epc_fast.__main__ import main

real_write_csv = table_formats.write_csv

def write_csv_signalled(path, columns):
    os.kill(os.getpid(), signal.{signame})
    real_write_csv(path, columns)

table_formats.write_csv = write_csv_signalled
sys.exit(main(["scan", {str(config)!r}, "--out", {str(out)!r}, "--no-progress", "--no-plots"]))
""")
    finished = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                              timeout=120)
    assert finished.returncode == code, finished.stderr
    assert finished.stderr == (f"epc-fast scan: {signame} while the results were written: "
                               "every file is written whole, the scan is complete\n")
    assert sorted(p.name for p in out.iterdir()) == TABLES  # no .tmp, no lock left
    assert sum(int(r["points"]) for r in _rows(out / "summary_by_design.csv")) == 200_000
    assert len(_rows(out / "best.csv")) == 3
    manifest = _manifest(out)
    assert manifest["state"] == "complete" and manifest["stopped_by"] is None
    assert manifest["points_done"] == 200_000 and set(manifest["files"]) == set(TABLES) - {
        "manifest.json"}


def test_a_second_ctrl_c_while_the_tables_are_written_costs_no_file(tmp_path, capsys,
                                                                     monkeypatch):
    import epc_fast.jobs.table_formats

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", _Chunks(stop_at=2))
    real_write_csv = epc_fast.jobs.table_formats.write_csv

    def write_csv_after_ctrl_c(path, columns):
        os.kill(os.getpid(), signal.SIGINT)
        real_write_csv(path, columns)

    monkeypatch.setattr(epc_fast.jobs.table_formats, "write_csv", write_csv_after_ctrl_c)
    out = tmp_path / "out"
    code, stdout, _ = _cli(capsys, _config(tmp_path, TOP_K), "--out", out, "--no-plots",
                           "--chunk-points", CHUNK)
    assert code == 130 and "INTERRUPTED" in stdout
    assert sorted(p.name for p in out.iterdir()) == TABLES
    assert sum(int(r["points"]) for r in _rows(out / "summary_by_design.csv")) == CHUNK
    manifest = _manifest(out)
    assert manifest["state"] == "interrupted" and manifest["stopped_by"] == "SIGINT"
    assert manifest["points_done"] == CHUNK


def test_a_full_disk_mid_run_leaves_the_tables_of_the_merged_prefix(tmp_path, capsys,
                                                                    monkeypatch):
    real_reduce_chunk = epc_fast.scan.running.runner.reduce_chunk
    calls = []

    def full_on_the_third_chunk(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_reduce_chunk(*args, **kwargs)

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", full_on_the_third_chunk)
    out = tmp_path / "out"
    code, stdout, err = _cli(capsys, _config(tmp_path, TOP_K), "--out", out, "--no-plots",
                             "--chunk-points", CHUNK)
    assert code == 1 and stdout.splitlines()[0].endswith(
        "-- FAILED: OSError: [Errno 28] No space left on device; partial results")
    assert err == ("epc-fast scan: error: OSError: [Errno 28] No space left on device; the "
                   "131,072 points merged before it are written, marked partial\n")
    assert sorted(p.name for p in out.iterdir()) == TABLES
    assert sum(int(r["points"]) for r in _rows(out / "summary_by_design.csv")) == 2 * CHUNK
    manifest = _manifest(out)
    assert manifest["state"] == "failed" and manifest["partial"] is True
    assert manifest["stopped_by"] == "OSError: [Errno 28] No space left on device"
    assert manifest["points_done"] == 2 * CHUNK


class _FullDisk:
    """The ``os`` module of :mod:`epc_fast.jobs.atomic` on a disk that fills while the scan's
    second chunk runs: from then on no new file can be made (ENOSPC), as on a real full disk,
    while a file's blocks already written can be written again."""

    def __init__(self, monkeypatch):
        import epc_fast.jobs.atomic

        self.full = False
        self.chunks = 0
        self.reduce_chunk = epc_fast.scan.running.runner.reduce_chunk
        monkeypatch.setattr(epc_fast.jobs.atomic, "os", self)
        monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", self.chunk)

    def chunk(self, *args, **kwargs):
        self.chunks += 1
        self.full = self.full or self.chunks == 2
        return self.reduce_chunk(*args, **kwargs)

    def open(self, path, flags, *args):
        if self.full and flags & os.O_CREAT:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return os.open(path, flags, *args)

    def __getattr__(self, name):
        return getattr(os, name)


def test_a_disk_that_fills_mid_run_leaves_a_manifest_that_says_failed_and_why(
        tmp_path, capsys, monkeypatch):
    _FullDisk(monkeypatch)
    out = tmp_path / "out"
    code, stdout, err = _cli(capsys, _config(tmp_path), "--out", out, "--no-plots",
                             "--chunk-points", CHUNK)
    assert code == 1 and "No space left on device" in err
    manifest = _manifest(out)
    assert manifest["state"] == "failed" and manifest["partial"] is True
    assert manifest["stopped_by"].startswith("OSError: [Errno 28] No space left on device")
    assert manifest["points_done"] == 2 * CHUNK
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]


def test_a_manifest_that_cannot_be_written_at_all_is_named_on_stderr(tmp_path, capsys,
                                                                     monkeypatch):
    import epc_fast.jobs.output.manifest

    def no_block_left(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    _FullDisk(monkeypatch)
    monkeypatch.setattr(epc_fast.jobs.output.manifest, "_rewrite_in_place", no_block_left)
    out = tmp_path / "out"
    code, stdout, err = _cli(capsys, _config(tmp_path), "--out", out, "--no-plots",
                             "--chunk-points", CHUNK)
    assert code == 1
    assert (f"epc-fast scan: could not record how the scan ended in {out / 'manifest.json'} "
            "(OSError: [Errno 28] No space left on device): it still says 'running', 65,536 "
            "points done\n") in err
    assert _manifest(out)["state"] == "running"


def test_a_failed_plot_leaves_the_tables_and_a_manifest_that_says_so(tmp_path, capsys,
                                                                     monkeypatch):
    import epc_fast.scan.plot

    def broken_plot(*args, **kwargs):
        raise RuntimeError("no renderer")

    monkeypatch.setattr(epc_fast.scan.plot, "plot_distributions", broken_plot)
    out = tmp_path / "out"
    code, _, err = _cli(capsys, _config(tmp_path, '[reductions.h]\nkind = "histogram"\n'
                                        'low = 1e3\nhigh = 1e7\n'), "--out", out)
    assert code == 1 and err == "epc-fast scan: error: RuntimeError: no renderer\n"
    assert sorted(p.name for p in out.iterdir()) == ["h.csv", "h.md", "manifest.json",
                                                     "summary_by_design.csv",
                                                     "summary_by_design.md"]
    manifest = _manifest(out)
    assert manifest["state"] == "failed" and manifest["stopped_by"] == "RuntimeError: no renderer"
    assert manifest["points_done"] == 200_000
    assert manifest["files"] == ["summary_by_design.csv", "summary_by_design.md", "h.csv",
                                 "h.md"]


def test_a_directory_holding_only_a_dead_runs_leftovers_is_not_refused_as_not_empty(
        tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / ".epc-fast.lock").write_text('{"pid": 1, "host": "gone"}\n')
    (out / ".summary_by_design.csv.0a1b2c3d4e5f.tmp").write_text("half a tab")
    (out / ".write-probe-4242.tmp").write_bytes(b"epc_fast")
    code, _, err = _cli(capsys, _config(tmp_path), "--out", out)
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "summary_by_design.csv",
                                                     "summary_by_design.md"]


def test_ctrl_c_while_the_sobol_indices_are_computed_leaves_a_manifest_saying_so(
        tmp_path, capsys, monkeypatch):
    import epc_fast.commands.sobol

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(epc_fast.commands.sobol, "compute", interrupted)
    out = tmp_path / "out"
    code, _, err = _cli(capsys, _config(tmp_path, "[sobol]\npoints = 16\n"), "--out", out)
    assert code == 130 and err == "epc-fast scan: interrupted before the first point\n"
    manifest = _manifest(out)
    assert manifest["state"] == "interrupted" and manifest["stopped_by"] == "SIGINT"
    assert manifest["points_done"] == 0 and manifest["partial"] is True
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json"]


# --- partial results say so in every file -----------------------------------------------------

def test_every_file_of_an_interrupted_scan_says_its_results_are_partial(tmp_path, capsys,
                                                                       monkeypatch):
    from epc_fast.scan.tables import PARTIAL_COLUMN

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", _Chunks(stop_at=3))
    titles = []
    real_save = epc_fast.scan.plot._save
    monkeypatch.setattr(epc_fast.scan.plot, "_save", lambda figure, path: (
        titles.append(figure.get_suptitle() + " ".join(a.get_title() for a in figure.axes)),
        real_save(figure, path)))
    out = tmp_path / "out"
    config = _config(tmp_path, '[reductions.best]\nkind = "top_k"\nk = 3\n'
                     '[reductions.distribution]\nkind = "histogram"\nlow = 1e3\nhigh = 1e7\n'
                     'by = "design"\n'
                     '[reductions.bands]\nkind = "quantiles"\nq = [0.1, 0.5, 0.9]\nby = '
                     '["design", { parameter = "illuminance_lux", log_bins = [10, 100_000, 4] }]'
                     '\n')
    code, _, _ = _cli(capsys, config, "--out", out, "--chunk-points", CHUNK)
    assert code == 130
    done = f"{2 * CHUNK} of {_manifest(out)['points_requested']}"
    csvs = sorted(out.glob("*.csv"))
    assert csvs and all(row[PARTIAL_COLUMN] == done for path in csvs for row in _rows(path))
    note = f"**PARTIAL RESULTS: {2 * CHUNK:,} of "
    assert all(path.read_text().startswith(note) for path in out.glob("*.md"))
    assert len(titles) == 2 and all("PARTIAL RESULTS: " in title for title in titles)


def test_a_complete_scans_files_carry_no_partial_mark(tmp_path, capsys):
    from epc_fast.scan.tables import PARTIAL_COLUMN

    out = tmp_path / "out"
    assert _cli(capsys, _config(tmp_path), "--out", out, "--no-plots")[0] == 0
    assert all(PARTIAL_COLUMN not in row for path in out.glob("*.csv") for row in _rows(path))
    assert not any("PARTIAL" in path.read_text() for path in out.glob("*.md"))


#: Where a signal may arrive between the --out lock and the scan's first chunk: the module,
#: the function and whether the signal comes after it ran (else before it runs).
START_PHASES = {
    "the lock just taken": ("epc_fast.jobs.output.lock", "OutputLock.acquire", True),
    "the first manifest written": ("epc_fast.jobs.output.manifest", "write_manifest", True),
    "the cluster connected": ("epc_fast.commands.scan", "_client", False),
    "the Parquet staging made": ("epc_fast.scan.running.parquet", "prepare_directory", True),
}


@pytest.mark.parametrize("phase", START_PHASES)
@pytest.mark.parametrize("signame, code", [("SIGTERM", 143), ("SIGINT", 130)])
def test_a_signal_between_the_lock_and_the_first_chunk_leaves_a_true_manifest(
        tmp_path, phase, signame, code):
    module, function, after = START_PHASES[phase]
    owner, _, name = function.rpartition(".")
    config = _config(tmp_path, '[output]\nparquet = "points"\n')
    out = tmp_path / "out"
    script = tmp_path / "signalled.py"
    script.write_text(f"""
import importlib, os, signal, sys
from epc_fast.__main__ import main

module = importlib.import_module({module!r})
owner = getattr(module, {owner!r}) if {owner!r} else module
real = getattr(owner, {name!r})
signalled = []

def signalled_once(*args, **kwargs):
    if {after!r}:
        value = real(*args, **kwargs)
    if not signalled:
        signalled.append(True)
        os.kill(os.getpid(), signal.{signame})
    return value if {after!r} else real(*args, **kwargs)

setattr(owner, {name!r}, signalled_once)
sys.exit(main(["scan", {str(config)!r}, "--out", {str(out)!r}, "--no-progress", "--no-plots",
               "--chunk-points", "{CHUNK}"]))
""")
    finished = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                              timeout=120)
    assert finished.returncode == code, finished.stderr
    manifest = _manifest(out)
    assert manifest["state"] == "interrupted" and manifest["stopped_by"] == signame
    assert manifest["points_done"] == 0 and manifest["partial"] is True
    left = sorted(str(p.relative_to(out)) for p in out.rglob("*"))
    assert not [p for p in left if p.endswith(".tmp") or "/.run-" in p or ".lock" in p], left
