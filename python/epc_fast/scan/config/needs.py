"""The optional dependencies a scan of a config needs, checked before its first point
(:func:`epc_fast.jobs.extras.check_extras`)."""

from __future__ import annotations

from ...jobs.extras import DASK, PARQUET, PLOT, SENSITIVITY

__all__ = ["scan_extras"]


def scan_extras(config, planned, cluster: bool) -> list:
    """What a scan of ``config`` needs (see :func:`check_extras`): matplotlib when it writes a
    plot (a ``.png`` among the ``planned`` files), pyarrow for Parquet, dask.distributed on a
    cluster, SALib for a ``[sobol]`` table."""
    needs = []
    if any(str(name).endswith(".png") for name in planned):
        needs.append((PLOT, "the scan's plots", "--no-plots"))
    if config.parquet is not None:
        needs.append((PARQUET, "the Parquet points ([output] parquet)", "no [output] parquet"))
    if cluster:
        needs.append((DASK, "a scan on a cluster (--scheduler)", ""))
    if config.sobol is not None:
        needs.append((SENSITIVITY, "the [sobol] table's Sobol' indices", ""))
    return needs
