"""A scan's manifest, ``manifest.json`` in its output directory: what ran and how far it got,
written and read here for every command's output directory (the scan's first record:
:func:`epc_fast.scan.output.record.new_manifest`).

It records the config (its TOML text and the command line's overrides), the seed, the epc_fast
version and core build, the points asked for and done, ``partial``, the state (``running``
while the scan runs, updated after every merged chunk; then ``complete``, ``interrupted`` or
``failed``) and the files written. A directory whose manifest still says ``running`` and
whose lock no run holds (:mod:`~epc_fast.jobs.output.lock`) was left by a scan that was killed.

A scan's last record (any state but ``running``) is written even on a full disk: every
manifest's file keeps :data:`RESERVE_BYTES` of spaces after its JSON (which JSON ignores), and
when the atomic write of the last record fails for lack of space, the record is written over the
previous one, in place, in the blocks the file already has. When even that fails, stderr says
that the manifest could not be written and what it still says.
"""

from __future__ import annotations

import errno
import json
import os
import sys
import time
from pathlib import Path

from ..atomic import atomic_write

__all__ = ["MANIFEST_NAME", "FORMAT", "RESERVE_BYTES", "write_manifest", "read_manifest",
           "describe", "now_utc"]

MANIFEST_NAME = "manifest.json"
FORMAT = "epc_fast scan manifest 1"
#: Bytes of spaces after a manifest's JSON: room for its last record (a state, the error that
#: stopped the scan, the files written) in the file's own blocks when the disk is full.
RESERVE_BYTES = 4096
#: The errors of a disk (or a quota) with no room left.
_NO_ROOM = (errno.ENOSPC, errno.EDQUOT)


def now_utc() -> str:
    """The time now in UTC, as a manifest records it."""
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())


def write_manifest(directory, manifest: dict) -> Path:
    """Write ``manifest`` (its ``updated_utc`` set now) atomically into ``directory``.

    A scan's last record (a state other than ``running``) that finds no room on the disk is
    written in place over the previous record; when it cannot be written at all, stderr says
    so before the error is raised.
    """
    manifest["updated_utc"] = now_utc()
    text = json.dumps(manifest, indent=1) + "\n"
    path = Path(directory) / MANIFEST_NAME
    try:
        return atomic_write(path, lambda p: p.write_text(text + " " * RESERVE_BYTES + "\n"))
    except OSError as error:
        if manifest.get("state") == "running":  # the scan stops; its last record follows
            raise
        if error.errno in _NO_ROOM:
            try:
                _rewrite_in_place(path, text)
                return path
            except OSError:
                pass
        _say_not_recorded(path, error)
        raise


def _rewrite_in_place(path: Path, text: str) -> None:
    """Write ``text`` over the manifest at ``path``, padded with spaces to the file's size, in
    the blocks it has: no new block is needed. Not atomic (a crash midway leaves a file that
    :func:`read_manifest` refuses): only for a disk with no room for a new file."""
    data = text.encode()
    descriptor = os.open(path, os.O_WRONLY | getattr(os, "O_NOFOLLOW", 0))
    try:
        size = os.fstat(descriptor).st_size
        if len(data) > size:
            raise OSError(errno.ENOSPC, f"{os.strerror(errno.ENOSPC)} (the record is "
                                        f"{len(data):,} bytes, its file {size:,})")
        data += b" " * (size - len(data) - 1) + b"\n"
        written = 0
        while written < size:
            written += os.pwrite(descriptor, data[written:], written)
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def _say_not_recorded(path: Path, error: OSError) -> None:
    """Say on stderr that a scan's end is not in its manifest, and what the manifest says."""
    found = read_manifest(path.parent)
    if found is None:
        now = "it is missing or unreadable"
    else:
        now = (f"it still says {found.get('state')!r}, {found.get('points_done', 0):,} points "
               "done")
    text = " ".join(str(error).split())
    print(f"epc-fast scan: could not record how the scan ended in {path} "
          f"({type(error).__name__}: {text}): {now}", file=sys.stderr)


def read_manifest(directory) -> dict | None:
    """The manifest in ``directory``, or None when there is none or it is not one of ours."""
    path = Path(directory) / MANIFEST_NAME
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size > 2**26:
            return None
        manifest = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return manifest if isinstance(manifest, dict) and manifest.get("format") == FORMAT else None


def describe(manifest: dict) -> str:
    """What a manifest says of its scan, in a few words, for a directory whose lock no run
    holds (a live run's directory is refused naming that run before its manifest is read)."""
    done = f"{manifest.get('points_done', 0):,} of {manifest.get('points_requested', 0):,} points"
    state = manifest.get("state")
    if state == "running":
        return (f"a scan that did not finish ({done} merged, last recorded "
                f"{manifest.get('updated_utc')}): it was killed (no run holds this "
                "directory's lock)")
    if state == "complete":
        return f"a complete scan ({done})"
    return f"a partial scan ({state}, {done}, stopped by {manifest.get('stopped_by')})"
