"""The same scan on a Dask LocalCluster (2 worker processes on loopback) gives the same numbers
as a local scan, to the last bit."""

import dataclasses

import numpy as np
import pytest

from epc_fast.scan import BLOCK_POINTS, run
from helpers.scan import SPACE, assert_same_numbers, every_reduction

distributed = pytest.importorskip("distributed")

POINTS = 4 * BLOCK_POINTS + 999


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield client


def _run(**kwargs):
    return run(SPACE, POINTS, seed=8, reductions=every_reduction(), chunk_points=BLOCK_POINTS,
               **{"progress": False, **kwargs})


def test_a_local_cluster_gives_the_same_numbers_as_a_local_scan(client):
    assert_same_numbers(_run(client=client), _run())


def test_an_interrupted_cluster_scan_returns_the_prefix_merged_in_order(client):
    def interrupt_after_two_chunks(done, total):
        if done >= 2 * BLOCK_POINTS:
            raise KeyboardInterrupt

    on_cluster = _run(client=client, progress=interrupt_after_two_chunks)
    local = _run(progress=interrupt_after_two_chunks)
    assert on_cluster.partial and on_cluster.points == 2 * BLOCK_POINTS
    assert_same_numbers(on_cluster, local)


def test_workers_write_the_same_parquet_files_as_a_local_scan(client, tmp_path):
    import pyarrow.parquet as pq

    _run(client=client, parquet=tmp_path / "cluster")
    _run(parquet=tmp_path / "local")
    on_cluster = pq.read_table(tmp_path / "cluster").to_pydict()
    local = pq.read_table(tmp_path / "local").to_pydict()
    assert on_cluster.keys() == local.keys()
    for name in local:
        assert np.array_equal(np.asarray(on_cluster[name]), np.asarray(local[name]),
                              equal_nan=name not in ("design", "point", "status", "cause")), name


def test_the_cluster_scan_records_where_its_time_went(client):
    timing = dataclasses.asdict(_run(client=client).timing)
    assert all(seconds > 0 for name, seconds in timing.items() if name != "output_s")


def test_a_space_with_readout_modes_gives_the_same_numbers_on_the_cluster(client):
    from epc_fast.presets import HIGH_TIER
    from epc_fast.scan import Choice, LogUniform, Space, Summary

    modes = ({"binning": 1}, {"binning": 2}, {"binning": 2, "frames": 4})
    space = Space(design=Choice([HIGH_TIER[3].with_(read_noise_e=2.0, modes=modes),
                                 HIGH_TIER[0].with_(binning=2, binning_readout="charge")]),
                  illuminance_lux=LogUniform(1, 1e5), alignment_error_um=0.3)
    common = dict(seed=3, reductions={"s": Summary(by="design")}, chunk_points=BLOCK_POINTS,
                  progress=False)
    on_cluster, local = (run(space, 2 * BLOCK_POINTS + 5, client=c, **common)
                         for c in (client, None))
    assert np.array_equal(on_cluster["s"].mode_counts, local["s"].mode_counts)
    assert np.array_equal(on_cluster["s"].mean, local["s"].mean)
    assert on_cluster["s"].mode_counts[0, 1:].min() > 0
