"""A command's config file as a TOML document.

A file is read only when it is a regular file within a size bound (``/dev/zero`` or a FIFO
would never end), as UTF-8, and its text parsed as TOML; a mistake raises a ConfigError naming
the command's config (:func:`~epc_fast.jobs.schema.config_of`) and the file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .errors import ConfigError, TooLargeError
from .schema import config_prefix, where_prefix

__all__ = ["MAX_CONFIG_BYTES", "read_text", "toml_document"]

#: Bytes of a config file.
MAX_CONFIG_BYTES = 16 * 2**20


def read_text(path: Path, max_bytes: int, where: str | None = None) -> str:
    """The UTF-8 text of the regular file ``path`` of at most ``max_bytes`` bytes."""
    prefix = f"{where_prefix(where)}: " if where else f"{config_prefix()}: "
    try:
        info = os.stat(path)
    except OSError as error:
        raise ConfigError(f"{prefix}cannot read {str(path)!r}: {error.strerror}") from None
    if not stat.S_ISREG(info.st_mode):
        raise ConfigError(f"{prefix}{str(path)!r} is not a regular file")
    if info.st_size > max_bytes:
        raise TooLargeError(f"{prefix}{str(path)!r} holds {info.st_size:,} bytes; at most "
                            f"{max_bytes:,} are read")
    try:
        with open(path, "rb") as handle:
            data = handle.read(max_bytes + 1)
    except OSError as error:
        raise ConfigError(f"{prefix}cannot read {str(path)!r}: {error.strerror}") from None
    if len(data) > max_bytes:
        raise TooLargeError(f"{prefix}{str(path)!r} holds more than {max_bytes:,} bytes")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ConfigError(f"{prefix}{str(path)!r} is not UTF-8 text (byte {error.start})"
                          ) from None


def _toml():
    try:
        import tomllib
    except ModuleNotFoundError:  # Python < 3.11
        try:
            import tomli as tomllib
        except ModuleNotFoundError:
            raise ImportError("reading configs on Python < 3.11 needs tomli: "
                              "pip install tomli") from None
    return tomllib


def toml_document(text: str, source: str) -> dict:
    """The TOML document of a config's ``text``; a ConfigError naming ``source`` when it is
    not TOML."""
    try:
        return _toml().loads(text)
    except _toml().TOMLDecodeError as error:
        raise ConfigError(f"{config_prefix()} {source}: not valid TOML: {error}") from None
