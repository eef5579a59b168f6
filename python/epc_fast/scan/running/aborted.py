"""The error of a scan that could not go on, as opposed to a user's mistake."""

from __future__ import annotations

__all__ = ["ScanAborted"]


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
