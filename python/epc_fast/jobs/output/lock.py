"""One writer per output directory: a lock taken before anything is written in ``--out``.

The lock is ``fcntl.flock`` on the hidden file :data:`LOCK_NAME` in the directory, which holds
its holder's pid, host, start time and command. The kernel releases a flock when its holder's
last descriptor closes, so a run that dies (SIGKILL, a power cut of its machine on a network
file system) leaves no lock behind: the next run takes it over and says whose it was. A live
holder's lock is refused with one line naming it. The file is removed when the run releases
the lock; a file that is left names a run that died. Anything else under the lock's name (a
FIFO, a directory, a symbolic link) is refused with one line naming it, before it is opened
for writing.

A releasing holder removes the file while it holds the lock, so a run that opened the old file
just before may get the lock of a file that is no longer there: it checks that the file it
locked is still the one under the name, and tries again if not.
"""

from __future__ import annotations

import json
import os
import socket
import stat
import sys
import time
from pathlib import Path

from ..errors import OutputError

__all__ = ["OutputLock", "LOCK_NAME"]

#: The lock file in an output directory.
LOCK_NAME = ".epc-fast.lock"
#: Tries to lock a file that a releasing holder removed in between.
_TRIES = 20


def _holder_text(holder: dict) -> str:
    if not holder.get("pid"):
        return "another run"
    return (f"pid {holder['pid']}" + (f" on {holder['host']}" if holder.get("host") else "")
            + (f" since {holder['since']}" if holder.get("since") else "")
            + (f" ({holder['command']})" if holder.get("command") else ""))


#: What a path that is not a regular file is, for people.
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
          (stat.S_ISLNK, "a symbolic link"), (stat.S_ISSOCK, "a socket"),
          (stat.S_ISCHR, "a device"), (stat.S_ISBLK, "a device"))


def _kind(status, target) -> str | None:
    """What ``target`` is by ``status`` (os.lstat of a path, os.fstat of a descriptor) when it
    exists and is not a regular file ("a FIFO", "a directory", ...); None otherwise."""
    try:
        mode = status(target).st_mode
    except FileNotFoundError:
        return None
    if stat.S_ISREG(mode):
        return None
    return next((text for test, text in _KINDS if test(mode)), "a special file")


def _read_holder(descriptor: int) -> dict:
    try:
        os.lseek(descriptor, 0, os.SEEK_SET)
        holder = json.loads(os.read(descriptor, 4096).decode("utf-8", "replace") or "{}")
    except (OSError, ValueError):
        return {}
    return holder if isinstance(holder, dict) else {}


class OutputLock:
    """The lock of the directory ``directory`` (which exists).

    :meth:`acquire` takes it or raises :class:`~epc_fast.jobs.errors.OutputError` naming the
    holder; it returns the holder taken over from (a run that died holding it), or None.
    :meth:`release` gives it back and removes the file.
    """

    def __init__(self, directory):
        self.path = Path(directory) / LOCK_NAME
        self.descriptor = None

    def acquire(self) -> dict | None:
        import fcntl

        flags = (os.O_RDWR | os.O_CREAT | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0)
                 | getattr(os, "O_CLOEXEC", 0))
        for _ in range(_TRIES):
            self._check_kind(_kind(os.lstat, self.path))
            try:
                descriptor = os.open(self.path, flags, 0o644)
            except OSError as error:
                raise OutputError(f"--out {str(self.path.parent)!r}: cannot create its lock "
                                  f"file {LOCK_NAME}: {error.strerror}") from None
            try:
                self._check_kind(_kind(os.fstat, descriptor))
            except OutputError:
                os.close(descriptor)
                raise
            try:
                fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                holder = _read_holder(descriptor)
                os.close(descriptor)
                raise OutputError(
                    f"--out {str(self.path.parent)!r}: another run writes here: "
                    f"{_holder_text(holder)}; wait for it to end, or choose another --out"
                ) from None
            try:
                same = os.fstat(descriptor).st_ino == os.stat(self.path,
                                                              follow_symlinks=False).st_ino
            except FileNotFoundError:
                same = False
            if not same:
                os.close(descriptor)
                continue
            previous = _read_holder(descriptor)
            self.descriptor = descriptor
            self._write_holder()
            return previous or None
        raise OutputError(f"--out {str(self.path.parent)!r}: its lock file {LOCK_NAME} keeps "
                          "being replaced; another run is starting or ending there")

    def _check_kind(self, kind: str | None) -> None:
        """An OutputError naming the lock file when it is not a regular file (``kind``)."""
        if kind is not None:
            raise OutputError(f"--out {str(self.path.parent)!r}: its lock file {self.path} is "
                              f"{kind}, not a file: remove it, or choose another --out")

    def _write_holder(self) -> None:
        holder = {"pid": os.getpid(), "host": socket.gethostname(),
                  "since": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                  "command": " ".join(["epc-fast", *sys.argv[1:]])[:200]}
        os.ftruncate(self.descriptor, 0)
        os.pwrite(self.descriptor, (json.dumps(holder) + "\n").encode(), 0)

    def release(self) -> None:
        if self.descriptor is None:
            return
        try:
            if os.fstat(self.descriptor).st_ino == os.stat(self.path,
                                                           follow_symlinks=False).st_ino:
                os.unlink(self.path)
        except OSError:
            pass
        finally:
            os.close(self.descriptor)
            self.descriptor = None

    def __del__(self):
        # An OutputDirectory dropped without close() gives the lock back with its object.
        self.release()

    @staticmethod
    def describe(holder: dict) -> str:
        """The holder of a lock, in a few words."""
        return _holder_text(holder)
