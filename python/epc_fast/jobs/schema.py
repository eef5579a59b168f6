"""Typed checks of a command's config values, each message naming the command's config.

Each check takes ``where`` (the TOML table, e.g. ``reductions.best``), the key and the value,
and returns the value in its Python type or raises :class:`~epc_fast.jobs.errors.ConfigError`
with one line naming the config (``simulate config [simulate]``), the key and the value and
what was expected. A command's parser reads its config inside :func:`config_of` (its name);
every check and every message of a shared parser (a scan space's, read by ``scan``,
``optimize`` and ``simulate`` alike) names that command's config. Types are strict: a string is
never a boolean or a list, a float with a fraction is never an integer, NaN and infinities are
never numbers. A float that is a whole number is an integer (TOML writes large counts as
``1e6``).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import re

from .._validation import short
from .errors import ConfigError, TooLargeError

__all__ = ["MAX_LIST", "config_of", "config_prefix", "where_prefix", "short", "integer",
           "number", "boolean", "string", "choice", "number_list", "table_of", "take", "wrapped",
           "file_name", "check_size"]

#: Values in one list (grid, choice, weights, edges, samples, q).
MAX_LIST = 1_000_000

#: The command whose config is being read ("scan", "optimize", ...); None: a config alone.
_COMMAND = contextvars.ContextVar("command", default=None)

#: A name that becomes a file name: a letter or digit, then letters, digits, _ - and dots.
_FILE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")


@contextlib.contextmanager
def config_of(command: str):
    """Within the block, a config's messages name ``command``'s config (``"optimize"``:
    ``optimize config [optimize]: ...``)."""
    token = _COMMAND.set(command)
    try:
        yield
    finally:
        _COMMAND.reset(token)


def config_prefix() -> str:
    """How a message names the config being read: ``"scan config"``, or ``"config"`` outside
    :func:`config_of`."""
    command = _COMMAND.get()
    return "config" if command is None else f"{command} config"


def where_prefix(where: str) -> str:
    """How a message names table ``where`` of the config being read: ``"scan config [scan]"``."""
    return f"{config_prefix()} [{where}]"


def _fail(where: str, key: str, value, expected: str, cls=ConfigError):
    raise cls(f"{where_prefix(where)}: {key} = {short(value)}: expected {expected}")


def integer(where: str, key: str, value, low: int, high: int | None = None,
            size: bool = False) -> int:
    """An int in [low, high]: a TOML integer, or a float that is a whole number. A ``size``
    above ``high`` raises :class:`TooLargeError` (a MemoryError too)."""
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        value = int(value)
    span = f">= {low:,}" if high is None else f"between {low:,} and {high:,}"
    if isinstance(value, bool) or not isinstance(value, int):
        _fail(where, key, value, f"an integer {span}")
    if value < low:
        _fail(where, key, value, f"an integer {span}")
    if high is not None and value > high:
        _fail(where, key, value, f"an integer {span}", TooLargeError if size else ConfigError)
    return value


def number(where: str, key: str, value, low: float | None = None, high: float | None = None,
           low_open: bool = False, high_open: bool = False) -> float:
    """A finite float, optionally in [low, high] (``low_open``: above ``low``; ``high_open``:
    below ``high``)."""
    expected = "a finite number" + _range_text(low, high, low_open, high_open)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        _fail(where, key, value, expected)
    value = float(value)
    if ((low is not None and (value <= low if low_open else value < low))
            or (high is not None and (value >= high if high_open else value > high))):
        _fail(where, key, value, expected)
    return value


def _range_text(low, high, low_open, high_open=False) -> str:
    if low is None and high is None:
        return ""
    if high is None:
        return f" {'>' if low_open else '>='} {low:g}"
    if low is None:
        return f" {'<' if high_open else '<='} {high:g}"
    return f" in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"


def boolean(where: str, key: str, value) -> bool:
    """A TOML boolean: ``true`` or ``false`` (never a string such as ``"false"``)."""
    if not isinstance(value, bool):
        _fail(where, key, value, "true or false (a TOML boolean, without quotes)")
    return value


def string(where: str, key: str, value) -> str:
    if not isinstance(value, str):
        _fail(where, key, value, "a string")
    return value


def choice(where: str, key: str, value, allowed) -> str:
    if not isinstance(value, str) or value not in allowed:
        _fail(where, key, value, "one of " + ", ".join(f'"{a}"' for a in allowed))
    return value


def number_list(where: str, key: str, value, low: float | None = None,
                high: float | None = None, min_length: int = 1) -> tuple:
    """A list of finite numbers (at least ``min_length``, at most :data:`MAX_LIST`)."""
    if not isinstance(value, list):
        _fail(where, key, value, "a list of finite numbers, e.g. [1, 2]")
    if not min_length <= len(value) <= MAX_LIST:
        _fail(where, key, value, f"a list of {min_length:,} to {MAX_LIST:,} numbers",
              TooLargeError if len(value) > MAX_LIST else ConfigError)
    for item in value:
        if (isinstance(item, bool) or not isinstance(item, (int, float))
                or not math.isfinite(item) or (low is not None and item < low)
                or (high is not None and item > high)):
            _fail(where, key, value, "a list of finite numbers" + _range_text(low, high, False)
                  + f" (holds {short(item)})")
    return tuple(value)


def table_of(where: str, value) -> dict:
    """``value`` as the TOML table ``[where]`` (a string or a number there is refused)."""
    if not isinstance(value, dict):
        raise ConfigError(f"{where_prefix(where)}: {short(value)}: expected a table, e.g. "
                          "{ key = value } or a [section]")
    return value


def take(table: dict, where: str, required=(), optional=()) -> dict:
    """``table``, refusing unknown or missing keys with a message naming ``where``."""
    unknown = sorted(set(table) - set(required) - set(optional))
    if unknown:
        raise ConfigError(f"{where_prefix(where)}: unknown key(s) {', '.join(unknown)}; known: "
                          f"{', '.join(tuple(required) + tuple(optional))}")
    missing = [k for k in required if k not in table]
    if missing:
        raise ConfigError(f"{where_prefix(where)}: missing {', '.join(missing)}")
    return table


def wrapped(where: str, build):
    """``build()``, its ValueError or TypeError re-raised as a ConfigError naming ``where``
    (for checks the scan's classes make themselves, e.g. a distribution's low < high)."""
    try:
        return build()
    except ConfigError:
        raise
    except (ValueError, TypeError) as error:
        raise ConfigError(f"{where_prefix(where)}: {error}") from None


def file_name(where: str, key: str, value) -> str:
    """A name that becomes a file or directory inside the output directory: a letter or digit,
    then up to 99 letters, digits, ``_``, ``-`` or ``.`` (no path separator, never ``..``)."""
    if not isinstance(value, str) or not _FILE_NAME.fullmatch(value) or ".." in value:
        _fail(where, key, value, "a name of letters, digits, _ - and . (it names a file in "
                                 "--out; no / or ..)")
    return value


def check_size(where: str, what: str, count: int, bound: int, bytes_each: int) -> None:
    """Refuse ``count`` things of ``bytes_each`` bytes beyond ``bound``, before allocating."""
    if count > bound:
        raise TooLargeError(
            f"{where_prefix(where)}: {what} of {count:,} would need ~{_bytes(count * bytes_each)}"
            f" of memory; at most {bound:,} ({_bytes(bound * bytes_each)})")


def _bytes(count: float) -> str:
    for unit in ("bytes", "KB", "MB", "GB", "TB", "PB"):
        if count < 1000:
            return f"{count:.3g} {unit}"
        count /= 1000
    return f"{count:.3g} EB"
