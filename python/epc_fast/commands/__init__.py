"""Sub-commands of ``epc-fast``, one module each, found by :func:`discover`.

A command module defines ``NAME`` (the sub-command), ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int`` (the exit code). Adding a module here adds a
sub-command; nothing else needs to change.
"""

from __future__ import annotations

import importlib
import pkgutil


def discover() -> dict:
    """{name: module} of every command module in this package, sorted by name."""
    modules = {}
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        modules[module.NAME] = module
    return dict(sorted(modules.items()))
