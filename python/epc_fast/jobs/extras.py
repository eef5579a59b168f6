"""The optional dependencies a run needs, checked before its first point.

Each optional dependency belongs to an extra of the package (``pip install 'epc-fast[plot]'``)
and is imported only by the code that uses it, after the points are computed. A command asks
here first, so that a run without it stops before any work, in one line naming the extra to
install and, where there is one, the flag that does without (``--no-plots``), with exit code 2
(:class:`MissingExtra` is a usage error) instead of failing after its last point.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from .errors import UsageError

__all__ = ["Extra", "MissingExtra", "PLOT", "PARQUET", "DASK", "SENSITIVITY", "OPTIMIZE",
           "check_extras"]


class MissingExtra(UsageError, ImportError):
    """An optional dependency a run needs is not installed (or does not import); the message
    names the extra to install and the flag that does without, if any."""


@dataclass(frozen=True)
class Extra:
    """An extra of the package: its name, the modules it provides (imported in order, the
    top-level package first) and what needs them, for messages."""

    name: str
    modules: tuple
    package: str


PLOT = Extra("plot", ("matplotlib", "matplotlib.figure"), "matplotlib")
PARQUET = Extra("parquet", ("pyarrow", "pyarrow.parquet"), "pyarrow")
DASK = Extra("dask", ("distributed",), "dask.distributed")
SENSITIVITY = Extra("sensitivity", ("SALib", "SALib.sample.sobol", "SALib.analyze.sobol"),
                    "SALib")
OPTIMIZE = Extra("optimize", ("scipy", "scipy.optimize"), "SciPy")


def _missing(extra: Extra) -> str | None:
    """The first of ``extra``'s modules that does not import, and why; None when all do."""
    for module in extra.modules:
        try:
            importlib.import_module(module)
        except ImportError as error:
            return f"{module}: {error}"
    return None


def check_extras(needs) -> None:
    """A :class:`MissingExtra` for the first of ``needs`` (``(extra, what, without)``: an
    :class:`Extra`, what needs it, the flag that does without it or ``""``) whose modules do
    not import."""
    for extra, what, without in needs:
        if _missing(extra) is not None:
            alternative = f" (or {without})" if without else ""
            raise MissingExtra(f"{extra.package} is needed for {what} and is not installed: "
                               f"pip install 'epc-fast[{extra.name}]'{alternative}")
