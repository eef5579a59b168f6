"""Sub-commands of ``epc-fast``, one module each, found by :func:`discover`.

A command module defines ``NAME`` (the sub-command), ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int`` (the exit code). Adding a module here adds a
sub-command; nothing else needs to change. The helpers below are what the commands share:
their arguments and how they print a duration.
"""

from __future__ import annotations

import argparse
import importlib
import math
import pkgutil


def discover() -> dict:
    """{name: module} of every command module in this package, sorted by name."""
    modules = {}
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        modules[module.NAME] = module
    return dict(sorted(modules.items()))


def whole(name: str, low: int, high: int, multiple: int = 1):
    """An argparse type: an integer in [low, high] (``1e9`` accepted, ``70000.9`` refused)."""
    def parse(text: str) -> int:
        try:
            value = float(text) if any(c in text for c in ".eE") else int(text)
        except ValueError:
            value = math.nan
        if isinstance(value, float):
            value = int(value) if math.isfinite(value) and value.is_integer() else None
        if value is None or not low <= value <= high or value % multiple:
            extra = f", a multiple of {multiple}" if multiple > 1 else ""
            raise argparse.ArgumentTypeError(
                f"{name} {text!r}: expected an integer between {low:,} and {high:,}{extra}")
        return value
    return parse


def add_output_arguments(parser: argparse.ArgumentParser, default: str, replaced: str) -> None:
    """``--out`` (default ``default``) and ``--overwrite``, which replaces only ``replaced``."""
    parser.add_argument("--out", default=default, help="output directory (default: "
                        "%(default)s); refused when not empty, unless --overwrite")
    parser.add_argument("--overwrite", action="store_true", help="write into a --out that is not "
                        f"empty, replacing only {replaced}")


def duration(seconds: float) -> str:
    """A wall time with the digits that matter: ``"42 ms"``, ``"3.21 s"``, ``"24.8 s"``,
    ``"2 min 05 s"``."""
    if seconds < 1.0:
        return f"{seconds * 1e3:.2g} ms" if seconds < 0.01 else f"{seconds * 1e3:.0f} ms"
    if seconds < 10.0:
        return f"{seconds:.2f} s"
    if seconds < 60.0:
        return f"{seconds:.1f} s"
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest:02d} s"
