"""Per-point output: one Parquet file per chunk in a directory (needs the ``parquet`` extra).

Each chunk writes ``part-<first point, 12 digits>.parquet`` with the point index, the design
(a dictionary column of names), every parameter that varies, and every output of
:func:`epc_fast.evaluate`. The directory is one dataset: ``pyarrow.parquet.read_table(dir)``
or ``pandas.read_parquet(dir)`` reads it whole, in point order. On Dask, each worker writes its
own chunks, so the directory must be on a file system every worker sees.

A part is written in two steps, so the directory never holds more than the merged prefix
under final names: the chunk's task writes it whole to a hidden name (``.ready-part-...``, via
a temporary file and a rename), and the scan renames it to ``part-...`` only once the chunk's
reductions are merged (:func:`commit_parts`). An interrupted or killed scan leaves at most
hidden files beyond its prefix, which Parquet readers skip and :func:`discard_uncommitted`
removes.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..api import Result
from .atomic import TEMPORARY_SUFFIX, atomic_write
from .space import Points, Space

__all__ = ["prepare_directory", "write_part", "commit_parts", "discard_uncommitted",
           "committed_parts"]

_READY = re.compile(r"\.ready-(part-(\d{12,})\.parquet)")
_PART = re.compile(r"part-(\d{12,})\.parquet")


def _pyarrow():
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise ImportError("Parquet output needs pyarrow: pip install 'epc-fast[parquet]'") from None
    return pyarrow


def prepare_directory(directory) -> str:
    """Create ``directory`` for a scan's parts; refuse a symlink (never written through) and a
    directory that already holds parts."""
    _pyarrow()
    path = Path(directory)
    if path.is_symlink():
        raise FileExistsError(f"{path} is a symlink; a scan writes its parts into a real "
                              "directory only")
    path.mkdir(parents=True, exist_ok=True)
    if any(_PART.fullmatch(p.name) or _READY.fullmatch(p.name) for p in path.iterdir()):
        raise FileExistsError(f"{path} already holds part-*.parquet files of another scan")
    # Writable before the first point, not after the first chunk's work.
    os.unlink(atomic_write(path / ".write-probe", lambda probe: probe.write_bytes(b"epc_fast")))
    return str(path)


def write_part(directory: str, space: Space, points: Points, result: Result) -> None:
    """Write one chunk's points and outputs, whole, under its hidden ready name."""
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
    target = Path(directory) / f".ready-part-{points.start:012d}.parquet"
    atomic_write(target, lambda path: pa.parquet.write_table(table, path))


def commit_parts(directory: str, done: int) -> list[str]:
    """Rename every ready part of a chunk starting before point ``done`` to its final name;
    the names committed now, in point order."""
    committed = []
    for entry in sorted(os.scandir(directory), key=lambda e: e.name):
        match = _READY.fullmatch(entry.name)
        if match and int(match.group(2)) < done:
            os.replace(entry.path, os.path.join(directory, match.group(1)))
            committed.append(match.group(1))
    return committed


def committed_parts(directory: str) -> list[str]:
    """The final part names in ``directory``, in point order."""
    return sorted(e.name for e in os.scandir(directory) if _PART.fullmatch(e.name))


def discard_uncommitted(directory: str, done: int) -> None:
    """Remove what lies beyond the merged prefix of ``done`` points: ready parts, temporary
    files, and any part starting at or after ``done``."""
    for entry in os.scandir(directory):
        ready, part = _READY.fullmatch(entry.name), _PART.fullmatch(entry.name)
        stray = (ready is not None or (part is not None and int(part.group(1)) >= done)
                 or (entry.name.startswith(".") and entry.name.endswith(TEMPORARY_SUFFIX)))
        if stray:
            try:
                os.unlink(entry.path)
            except FileNotFoundError:
                pass
