"""The output directory of an ``epc-fast`` command: one policy for everything a run writes.

- One run writes in a directory at a time: :meth:`OutputDirectory.prepare` takes its lock
  (:mod:`~epc_fast.jobs.output.lock`) before anything else, refuses it while another run
  holds it, and takes it over, saying so, from a run that died; :meth:`OutputDirectory.close`
  (or the end of a ``with`` block) releases it.
- Everything stays inside the directory: file names are checked (no separator, no ``..``) and
  a symlink in it is replaced, never written through.
- A directory that is not empty is refused unless ``overwrite``; then the files this run
  writes are replaced, and the previous run's files it will not write are removed before the
  first point (those its manifest lists, its Parquet parts, and the names an ``epc-fast``
  command always writes, :data:`COMMAND_FILES`), so no file of
  another run is left beside this run's; nothing else is touched. A dead run's temporary
  files (and its lock file) are removed, and do not make the directory "not empty".
- Before the first point: the directory is created, a probe file is written and removed
  (writability), and its free space is compared with what the scan will write.
- Every file is written to a temporary name in the same directory and renamed into place
  (:func:`~epc_fast.jobs.atomic.atomic_write`).
"""

from __future__ import annotations

import os
import re
import shutil
import sys
from pathlib import Path

from ..atomic import TEMPORARY_SUFFIX, atomic_write, probe_writable
from ..errors import OutputError
from .lock import LOCK_NAME, OutputLock
from .manifest import MANIFEST_NAME, describe, read_manifest

__all__ = ["OutputDirectory", "TABLE_BYTES", "PARQUET_BYTES_PER_VALUE", "STAGING_PREFIX",
           "COMMAND_FILES"]

#: The file names an ``epc-fast`` command writes whatever its config: ``optimize``'s four,
#: ``sobol``'s two and the scan's manifest (which lists the scan's other files). ``--overwrite``
#: removes these, and those the previous manifest lists, when the run will not write them.
COMMAND_FILES = frozenset({"optimum.json", "optimum.md", "curve.csv", "curve.png",
                           "sobol.csv", "sobol.md", MANIFEST_NAME})
#: The start of the name of a run's staging directory for its Parquet parts.
STAGING_PREFIX = ".run-"

#: Bytes kept free for tables, plots and the manifest.
TABLE_BYTES = 16 * 2**20
#: Bytes a Parquet point takes per column at most (8-byte values, before compression).
PARQUET_BYTES_PER_VALUE = 8
_SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,199}")
_PARTS = re.compile(r"(\.ready-)?part-\d{12,}\.parquet")
#: A temporary file of a run that died: an atomic write's or a writability probe's.
_LEFTOVER = re.compile(r"\.(.+\.[0-9a-f]{12}|write-probe-\d+)" + re.escape(TEMPORARY_SUFFIX))


def _short_list(names) -> str:
    names = sorted(names)
    return ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")


def _human(count: float) -> str:
    for unit in ("bytes", "KB", "MB", "GB", "TB"):
        if count < 1000:
            return f"{count:.3g} {unit}"
        count /= 1000
    return f"{count:.3g} PB"


class OutputDirectory:
    """A scan's output directory, checked and locked by :meth:`prepare` before the scan starts,
    released by :meth:`close` (a context manager: ``with OutputDirectory(path) as out``).

    Parameters
    ----------
    path : the directory (``--out``); created if missing.
    overwrite : replace this scan's files in a directory that is not empty.
    """

    def __init__(self, path, overwrite: bool = False):
        self.path = Path(path)
        self.overwrite = overwrite
        self.written: list[str] = []
        self.lock = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Release the directory's lock (nothing when :meth:`prepare` did not take it)."""
        if self.lock is not None:
            self.lock.release()
            self.lock = None

    def _take_lock(self) -> None:
        if self.lock is not None:
            return
        lock = OutputLock(self.path)
        previous = lock.acquire()
        self.lock = lock
        if previous is not None:
            print(f"--out {str(self.path)!r}: took over the lock of a run that ended without "
                  f"releasing it ({OutputLock.describe(previous)}); the system freed it when "
                  "that run's process ended", file=sys.stderr)

    def _refuse(self, why: str):
        raise OutputError(f"--out {str(self.path)!r}: {why}")

    def prepare(self, planned: dict, parquet: str | None = None, parquet_bytes: int = 0) -> None:
        """Check and make ready the directory for the files ``planned`` ({name: what}).

        ``parquet`` names the Parquet directory among them, ``parquet_bytes`` the bytes its
        parts will take at most.
        """
        for name in planned:
            if not _SAFE_NAME.fullmatch(name) or ".." in name:
                self._refuse(f"{name!r} is not a file name a scan writes (letters, digits, "
                             "_ - and .)")
        if self.path.exists() and not self.path.is_dir():
            self._refuse("exists and is not a directory")
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            self._refuse(f"cannot create or list it: {error.strerror}")
        self._take_lock()
        try:
            present = [name for name in os.listdir(self.path) if name != LOCK_NAME]
        except OSError as error:
            self._refuse(f"cannot create or list it: {error.strerror}")
        # The lock is held: temporary files here are a dead run's leftovers, not results.
        for name in [name for name in present if _LEFTOVER.fullmatch(name)]:
            self._remove(self.path / name)
            present.remove(name)
        if present and not self.overwrite:
            self._refuse(self._found(present, planned))
        for name in planned:
            target = self.path / name
            is_dir = target.is_dir() and not target.is_symlink()
            if name == parquet:
                if target.is_symlink() or (target.exists() and not is_dir):
                    self._refuse(f"{name} exists and is not a directory; the Parquet parts "
                                 "go into a real directory only (a symlink is not followed)")
            elif is_dir:
                self._refuse(f"{name} is a directory; this scan writes a file of that name")
        if self.overwrite:
            self._clear_previous(present, parquet)
            self._remove_previous_run(planned, parquet)
        self._probe(self.path)
        if parquet is not None:
            try:
                (self.path / parquet).mkdir(exist_ok=True)
            except OSError as error:
                self._refuse(f"cannot create {parquet}: {error.strerror}")
            self._probe(self.path / parquet)
        needed = TABLE_BYTES + parquet_bytes
        free = shutil.disk_usage(self.path).free
        if free < needed:
            self._refuse(f"has {_human(free)} free; this scan writes up to ~{_human(needed)} "
                         f"(tables and plots {_human(TABLE_BYTES)}"
                         + (f", Parquet {_human(parquet_bytes)})" if parquet else ")")
                         + ": free space, choose another --out, or scan fewer points")

    def _found(self, present: list, planned: dict) -> str:
        manifest = read_manifest(self.path)
        clashing = sorted(set(present) & set(planned))
        what = (f"holds {describe(manifest)}" if manifest is not None
                else f"is not empty ({_short_list(present)})")
        replaced = (f"; --overwrite replaces {_short_list(clashing)}" if clashing
                    else "; --overwrite writes beside them")
        return (f"{what}{replaced}, or choose another --out (a scan never writes into a "
                "directory that is not empty without --overwrite)")

    def _clear_previous(self, present: list, parquet: str | None) -> None:
        """Remove the temporary files a killed scan left, and the previous Parquet parts and
        staging directories (the lock is held: no other run is writing them)."""
        for name in present:
            if name.startswith(".") and name.endswith(TEMPORARY_SUFFIX):
                self._remove(self.path / name)
        directory = None if parquet is None else self.path / parquet
        if directory is not None and directory.is_dir() and not directory.is_symlink():
            for entry in os.scandir(directory):
                stale = _PARTS.fullmatch(entry.name) or (
                    entry.name.startswith(".") and entry.name.endswith(TEMPORARY_SUFFIX))
                if stale and entry.is_file(follow_symlinks=False):
                    self._remove(Path(entry.path))
                elif (entry.name.startswith(STAGING_PREFIX)
                      and entry.is_dir(follow_symlinks=False)):
                    shutil.rmtree(entry.path, ignore_errors=True)

    def _remove_previous_run(self, planned: dict, parquet: str | None) -> None:
        """Remove the previous run's files that this run will not write: those its manifest
        lists and the names a command always writes; a Parquet directory of its that this run
        does not reuse loses its parts and staging directories (and goes, once empty)."""
        manifest = read_manifest(self.path) or {}
        files = manifest.get("files")
        previous = set(COMMAND_FILES)
        previous.update(name for name in (files if isinstance(files, list) else [])
                        if isinstance(name, str) and _SAFE_NAME.fullmatch(name)
                        and ".." not in name)
        for name in sorted(previous - set(planned)):
            target = self.path / name
            if target.is_symlink() or target.is_file():
                self._remove(target)
        old = manifest.get("parquet")
        if (isinstance(old, str) and old != parquet and _SAFE_NAME.fullmatch(old)
                and ".." not in old and old not in planned):
            directory = self.path / old
            if directory.is_dir() and not directory.is_symlink():
                self._clear_previous([], old)
                try:
                    directory.rmdir()
                except OSError:
                    pass  # it holds files the user put there: they stay

    def _remove(self, path: Path) -> None:
        try:
            path.unlink()
        except OSError as error:
            self._refuse(f"cannot remove {path.name}: {error.strerror}")

    def _probe(self, directory: Path) -> None:
        try:
            probe_writable(directory)
        except OSError as error:
            self._refuse(f"{directory.name or directory} is not writable: {error.strerror}")

    def write(self, name: str, write) -> Path:
        """Write the file ``name`` atomically with ``write(temporary_path)``."""
        if not _SAFE_NAME.fullmatch(name) or ".." in name:
            self._refuse(f"{name!r} is not a file name a scan writes")
        path = atomic_write(self.path / name, write)
        if name not in self.written:
            self.written.append(name)
        return path
