"""The errors a scan raises for a user's mistake, as opposed to a fault in the package.

``epc-fast scan`` prints these as one line and exits with code 2 (a usage error); the others
are printed as one line with exit code 1 (``--debug`` shows their traceback).
"""

from __future__ import annotations

__all__ = ["UsageError", "ConfigError", "TooLargeError", "OutputError", "ScanAborted"]


class UsageError(ValueError):
    """A mistake in what the user asked for: a config, an option, an output directory."""


class ConfigError(UsageError):
    """A scan config key with a wrong type or value; the message names table, key and value."""


class TooLargeError(ConfigError, MemoryError):
    """A size a config controls beyond its bound, refused before anything is allocated."""


class OutputError(UsageError):
    """An output directory or file name the scan refuses to write to."""


class ScanAborted(RuntimeError):
    """A scan that could not go on (e.g. its Dask cluster lost every worker).

    Attributes
    ----------
    result : ScanResult or None, the prefix of points merged before the failure, marked
        ``partial``, when the scan got as far as building it.
    """

    def __init__(self, message: str):
        super().__init__(message)
        self.result = None
