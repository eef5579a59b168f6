"""An empirical distribution's sample file, named by a scan config: one number a line."""

from __future__ import annotations

import math
from pathlib import Path

from ...jobs.document import read_text
from ...jobs.errors import ConfigError, TooLargeError
from ...jobs.schema import MAX_LIST, short, where_prefix
from .bounds import MAX_SAMPLE_FILE_BYTES

__all__ = ["read_samples"]


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
