"""A Dask scan never mixes in another epc_fast build's numbers; workers that die one after the
other (one alive at every moment) cost nothing; a cluster that loses every worker, or a scan
that stalls, ends with a clear error that keeps the prefix merged before, marked partial."""

import os
import signal
import time

import pytest

import epc_fast.scan.running.dask_backend as dask_backend
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import BLOCK_POINTS, LogUniform, Space, Summary, run
from epc_fast.scan.running.aborted import ScanAborted
from helpers.scan import SPACE as EVERY_KIND_SPACE
from helpers.scan import assert_same_numbers, every_reduction

distributed = pytest.importorskip("distributed")

#: Each test starts a cluster of worker processes and kills or stalls them: 15 s on 2 cores.
pytestmark = pytest.mark.heavy

SPACE = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5))


def _cluster():
    return distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                    host="127.0.0.1", dashboard_address=None)


def _set_version(version):
    import epc_fast

    epc_fast.__version__ = version


def test_workers_of_another_epc_fast_version_are_refused_before_any_chunk(tmp_path):
    with _cluster() as cluster, distributed.Client(cluster) as client:
        client.run(_set_version, "0.0.0+other")
        with pytest.raises(dask_backend.WorkerMismatch,
                           match=r"run epc_fast 0\.0\.0\+other \(core .*\), not this client's "
                                 r"epc_fast .* install the same epc_fast on every worker"):
            run(SPACE, 4 * BLOCK_POINTS, seed=1, reductions={"s": Summary()},
                chunk_points=BLOCK_POINTS, progress=False, client=client)


def test_a_task_on_a_worker_of_another_build_refuses_to_run():
    # A worker that joins after the scan started is checked by each task it runs.
    with pytest.raises(dask_backend.WorkerMismatch, match="not the client's epc_fast 9.9"):
        dask_backend.checked_reduce_chunk(("9.9", "x86-64"), SPACE, (), 1, 0, BLOCK_POINTS,
                                          BLOCK_POINTS, None, None)


def test_losing_every_worker_ends_with_a_clear_error_and_the_partial_prefix(monkeypatch):
    monkeypatch.setattr(dask_backend, "WORKERLESS_S", 2.0)
    monkeypatch.setattr(dask_backend, "POLL_S", 0.2)
    with _cluster() as cluster, distributed.Client(cluster) as client:
        def lose_every_worker(done, total):
            if cluster.workers:
                cluster.scale(0)

        with pytest.raises(ScanAborted, match=r"^the Dask cluster .*, after [\d,]+ points were "
                                              r"merged$") as error:
            run(SPACE, 40 * BLOCK_POINTS, seed=1, reductions={"s": Summary()},
                chunk_points=BLOCK_POINTS, progress=lose_every_worker, client=client)
    result = error.value.result
    assert result.partial and BLOCK_POINTS <= result.points < 40 * BLOCK_POINTS
    assert result.points % BLOCK_POINTS == 0
    assert int(result["s"].points.sum()) == result.points


def _worker_pids(client) -> dict:
    return client.run(os.getpid, on_error="ignore")


def _kill_and_wait_for_its_replacement(client, pid, killed, timeout=15.0):
    """SIGKILL a worker process; return once the nanny's new worker has joined (two workers,
    none of them killed)."""
    os.kill(pid, signal.SIGKILL)
    killed.add(pid)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        pids = set(_worker_pids(client).values())
        if len(pids) == 2 and not pids & killed:
            return
        time.sleep(0.05)
    raise AssertionError("the nanny did not restart the killed worker")


def test_workers_killed_one_after_the_other_cost_no_point(tmp_path):
    # Each worker is killed in turn, the second as soon as the first's replacement joined (one
    # worker alive at every moment; the new one has not run a task yet): the scan's space and
    # plan, and the chunks done on the killed workers, are computed again elsewhere, and the
    # scan ends with every point and the same numbers as an undisturbed local run.
    import pyarrow.parquet as pq

    points, chunk = 12 * BLOCK_POINTS, BLOCK_POINTS
    with _cluster() as cluster, distributed.Client(cluster) as client:
        killed = set()

        def kill_each_worker_in_turn(done, total):
            if done == chunk:
                for pid in sorted(_worker_pids(client).values()):
                    _kill_and_wait_for_its_replacement(client, pid, killed)

        on_cluster = run(EVERY_KIND_SPACE, points, seed=5, reductions=every_reduction(),
                         chunk_points=chunk, progress=kill_each_worker_in_turn, client=client,
                         parquet=tmp_path / "cluster")
        assert len(killed) == 2
    local = run(EVERY_KIND_SPACE, points, seed=5, reductions=every_reduction(),
                chunk_points=chunk, progress=False, parquet=tmp_path / "local")
    assert not on_cluster.partial and on_cluster.points == points
    assert_same_numbers(on_cluster, local)
    assert sorted(os.listdir(tmp_path / "cluster")) == sorted(os.listdir(tmp_path / "local"))
    assert pq.read_table(tmp_path / "cluster").equals(pq.read_table(tmp_path / "local"))


LATE_CONFIG = """\
[scan]
points = 262_144
seed = 3

[design]
presets = ["HIGH_TIER"]

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }

[reductions.summary]
kind = "summary"
by = "design"

[output]
parquet = "points"
"""


def test_no_worker_writes_into_the_parquet_directory_after_the_command_returns(
        tmp_path, monkeypatch, capsys):
    # The third chunk's task is slow: it is still running when Ctrl-C stops the scan, and a
    # second Ctrl-C arrives while the scan cancels its tasks. The command returns; then the
    # task finishes and tries to write its part: points/ holds exactly the committed parts.
    import json
    import threading

    import epc_fast.jobs.output.manifest as manifest_module
    import epc_fast.scan.running.parquet as parquet
    from epc_fast.__main__ import main

    started, release, finished = threading.Event(), threading.Event(), threading.Event()
    late = []
    real_write_part = parquet.write_part

    def slow_write_part(directory, space, points, result):
        if points.start != 2 * BLOCK_POINTS:
            return real_write_part(directory, space, points, result)
        started.set()
        try:
            release.wait(30)
            return real_write_part(directory, space, points, result)
        except Exception as error:
            late.append(error)
            raise
        finally:
            finished.set()

    real_write_manifest = manifest_module.write_manifest

    def write_manifest_then_ctrl_c(directory, manifest):
        path = real_write_manifest(directory, manifest)
        if manifest["points_done"] == 2 * BLOCK_POINTS:
            assert started.wait(30)
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C while the third chunk's task runs
        return path

    real_cancel = distributed.Future.cancel
    second = []

    def cancel_after_a_second_ctrl_c(self, *args, **kwargs):
        if not second and threading.current_thread() is threading.main_thread():
            second.append(True)
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C again, while the tasks are cancelled
        return real_cancel(self, *args, **kwargs)

    monkeypatch.setattr(parquet, "write_part", slow_write_part)
    monkeypatch.setattr(distributed.Future, "cancel", cancel_after_a_second_ctrl_c)
    monkeypatch.setattr(manifest_module, "write_manifest", write_manifest_then_ctrl_c)
    config = tmp_path / "scan.toml"
    config.write_text(LATE_CONFIG)
    out = tmp_path / "out"
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                      dashboard_address=None) as cluster:
            try:
                code = main(["scan", str(config), "--out", str(out), "--no-progress",
                             "--no-plots", "--chunk-points", str(BLOCK_POINTS),
                             "--scheduler", cluster.scheduler_address])
            except KeyboardInterrupt:
                code = "KeyboardInterrupt"
            assert started.is_set() and second
            release.set()
            assert finished.wait(30)
            time.sleep(0.2)  # the task's last file operations
    finally:
        release.set()
    capsys.readouterr()
    assert code == 130
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["state"] == "interrupted" and manifest["stopped_by"] == "SIGINT"
    committed = sorted(name for name in manifest["files"] if name.startswith("points/"))
    assert sorted(f"points/{name}" for name in os.listdir(out / "points")) == committed
    assert manifest["points_done"] == 2 * BLOCK_POINTS and len(committed) == 2
    assert "summary_by_design.csv" in manifest["files"]  # the merged prefix's tables
    assert isinstance(late[0], FileNotFoundError)  # the late part is discarded


def _exit_on_the_third_chunk():
    import epc_fast.scan.running.dask_backend as worker_backend

    real = worker_backend.reduce_chunk

    def exit_on_the_third_chunk(space, plan, seed, start, *args):
        if start == 2 * BLOCK_POINTS:
            os._exit(1)  # the worker process dies with the task
        return real(space, plan, seed, start, *args)

    worker_backend.reduce_chunk = exit_on_the_third_chunk


def test_a_chunk_that_kills_its_workers_past_the_allowed_failures_ends_with_the_prefix():
    import dask

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            _cluster() as cluster, distributed.Client(cluster) as client:
        client.run(_exit_on_the_third_chunk)
        with pytest.raises(ScanAborted, match=r"^the Dask cluster failed the scan's tasks "
                                              r"\(KilledWorker: .*\), after [\d,]+ points were "
                                              r"merged$") as error:
            run(SPACE, 8 * BLOCK_POINTS, seed=1, reductions={"s": Summary()},
                chunk_points=BLOCK_POINTS, progress=False, client=client)
    # The tasks that shared the dying worker fail with it: the prefix ends at the third chunk
    # or before it.
    result = error.value.result
    assert result.partial and result.points in (0, BLOCK_POINTS, 2 * BLOCK_POINTS)
    assert int(result["s"].points.sum()) == result.points


@pytest.mark.parametrize("times", [1, dask_backend.RESUBMITS + 1])
def test_a_chunk_whose_task_the_cluster_lost_is_submitted_again_a_few_times(times):
    # The cluster cancels the second chunk's task `times` times (as when the data it needs is
    # forgotten): the scan submits it again, and gives up only past RESUBMITS.
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        real_submit, lost = client.submit, []

        def submit_losing_the_second_chunk(function, *args, **kwargs):
            future = real_submit(function, *args, **kwargs)
            if function is dask_backend.checked_reduce_chunk and args[4] == BLOCK_POINTS \
                    and len(lost) < times:
                lost.append(future)
                future.cancel()
            return future

        client.submit = submit_losing_the_second_chunk
        reductions = {"s": Summary(by="design")}
        if times <= dask_backend.RESUBMITS:
            on_cluster = run(SPACE, 4 * BLOCK_POINTS, seed=2, reductions=reductions,
                             chunk_points=BLOCK_POINTS, progress=False, client=client)
            local = run(SPACE, 4 * BLOCK_POINTS, seed=2, reductions=reductions,
                        chunk_points=BLOCK_POINTS, progress=False)
            assert_same_numbers(on_cluster, local)
        else:
            with pytest.raises(ScanAborted, match=r"^the Dask cluster lost the task of points "
                                                  r"65,536 to 131,071 4 times, after [\d,]+ "
                                                  r"points were merged$") as error:
                run(SPACE, 4 * BLOCK_POINTS, seed=2, reductions=reductions,
                    chunk_points=BLOCK_POINTS, progress=False, client=client)
            assert error.value.result.points in (0, BLOCK_POINTS)
    assert len(lost) == times


def test_a_scan_whose_chunks_stop_arriving_ends_naming_the_stall_and_cancels_its_tasks():
    # The third chunk's task blocks (a hung worker, a task the cluster never runs): no chunk
    # merges for the stall timeout, and the scan ends with the prefix before it, its tasks
    # cancelled, instead of waiting forever. (Without the watchdog the task is released after
    # 20 s and the scan ends complete.)
    import threading

    import dask

    release = threading.Event()
    real = dask_backend.reduce_chunk

    def block_on_the_third_chunk(space, plan, seed, start, *args):
        if start == 2 * BLOCK_POINTS:
            release.wait(20)
        return real(space, plan, seed, start, *args)

    started = time.monotonic()
    try:
        with dask.config.set({"epc-fast.stall-timeout": "3s"}), \
                distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                         dashboard_address=None) as cluster, \
                distributed.Client(cluster) as client:
            dask_backend.reduce_chunk = block_on_the_third_chunk
            with pytest.raises(ScanAborted, match=r"^the Dask cluster merged no chunk for 3 s "
                                                  r"\(epc-fast\.stall-timeout\), waiting for "
                                                  r"points 131,072 to 196,607 \(.*\), after "
                                                  r"131,072 points were merged$") as error:
                run(SPACE, 8 * BLOCK_POINTS, seed=1, reductions={"s": Summary()},
                    chunk_points=BLOCK_POINTS, progress=False, client=client)
            elapsed = time.monotonic() - started
            deadline = time.monotonic() + 10
            while cluster.scheduler.tasks and time.monotonic() < deadline:
                time.sleep(0.05)
            assert not cluster.scheduler.tasks  # every task of the scan cancelled
            release.set()  # the blocked thread ends, and the cluster closes
    finally:
        dask_backend.reduce_chunk = real
        release.set()
    assert elapsed < 15
    result = error.value.result
    assert result.partial and result.points == 2 * BLOCK_POINTS
    assert int(result["s"].points.sum()) == result.points


def test_the_stall_timeout_is_a_positive_duration_from_the_dask_config():
    import dask

    assert dask_backend.stall_timeout_s() == dask_backend.STALL_TIMEOUT_S
    with dask.config.set({"epc-fast.stall-timeout": "2 hours"}):
        assert dask_backend.stall_timeout_s() == 7200.0
    for value in ("soon", 0, -5):
        with dask.config.set({"epc-fast.stall-timeout": value}), \
                pytest.raises(ValueError, match=r"^Dask config epc-fast\.stall-timeout = "):
            dask_backend.stall_timeout_s()
