"""The checks every entry point applies to its arguments, each naming the argument and its
value in the error it raises: ``evaluate``, the inverse solvers, the optimiser and the scan's
tasks take them from here.

A leaf of the package but for :mod:`epc_fast._limits` (and the compiled core, loaded only when
a default thread count or :func:`float_arrays` is asked for).
"""

from __future__ import annotations

import functools
import math
import operator

import numpy as np

from ._limits import MAX_THREADS, startable_threads, threads_limit_reason

__all__ = ["short", "as_float_array", "float_arrays", "integer", "threads_of", "tolerance",
           "choice", "column", "compiled_core"]

#: The largest integer a float64 holds (its largest finite value).
_LARGEST_INT = int(np.finfo(np.float64).max)

_FLOAT64 = np.dtype(np.float64)

#: Read-only 0-d arrays of the Python floats calls pass, by value (the defaults most of all):
#: a scalar argument costs a dict lookup, not a new array. NaN and -0.0 are not kept (a NaN
#: key never matches; -0.0 would match 0.0's entry).
_SCALARS: dict = {}
_SCALARS_KEPT = 4096


def _scalar_array(value: float) -> np.ndarray:
    """``value`` (a Python float) as a read-only 0-d float64 array, kept for the next call."""
    keyed = value != 0.0 or math.copysign(1.0, value) > 0.0  # not -0.0, which finds 0.0
    arr = _SCALARS.get(value) if keyed else None
    if arr is None:
        arr = np.array(value, dtype=np.float64)
        if keyed and value == value:
            arr.flags.writeable = False
            if len(_SCALARS) >= _SCALARS_KEPT:
                _SCALARS.clear()
            _SCALARS[value] = arr
    return arr


def short(value) -> str:
    """``repr(value)`` on one line (an array's repr breaks lines), cut to 60 characters so
    that an error stays one readable line."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


def as_float_array(name: str, value) -> np.ndarray:
    """``value`` as a native-endian float64 array; a TypeError naming ``name`` for anything but
    real numbers, a ValueError for an integer no float64 holds. A float gives a read-only 0-d
    array; a float64 array is returned as it is."""
    kind = type(value)
    if kind is float:
        return _scalar_array(value)
    if kind is np.ndarray and value.dtype == _FLOAT64:
        return value
    if value is None:
        raise TypeError(f"{name} must be a number or an array of numbers, got None")
    if isinstance(value, np.ma.MaskedArray):
        raise TypeError(f"{name} is a masked array: its mask would be ignored; pass "
                        "plain values (e.g. .filled(np.nan) to make masked points INVALID)")
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be a number or an array of numbers, got {value!r}")
    if isinstance(value, int) and not isinstance(value, bool):  # beyond int64 NumPy says object
        if abs(value) > _LARGEST_INT:
            raise ValueError(f"{name}={short(value)} does not fit a float64 (|x| > 1.8e308)")
        value = float(value)
    try:
        arr = np.asarray(value)
    except Exception as exc:  # ragged lists and the like
        raise TypeError(f"{name} could not be read as an array: {exc}") from None
    if arr.dtype.kind not in "iuf":
        raise TypeError(
            f"{name} must hold real numbers, got dtype {arr.dtype} ({short(value)})")
    return arr.astype(np.float64, copy=False)


def float_arrays(names, values) -> tuple:
    """``[as_float_array(name, value) for name, value in zip(names, values)]``, the set of
    those arrays' shapes but () (what broadcasting them needs) and whether each of those
    arrays is C-contiguous (with one shape, the core reads them all as they are: no
    :func:`column` pass). The compiled core does the
    loop: a float kept from an earlier call and a float64 array are taken as they are, every
    other value is handed to :func:`as_float_array`. evaluate converts all of its model
    parameters on every call (tuples ``names`` and ``values``)."""
    return compiled_core().float_arrays(names, values, _SCALARS, as_float_array)


@functools.lru_cache(maxsize=None)
def compiled_core():
    """The compiled core (:mod:`epc_fast._core`), loaded on first use: importing the package
    loads none of it."""
    from . import _core

    return _core


def integer(name: str, value) -> int:
    """``value`` as an int (bools and floats refused), or a TypeError naming ``name``."""
    if isinstance(value, bool):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an integer, got {short(value)}") from None


def threads_of(threads) -> int:
    """The core threads of a call: ``threads`` checked (an int in [1, MAX_THREADS], and no
    more than the process can start: a ValueError saying how many it can), or for None the
    default (``OMP_NUM_THREADS`` or the cores, capped below what the process can start,
    :func:`epc_fast._core.checked_default_threads`)."""
    if threads is None:
        return compiled_core().checked_default_threads()
    count = integer("threads", threads)
    if not 1 <= count <= MAX_THREADS:
        raise ValueError(f"threads must be between 1 and {MAX_THREADS}, got {count}")
    # no more threads than this Python thread's calls have run on: the OpenMP runtime kept
    # them, no stack to map (the address-space check is about 1.5 us of every call)
    if count > 1 and count > compiled_core().started_threads():
        can = startable_threads()
        if count > can:
            raise ValueError(f"threads={count}: this process can start at most {can} threads "
                             f"({threads_limit_reason()}); pass threads={can} or fewer")
    return count


def tolerance(name: str, value) -> float:
    """1: a relative tolerance in [0, 1), or an error naming ``name``."""
    try:
        tol = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number, got {short(value)}") from None
    if not 0.0 <= tol < 1.0:
        raise ValueError(f"{name} must be in [0, 1), got {value!r}")
    return tol


def choice(name: str, value, allowed) -> str:
    """``value`` if it is one of the names ``allowed`` (a str), else a ValueError naming
    ``name``, the value and them all (an array or a list of names too)."""
    if not isinstance(value, str) or value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}; got "
                         f"{short(value)}")
    return value


def column(arr: np.ndarray, shape) -> np.ndarray:
    """A C-contiguous float64 array as the core reads a column (flat, whatever its dimensions):
    size 1 for a broadcast scalar, else every point of ``shape`` in C order. ``arr`` itself
    when it is one already: an array that broadcasts to ``shape`` with as many values has
    its points in that order."""
    if arr.flags.c_contiguous and (arr.size == 1 or arr.size == math.prod(shape)):
        return arr
    if arr.size == 1:
        return np.ascontiguousarray(arr.reshape(1))
    return np.ascontiguousarray(np.broadcast_to(arr, shape)).reshape(-1)
