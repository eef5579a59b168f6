"""A side of a comparison: a command line that starts a Python with epc_fast, running
:mod:`epc_fast.benchcompare.worker` as a session over its stdin and stdout."""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
from pathlib import Path

WORKER = Path(__file__).with_name("worker.py")


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


class Side:
    """A worker session in one side's Python; ``request`` sends one JSON request and returns
    the answer. A side whose Python does not start, or whose worker fails, raises a
    RuntimeError naming the side and its command, with the worker's last words."""

    def __init__(self, name: str, command: str):
        self.name, self.command = name, command
        words = split_command(command, name)
        try:
            self.process = subprocess.Popen(
                [*words, str(WORKER), "serve"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                stderr=subprocess.PIPE, text=True, bufsize=1)
        except OSError as exc:
            raise RuntimeError(f"{name} {command!r}: cannot start it ({exc})") from None

    def request(self, **message) -> dict:
        try:
            self.process.stdin.write(json.dumps(message) + "\n")
            self.process.stdin.flush()
            line = self.process.stdout.readline()
        except (BrokenPipeError, OSError):
            line = ""
        if not line:
            raise RuntimeError(f"{self.name} {self.command!r}: the worker stopped: "
                               f"{self._last_words()}")
        answer = json.loads(line)
        if "error" in answer:
            raise RuntimeError(f"{self.name}: {answer['error']}")
        return answer

    def _last_words(self) -> str:
        try:
            self.process.wait(timeout=10)
            text = self.process.stderr.read().strip()
        except subprocess.TimeoutExpired:
            text = ""
        lines = text.splitlines()[-5:]
        return " | ".join(lines) if lines else f"exit status {self.process.returncode}"

    def close(self) -> None:
        if self.process.poll() is None:
            try:
                self.process.stdin.write(json.dumps({"op": "quit"}) + "\n")
                self.process.stdin.close()
                self.process.wait(timeout=30)
            except (OSError, subprocess.TimeoutExpired):
                self.process.kill()
                self.process.wait()
        for stream in (self.process.stdout, self.process.stderr):
            stream.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def this_python() -> str:
    """The command line of the Python running this, quoted for a shell."""
    return shlex.quote(sys.executable)
