"""SIGINT and SIGTERM during a scan: both stop it between chunks, never inside a merge.

:func:`terminate_as_interrupt` turns SIGTERM into KeyboardInterrupt (as Python already does
for SIGINT) while a scan runs, so a ``kill`` stops the scan like Ctrl-C and its prefix is kept.
:func:`signals_deferred` holds both signals while a chunk is merged and delivers them after.
Both act only in the main thread (the only one Python delivers signals to) and only where the
handler is Python's own, leaving a handler the application installed alone.
:class:`SignalsHeld` holds both, whatever their handlers, while a run makes its directory ready
and while a finished run writes its results, and says which arrived: the command line then ends
as they asked, every file written. :class:`StopSignals`, inside it, lets both stop the scan.
"""

from __future__ import annotations

import signal
import sys
import threading
from contextlib import contextmanager

__all__ = ["terminate_as_interrupt", "signals_deferred", "StopSignals", "SignalsHeld",
           "STOP_SIGNALS"]

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def _interrupt(signum, frame):
    raise KeyboardInterrupt(signal.Signals(signum).name)


@contextmanager
def terminate_as_interrupt():
    """SIGTERM raises KeyboardInterrupt("SIGTERM") while the block runs, when its handler is
    the default (terminate at once)."""
    if not _main_thread() or signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def signals_deferred():
    """Hold SIGINT and SIGTERM until the block ends, then call the handlers they had (so a
    merge is never half done). A signal whose handler is not a Python callable (the default
    action, ignored, or installed outside Python) is not held."""
    held = [s for s in STOP_SIGNALS if callable(signal.getsignal(s))] if _main_thread() else []
    if not held:
        yield
        return
    received = []
    previous = {s: signal.signal(s, lambda signum, frame: received.append(signum)) for s in held}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    for signum in dict.fromkeys(received):
        previous[signum](signum, None)


class StopSignals:
    """A context in which SIGINT and SIGTERM raise KeyboardInterrupt, whatever SIGTERM's handler
    was (an ignored SIGINT stays ignored), and which remembers the signal that stopped the block
    (``name``; "SIGINT" for a KeyboardInterrupt no signal raised): the command line's exit code
    and manifest say which it was. Inside a :class:`SignalsHeld`, it stops the block, and from
    its end the signals are held again: at no moment does a signal fall to its default action.
    """

    def __init__(self):
        self.received = []
        self.previous = {}

    def __enter__(self):
        if _main_thread() and not self.previous:
            for signum in STOP_SIGNALS:
                if signum == signal.SIGTERM or signal.getsignal(signum) is not signal.SIG_IGN:
                    self.previous[signum] = signal.signal(signum, self._stop)
        return self

    def _stop(self, signum, frame):
        name = signal.Signals(signum).name
        self.received.append(name)
        raise KeyboardInterrupt(name)

    def __exit__(self, *exc):
        for signum, handler in self.previous.items():
            signal.signal(signum, handler if handler is not None else signal.SIG_DFL)
        self.previous = {}

    @property
    def name(self) -> str:
        return self.received[0] if self.received else "SIGINT"


class SignalsHeld:
    """A context in which SIGINT and SIGTERM do nothing but be recorded (``received``: their
    names, in order), whatever their handlers were (the default action included; an ignored
    signal stays ignored): a run's directory is made ready, and its tables and manifest are
    written, whole; then the caller ends as the signal asked. In a thread other than the main
    one it holds nothing (Python runs handlers in the main thread only)."""

    def __init__(self):
        self.received = []
        self.previous = {}

    def __enter__(self):
        if _main_thread() and not self.previous:
            for signum in STOP_SIGNALS:
                # None: a handler installed outside Python, which could not be put back.
                if signal.getsignal(signum) not in (signal.SIG_IGN, None):
                    self.previous[signum] = signal.signal(signum, self._record)
        return self

    def _record(self, signum, frame):
        self.received.append(signal.Signals(signum).name)

    def __exit__(self, *exc):
        for signum, handler in self.previous.items():
            signal.signal(signum, handler)
        self.previous = {}

    @property
    def name(self) -> str | None:
        """The first signal received, or None."""
        return self.received[0] if self.received else None

    def exit_code(self, prog: str) -> int:
        """0 when no signal came; else 128 + the first signal's number, after one line on
        stderr saying the files are whole."""
        if self.name is None:
            return 0
        print(f"{prog}: {self.name} while the results were written: every file is written "
              "whole", file=sys.stderr)
        return 128 + signal.Signals[self.name].value
