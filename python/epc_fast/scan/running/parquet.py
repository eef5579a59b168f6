"""Per-point output: one Parquet file per chunk in a directory (needs the ``parquet`` extra).

Each chunk writes ``part-<first point, 12 digits>.parquet`` with the point index, the design
(a dictionary column of names), every parameter that varies, and every output of
:func:`epc_fast.evaluate`. The directory is one dataset: ``pyarrow.parquet.read_table(dir)``
or ``pandas.read_parquet(dir)`` reads it whole, in point order. On Dask, each worker writes its
own chunks, so the directory must be on a file system every worker sees.

A part is written in two steps, so the directory never holds more than the merged prefix
under final names: the chunk's task writes it whole to a hidden name (``.ready-part-...``, via
a temporary file and a rename) in the run's own hidden staging directory
(``.run-<pid>-<random>/``, made by :func:`prepare_directory`), and the scan renames it to
``part-...`` in the directory only once the chunk's reductions are merged
(:func:`commit_parts`). An interrupted or killed scan leaves at most hidden files beyond its
prefix, which Parquet readers skip; :func:`discard_uncommitted` removes the run's staging
directory, and only it: never a part, nor what another run stages beside it.

Only the scan's own process moves parts into the directory. A task still running when the scan
ends (a Dask worker's, which cancelling cannot stop) finds the staging directory gone: it
discards its part and never creates the directory again, so nothing it writes lands in the
directory after the scan has returned. The staging directory is renamed away before it is
removed, so a task cannot write into it while it is being removed either.
"""

from __future__ import annotations

import os
import re
import secrets
import shutil
from pathlib import Path

import numpy as np

from ...api import Result
from ...jobs.atomic import atomic_write
from ...jobs.output.directory import STAGING_PREFIX
from ..sampling.space import Points, Space

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
    """Create ``directory`` for a scan's parts and this run's staging directory in it, and
    return the staging directory's path (where the chunks' tasks write); refuse a symlink
    (never written through) and a directory that already holds parts."""
    _pyarrow()
    path = Path(directory).absolute()  # the same on a worker whose directory is another
    if path.is_symlink():
        raise FileExistsError(f"{path} is a symlink; a scan writes its parts into a real "
                              "directory only")
    path.mkdir(parents=True, exist_ok=True)
    if any(_PART.fullmatch(p.name) or _READY.fullmatch(p.name) for p in path.iterdir()):
        raise FileExistsError(f"{path} already holds part-*.parquet files of another scan")
    staging = path / f"{STAGING_PREFIX}{os.getpid()}-{secrets.token_hex(6)}"
    staging.mkdir()
    # Writable before the first point, not after the first chunk's work.
    os.unlink(atomic_write(staging / ".write-probe", lambda probe: probe.write_bytes(b"epc")))
    return str(staging)


def write_part(directory: str, space: Space, points: Points, result: Result) -> None:
    """Write one chunk's points and outputs, whole, under its hidden ready name in the run's
    staging ``directory``; a staging directory that is gone (the scan has ended) is not made
    again: the part is discarded, with FileNotFoundError."""
    if not os.path.isdir(directory):
        raise FileNotFoundError(f"the scan's staging directory {directory} is gone (the scan "
                                f"has ended): the part of points {points.start:,} on is "
                                "discarded")
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
    """Rename every ready part in the staging ``directory`` of a chunk starting before point
    ``done`` to its final name in the Parquet directory; the names committed now, in point
    order."""
    committed = []
    parent = os.path.dirname(os.path.abspath(directory))
    for entry in sorted(os.scandir(directory), key=lambda e: e.name):
        match = _READY.fullmatch(entry.name)
        if match and int(match.group(2)) < done:
            os.replace(entry.path, os.path.join(parent, match.group(1)))
            committed.append(match.group(1))
    return committed


def committed_parts(directory: str) -> list[str]:
    """The final part names in ``directory``, in point order."""
    return sorted(e.name for e in os.scandir(directory) if _PART.fullmatch(e.name))


def discard_uncommitted(directory: str, done: int) -> None:
    """Remove the run's staging ``directory``: its ready parts beyond the merged prefix of
    ``done`` points and its temporary files. Nothing outside it is touched: the parts this
    run committed stay, and so does whatever another run writes beside them.

    It is first renamed to a name no task writes to (still a staging name, which the next
    ``--overwrite`` run clears should its removal fail): a task writing now fails instead of
    adding a file after the removal has listed the directory."""
    doomed = f"{directory}.discarded-{secrets.token_hex(4)}"
    try:
        os.rename(directory, doomed)
    except FileNotFoundError:
        return
    except OSError:
        doomed = directory
    shutil.rmtree(doomed, ignore_errors=True)
