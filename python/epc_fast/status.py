"""Per-point status codes (docs/model.md, "Per-point status") and the cause of an unreachable
SNR target.

The integer values are part of the binary contract with the C++ core
(``cpp/include/epc_fast/status.h``): keep the two in step.
"""

from __future__ import annotations

import enum

__all__ = ["Status", "Cause"]


class Status(enum.IntEnum):
    """What happened at one design point."""

    OK = 0
    """Every output is finite and meaningful."""
    INVALID = 1
    """An input is NaN, infinite where it must be finite, or outside its domain: all outputs NaN."""
    UNREACHABLE = 2
    """The SNR target cannot be met (see :class:`Cause`): T_MPE = +inf, blur, f50 and EPC NaN."""
    BLUR_UNBOUNDED = 3
    """The shake angle during T_MPE reaches pi/2: blur = +inf, f50 = 0, EPC = 0."""
    BEYOND_TABLE = 4
    """f50 lies past the last frequency of a tabulated MTF: f50 and EPC NaN; T_MPE, blur and
    the electron counts finite."""
    EXPOSURE_LIMIT = 5
    """One frame, T_MPE / frames, would be longer than ``max_exposure_s``, the longest the
    camera takes (docs/model.md, "Exposure limits and night mode"): T_MPE and the electron
    counts finite (what the target would need); blur, f50, EPC, the shares and the elasticities
    NaN. Only ``evaluate``'s Python layer gives it: the core never does."""


class Cause(enum.IntEnum):
    """Why a point is :attr:`Status.UNREACHABLE` (``NONE`` for every other status)."""

    NONE = 0
    NO_LIGHT = 1
    """The electron rate is zero: no light, zero reflectance or transmittance, or a rate below
    the smallest normal double (2.2e-308 e-/s, flushed to 0); also a T_MPE beyond the largest
    double (1.8e308 s)."""
    PRNU = 2
    """PRNU caps the SNR: prnu * 10**(snr_db/20) >= 1."""
    FULL_WELL = 3
    """The photo-electrons needed exceed the full well: rate * T_MPE > full_well_e."""
