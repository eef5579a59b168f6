"""A Dask scan never mixes in another epc_fast build's numbers, and a cluster that loses every
worker ends the scan with a clear error that keeps the prefix merged before, marked partial."""

import pytest

import epc_fast.scan.dask_backend as dask_backend
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import BLOCK_POINTS, LogUniform, Space, Summary, run
from epc_fast.scan.errors import ScanAborted

distributed = pytest.importorskip("distributed")

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
