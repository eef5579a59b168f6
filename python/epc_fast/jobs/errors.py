"""The errors a command raises for a user's mistake, as opposed to a fault in the package.

``epc-fast`` prints these as one line and exits with code 2 (a usage error); the others are
printed as one line with exit code 1 (``--debug`` shows their traceback).
"""

from __future__ import annotations

__all__ = ["UsageError", "ConfigError", "TooLargeError", "OutputError"]


class UsageError(ValueError):
    """A mistake in what the user asked for: a config, an option, an output directory."""


class ConfigError(UsageError):
    """A config key with a wrong type or value; the message names the command's config,
    table, key and value."""


class TooLargeError(ConfigError, MemoryError):
    """A size a config controls beyond its bound, refused before anything is allocated."""


class OutputError(UsageError):
    """An output directory or file name a command refuses to write to."""
