"""Files a scan config reads: the config itself and empirical sample files.

Both are read only when they are regular files within a size bound (``/dev/zero`` or a FIFO
would never end), as UTF-8; a mistake raises a ConfigError naming the file.
"""

from __future__ import annotations

import math
import os
import stat
from pathlib import Path

from ..errors import ConfigError, TooLargeError
from ..schema import MAX_LIST, MAX_SAMPLE_FILE_BYTES, short, where_prefix

__all__ = ["read_text", "read_samples"]


def read_text(path: Path, max_bytes: int, where: str | None = None) -> str:
    """The UTF-8 text of the regular file ``path`` of at most ``max_bytes`` bytes."""
    prefix = f"{where_prefix(where)}: " if where else "scan config: "
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


def read_samples(where: str, name, base: Path) -> tuple:
    """The finite numbers of a sample file, one a line (blank lines and ``#`` comments
    skipped), at most :data:`MAX_LIST` of them."""
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{where_prefix(where)}: file = {short(name)}: expected a file name")
    path = base / name
    text = read_text(path, MAX_SAMPLE_FILE_BYTES, where)
    samples = []
    for number, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        try:
            value = float(line)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise ConfigError(f"{where_prefix(where)}: file {str(path)!r} line {number}: "
                              f"{short(line)}: expected one finite number a line")
        if len(samples) == MAX_LIST:
            raise TooLargeError(f"{where_prefix(where)}: file {str(path)!r} holds more than "
                                f"{MAX_LIST:,} samples")
        samples.append(value)
    if not samples:
        raise ConfigError(f"{where_prefix(where)}: file {str(path)!r} holds no sample")
    return tuple(samples)
