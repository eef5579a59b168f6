"""Per-point output: one Parquet file per chunk in a directory (needs the ``parquet`` extra).

Each chunk writes ``part-<first point, 12 digits>.parquet`` with the point index, the design
(a dictionary column of names), every parameter that varies, and every output of
:func:`epc_fast.evaluate`. The directory is one dataset: ``pyarrow.parquet.read_table(dir)``
or ``pandas.read_parquet(dir)`` reads it whole, in point order. On Dask, each worker writes its
own chunks, so the directory must be on a file system every worker sees.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..api import Result
from .space import Points, Space

__all__ = ["prepare_directory", "write_part"]


def _pyarrow():
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise ImportError("Parquet output needs pyarrow: pip install 'epc-fast[parquet]'") from None
    return pyarrow


def prepare_directory(directory) -> str:
    """Create ``directory`` for a scan's parts; refuse one that already holds parts."""
    _pyarrow()
    path = Path(directory)
    path.mkdir(parents=True, exist_ok=True)
    if any(path.glob("part-*.parquet")):
        raise FileExistsError(f"{path} already holds part-*.parquet files of another scan")
    return str(path)


def write_part(directory: str, space: Space, points: Points, result: Result) -> None:
    """Write one chunk's points and outputs."""
    pa = _pyarrow()
    columns = {"point": pa.array(points.index)}
    if space.design_names:
        columns["design"] = pa.DictionaryArray.from_arrays(
            pa.array(points.indices["design"].astype(np.int32)), pa.array(space.design_names))
    for name in space.varying_parameters:
        columns[name] = pa.array(points.parameters[name])
    for name, values in result.as_dict().items():
        columns[name] = pa.array(values)
    table = pa.table(columns)
    pa.parquet.write_table(table, Path(directory) / f"part-{points.start:012d}.parquet")
