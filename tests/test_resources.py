"""What the process can hold: threads and memory under an address-space limit (RLIMIT_AS,
``ulimit -v``), each run in a child process that lowers its own limit, so that a failure ends
the child, not the test run."""

import os
import subprocess
import sys
import textwrap

import pytest

resource = pytest.importorskip("resource")

#: 4 GB, as ``ulimit -v 4000000``: room for the interpreter and a few hundred thread stacks.
LIMIT = 4_000_000_000

PRELUDE = f"""
import resource
resource.setrlimit(resource.RLIMIT_AS, ({LIMIT}, {LIMIT}))
import numpy as np
import epc_fast
DESIGN = dict(illuminance_lux=np.linspace(1.0, 1000.0, 100_000), pixel_pitch_um=1.0,
              f_number=2.0, focal_length_mm=4.0, pixel_count=12e6)
"""


def run_child(body: str, **env) -> subprocess.CompletedProcess:
    script = PRELUDE + textwrap.dedent(body) + "\nprint('SURVIVED', flush=True)\n"
    return subprocess.run([sys.executable, "-c", script], env=dict(os.environ, **env),
                          capture_output=True, text=True, timeout=120)


def test_threads_above_what_the_address_space_can_start_are_refused_naming_how_many_can():
    proc = run_child("""
        try:
            epc_fast.evaluate(**DESIGN, threads=1024)
        except ValueError as exc:
            print("REFUSED", exc)
        from epc_fast._limits import startable_threads
        fine = epc_fast.evaluate(**DESIGN, threads=startable_threads())
        print("RAN", int(np.count_nonzero(fine.status == 0)))
    """)
    assert "Thread creation failed" not in proc.stderr
    assert proc.returncode == 0, proc.stderr
    refused = next(line for line in proc.stdout.splitlines() if line.startswith("REFUSED"))
    assert "threads=1024" in refused and "RLIMIT_AS" in refused
    can = int(refused.split("at most ")[1].split()[0])
    assert 2 <= can < 1024
    assert "RAN 100000" in proc.stdout and "SURVIVED" in proc.stdout


def test_the_default_thread_count_is_capped_to_what_the_address_space_can_start():
    proc = run_child("""
        result = epc_fast.evaluate(**DESIGN)
        print("RAN", int(np.count_nonzero(result.status == 0)))
        from epc_fast import _core
        from epc_fast._limits import DEFAULT_THREADS_SHARE, startable_threads
        print("DEFAULT", _core.default_threads(), _core.checked_default_threads(),
              startable_threads(DEFAULT_THREADS_SHARE), startable_threads())
    """, OMP_NUM_THREADS="1024")
    assert "Thread creation failed" not in proc.stderr
    assert proc.returncode == 0, proc.stderr
    default = next(line for line in proc.stdout.splitlines() if line.startswith("DEFAULT"))
    runtime, checked, half, startable = map(int, default.split()[1:])
    assert runtime == 1024 and 2 <= checked == half < startable < 1024
    assert "RAN 100000" in proc.stdout and "SURVIVED" in proc.stdout


def test_a_scan_on_the_capped_default_runs_every_chunk_under_an_address_space_limit(tmp_path):
    # The scan resolves the default once and passes it to every chunk as an explicit count,
    # checked again there after the run has mapped more: the cap leaves room for that.
    proc = run_child(f"""
        from epc_fast.__main__ import main
        code = main(["scan", "--points", "131072", "--chunk-points", "65536", "--no-plots",
                     "--no-progress", "--out", {str(tmp_path / "out")!r}])
        print("EXIT", code)
    """, OMP_NUM_THREADS="1024")
    assert "Thread creation failed" not in proc.stderr
    assert proc.returncode == 0, proc.stderr
    assert "EXIT 0" in proc.stdout and "SURVIVED" in proc.stdout
    assert (tmp_path / "out" / "summary_by_design.csv").exists()


def test_the_memory_check_counts_the_address_space_left_under_rlimit_as():
    proc = run_child("""
        import time
        from epc_fast._limits import memory_limit_bytes
        print("LIMIT", memory_limit_bytes())
        start = time.perf_counter()
        try:  # 2.5e8 points from two small broadcast inputs: ~12 GB of outputs
            epc_fast.evaluate(illuminance_lux=np.linspace(1.0, 1e3, 25_000)[:, None],
                              pixel_pitch_um=np.linspace(0.8, 2.0, 10_000), f_number=2.0,
                              focal_length_mm=4.0, pixel_count=12e6, threads=1)
        except MemoryError as exc:
            print("REFUSED", f"{time.perf_counter() - start:.3f}", exc)
    """)
    assert proc.returncode == 0, proc.stderr
    limit = int(next(line for line in proc.stdout.splitlines()
                     if line.startswith("LIMIT")).split()[1])
    assert 0 < limit < LIMIT
    refused = next(line for line in proc.stdout.splitlines() if line.startswith("REFUSED"))
    seconds = float(refused.split()[1])
    assert seconds < 1.0 and "(250,000,000 points)" in refused and "RLIMIT_AS" in refused
    assert "SURVIVED" in proc.stdout


@pytest.mark.parametrize("command", ["scan", "optimize", "sobol"])
def test_a_command_refuses_threads_it_cannot_start_before_it_writes_anything(tmp_path, command):
    out = tmp_path / "out"
    config = os.path.join(os.path.dirname(__file__), "..", "examples", "optimize_pitch.toml")
    args = [command, *([config] if command == "optimize" else []), "--out", str(out),
            "--threads", "1024"]
    proc = run_child(f"""
        from epc_fast.__main__ import main
        print("EXIT", main({args!r}))
    """)
    assert "SURVIVED" in proc.stdout, proc.stderr
    assert "EXIT 1" in proc.stdout
    assert "threads=1024: this process can start at most" in proc.stderr
    assert not out.exists()  # refused before the --out directory is made


def test_a_thread_count_the_caller_s_thread_has_run_on_skips_the_stack_count(monkeypatch):
    # The OpenMP runtime keeps a thread's team: threads_of counts the stacks a call would map
    # (startable_threads) only for more threads than this Python thread's calls have run on.
    import threading

    import numpy as np

    import epc_fast
    from epc_fast import _core, _validation

    if not _core.openmp_enabled():
        pytest.skip("a build without OpenMP runs every call on one thread")

    def refuse_all(share=1.0):
        return 1

    def fresh_thread(work):
        box = {}

        def run():
            try:
                box["value"] = work()
            except ValueError as exc:
                box["error"] = str(exc)
        thread = threading.Thread(target=run)
        thread.start()
        thread.join()
        return box

    def first_calls():
        before = _core.started_threads()
        # one block: a team of one thread, whatever threads= says
        epc_fast.evaluate(100.0, 1.4, 2.0, 5.0, sensor_area_mm2=10.0, threads=2)
        one_block = _core.started_threads()
        epc_fast.evaluate(np.full(8192, 100.0), 1.4, 2.0, 5.0, sensor_area_mm2=10.0, threads=2)
        return before, one_block, _core.started_threads()

    assert fresh_thread(first_calls)["value"] == (1, 1, 2)
    monkeypatch.setattr(_validation, "startable_threads", refuse_all)
    # a new thread has run on none: its check runs, and here refuses
    assert "can start at most 1" in fresh_thread(lambda: _validation.threads_of(2))["error"]

    def after_a_two_thread_call():
        monkeypatch.undo()
        epc_fast.evaluate(np.full(8192, 100.0), 1.4, 2.0, 5.0, sensor_area_mm2=10.0, threads=2)
        monkeypatch.setattr(_validation, "startable_threads", refuse_all)
        kept = _validation.threads_of(2)  # the team of two is kept: no check, no refusal
        with pytest.raises(ValueError, match="can start at most 1"):
            _validation.threads_of(3)
        return kept
    assert fresh_thread(after_a_two_thread_call)["value"] == 2
