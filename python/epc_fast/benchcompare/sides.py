"""A side of a comparison: a command line that starts a Python with epc_fast, running
:mod:`epc_fast.benchcompare.worker` as a session over its stdin and stdout.

A side answers each request within ``timeout`` seconds, or it is killed with its whole process
group (it runs in a session of its own, so that the group holds whatever its command started);
an answer that is not JSON, JSON of the wrong shape, or a time that is not a finite number of
seconds above 0 ends the session too. Each fault raises a RuntimeError that names the side,
its command and the fault."""

from __future__ import annotations

import json
import math
import os
import select
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

WORKER = Path(__file__).with_name("worker.py")
#: Default seconds a side may take to answer one request (a block's setup, or one sample).
TIMEOUT = 600.0
#: Seconds a side may take to end after the quit request before it is killed.
QUIT_GRACE_S = 30.0
#: Longest answer line read; a longer one is not an answer of the worker.
MAX_LINE_BYTES = 2**20
#: The build's fields the reports show.
BUILD_FIELDS = ("version", "isa", "openmp", "python", "module")


def split_command(text: str, name: str) -> list[str]:
    """The words of a side's command line, split as a POSIX shell would; a ValueError naming
    the side when it is empty or not a command line."""
    try:
        words = shlex.split(text)
    except ValueError as exc:
        raise ValueError(f"{name} {text!r}: not a command line ({exc})") from None
    if not words:
        raise ValueError(f"{name} {text!r}: expected a command line that starts a Python with "
                         f"epc_fast installed, e.g. 'venv/bin/python' or "
                         f"'env EPC_FAST_ISA=x86-64 python3'")
    return words


def _seconds(value) -> bool:
    """Whether ``value`` is a finite number of seconds above 0."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value) and value > 0)


def _kind(value) -> str:
    return {dict: "object", list: "array", str: "string", bool: "boolean",
            type(None): "null"}.get(type(value), "number")


class Side:
    """A worker session in one side's Python; ``setup`` and ``sample`` send one request each and
    return the answer, checked. A side whose Python does not start, whose worker fails, stops
    answering or answers what the worker does not raises a RuntimeError naming the side and
    its command, with the worker's last words where it has any."""

    def __init__(self, name: str, command: str, timeout: float = TIMEOUT):
        self.name, self.command, self.timeout = name, command, timeout
        words = split_command(command, name)
        self._stderr = tempfile.TemporaryFile()
        self._buffer = b""
        try:
            self.process = subprocess.Popen(
                [*words, str(WORKER), "serve"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                stderr=self._stderr, start_new_session=True)
        except OSError as exc:
            self._stderr.close()
            raise RuntimeError(f"{name} {command!r}: cannot start it ({exc})") from None

    def setup(self, workloads: dict, seed: int) -> dict:
        """Draws the designs and runs each workload twice: the build, each workload's seconds
        in its second call, or why it cannot run."""
        answer = self._request(op="setup", workloads=workloads, seed=seed)
        for key in ("build", "seconds", "unavailable"):
            if not isinstance(answer.get(key), dict):
                self._fault(f"answered setup without {key!r}" if key not in answer else
                            f"answered setup with {key!r} a JSON {_kind(answer[key])}, "
                            f"expected an object")
        missing = [key for key in BUILD_FIELDS if key not in answer["build"]]
        if missing:
            self._fault(f"answered setup with a build without {missing[0]!r}")
        for name in workloads:
            if name in answer["seconds"]:
                if not _seconds(answer["seconds"][name]):
                    self._fault(f"its setup time of {name} is {answer['seconds'][name]!r}: "
                                f"expected a finite number of seconds above 0")
            elif not isinstance(answer["unavailable"].get(name), str):
                self._fault(f"answered setup with neither a time nor a reason for {name}")
        return answer

    def sample(self, workload: str, reps: int) -> dict:
        """The mean seconds of ``reps`` calls of ``workload`` in a row: wall (``seconds``) and
        CPU time (``cpu_seconds``)."""
        answer = self._request(op="time", workload=workload, reps=reps)
        for key in ("seconds", "cpu_seconds"):
            if key not in answer:
                self._fault(f"answered time without {key!r}")
            if not _seconds(answer[key]):
                self._fault(f"its time ({key}) of {workload} is {answer[key]!r}: expected a "
                            f"finite number of seconds above 0")
        return answer

    def _request(self, **message) -> dict:
        op = message["op"]
        try:
            self.process.stdin.write(json.dumps(message).encode() + b"\n")
            self.process.stdin.flush()
            line = self._read_line(op)
        except (BrokenPipeError, OSError):
            line = None
        if line is None:
            self._fault("the worker stopped", stopped=True)
        text = line.decode("utf-8", errors="replace").strip()
        try:
            answer = json.loads(text)
        except ValueError:
            shown = text if len(text) <= 80 else text[:77] + "..."
            self._fault(f"answered {op} with {shown!r}: not JSON")
        if not isinstance(answer, dict):
            self._fault(f"answered {op} with a JSON {_kind(answer)}, expected an object")
        if "error" in answer:
            self.kill()
            raise RuntimeError(f"{self.name}: {answer['error']}")
        return answer

    def _read_line(self, op: str) -> bytes | None:
        """The next line of the worker's stdout (None at its end), or a fault once ``timeout``
        seconds pass without one."""
        deadline = time.monotonic() + self.timeout
        descriptor = self.process.stdout.fileno()
        while b"\n" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                self._fault(f"no answer to {op} within {self.timeout:g} s (--timeout); killed "
                            f"it and its process group")
            if not select.select([descriptor], [], [], left)[0]:
                continue
            chunk = os.read(descriptor, 65536)
            if not chunk:
                return None
            self._buffer += chunk
            if len(self._buffer) > MAX_LINE_BYTES and b"\n" not in self._buffer:
                self._fault(f"answered {op} with more than {MAX_LINE_BYTES} bytes on one line: "
                            f"not the worker's answer")
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line

    def _fault(self, what: str, stopped: bool = False):
        """Kills the side (after up to 10 s for one that ``stopped`` to end by itself) and
        raises the RuntimeError that names it, ``what`` and the worker's last words."""
        if stopped:
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        self.kill()
        words = self._last_words()
        if stopped:
            what += f": {words or f'exit status {self.process.returncode}'}"
        elif words:
            what += f"; its last words: {words}"
        raise RuntimeError(f"{self.name} {self.command!r}: {what}")

    def _last_words(self) -> str:
        """The last lines of the worker's stderr, on one line."""
        try:
            size = self._stderr.seek(0, os.SEEK_END)
            self._stderr.seek(max(0, size - 65536))
            text = self._stderr.read().decode("utf-8", errors="replace").strip()
        except (OSError, ValueError):
            text = ""
        return " | ".join(text.splitlines()[-5:])

    def kill(self) -> None:
        """Kills the side's process group (the worker and whatever its command started)."""
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except OSError:
            pass  # the group has ended
        self.process.wait()

    def close(self) -> None:
        """Ends the session: the quit request, then the process group killed if the worker
        has not ended within QUIT_GRACE_S, or has left processes behind."""
        if self.process.poll() is None:
            try:
                self.process.stdin.write(json.dumps({"op": "quit"}).encode() + b"\n")
                self.process.stdin.close()
                self.process.wait(timeout=QUIT_GRACE_S)
            except (OSError, subprocess.TimeoutExpired):
                pass
        self.kill()
        for stream in (self.process.stdin, self.process.stdout, self._stderr):
            try:
                stream.close()
            except OSError:
                pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def this_python() -> str:
    """The command line of the Python running this, quoted for a shell."""
    return shlex.quote(sys.executable)
