"""Files written whole or not at all: to a temporary name in the same directory, flushed to
disk, then renamed into place (a rename within a directory is atomic on POSIX and Windows).

A crash, a kill or a full disk leaves the previous file (or none) under the final name, never
a truncated one; the temporary name starts with a dot, so readers of a Parquet directory
(``pyarrow``, ``pandas``) skip it. The rename replaces a symlink at the final name itself: it
never writes through it.
"""

from __future__ import annotations

import os
import secrets
from pathlib import Path

__all__ = ["atomic_write", "probe_writable", "TEMPORARY_SUFFIX"]

TEMPORARY_SUFFIX = ".tmp"


def probe_writable(directory) -> None:
    """Write, sync and remove a probe file in ``directory``: an OSError (with its strerror)
    when files cannot be written there (read-only, full, no permission)."""
    probe = Path(directory) / f".write-probe-{os.getpid()}{TEMPORARY_SUFFIX}"
    descriptor = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        os.write(descriptor, b"epc_fast")
        os.fsync(descriptor)
    finally:
        os.close(descriptor)
    os.unlink(probe)


def atomic_write(target, write) -> Path:
    """Call ``write(temporary_path)`` then rename the temporary file to ``target``.

    ``write`` creates the file's content at the path it is given (opening it for writing, or
    passing it to a library's save function). On any error the temporary file is removed and
    ``target`` is left as it was.
    """
    target = Path(target)
    temporary = target.parent / f".{target.name}.{secrets.token_hex(6)}{TEMPORARY_SUFFIX}"
    # O_EXCL: a new file of this process's own, never an existing file or a symlink's target;
    # mode 0o666 less the umask, as an ordinary open() would give.
    os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    try:
        write(Path(temporary))
        descriptor = os.open(temporary, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)
        os.replace(temporary, target)
    except BaseException:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        raise
    return target
