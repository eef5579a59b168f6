"""Elementary functions that give the same bits on every CPU.

NumPy dispatches ``power``, ``exp``, ``arctan`` and their kin to different SIMD code on CPUs
with and without AVX-512, and the two differ in the last bits. The functions here use only
NumPy's additions, multiplications, divisions, square roots, ``floor`` and ``ldexp``, which are
correctly rounded (or exact) on every CPU, so what is computed from them (the random designs of
the accuracy tables, the image corner's field angle) is the same on any x86-64 machine.
They are a few ulp from the exact values (tests/test_portable_math.py holds them to mpmath).
"""

from __future__ import annotations

import numpy as np

__all__ = ["exp10", "arctan_deg"]

#: log2(10), ln(2) and pi/2, rounded to float64.
_LOG2_10 = 3.321928094887362
_LN2 = 0.6931471805599453
_HALF_PI = 1.5707963267948966
#: Terms of exp(t)'s Taylor series for t in [0, ln 2): the 19th is below 2**-60 of the sum.
_EXP_TERMS = 19
#: Terms of atan(a)'s series for |a| <= tan(pi/16) (a^2 <= 0.0396): the 13th is below 2**-60 of a.
_ATAN_TERMS = 13


def exp10(u) -> np.ndarray:
    """10**u, within 2e-15 relative for 0 <= u <= 5 and 1e-13 for abs(u) <= 300 (the rounding of
    u·log2(10) grows with u); 10**inf = inf, 10**-inf = 0, NaN stays NaN."""
    x = np.asarray(u, dtype=np.float64) * _LOG2_10
    # beyond ±1e4 every result is 0 or inf (float64's range ends near 2**±1075)
    z = np.clip(np.nan_to_num(x), -1e4, 1e4)
    n = np.floor(z)
    t = (z - n) * _LN2  # z - floor(z) is exact
    power = np.ones_like(t)
    for k in range(_EXP_TERMS, 0, -1):  # Horner: 1 + t/1 (1 + t/2 (1 + ...))
        power = 1.0 + power * t / k
    with np.errstate(over="ignore"):
        return np.where(np.isnan(x), np.nan, np.ldexp(power, n.astype(np.int64)))


def arctan_deg(x) -> np.ndarray:
    """degree: atan(x), within a few ulp; atan(±inf) = ±90, NaN stays NaN."""
    x = np.asarray(x, dtype=np.float64)
    a = np.abs(x)
    with np.errstate(divide="ignore"):
        inverted = a > 1.0
        a = np.where(inverted, 1.0 / a, a)  # atan(a) = pi/2 - atan(1/a)
    for _ in range(2):  # atan(a) = 2 atan(a / (1 + sqrt(1 + a^2))): |a| <= tan(pi/16) after two
        a = a / (1.0 + np.sqrt(1.0 + a * a))
    a2 = a * a
    series = np.zeros_like(a)
    for k in range(_ATAN_TERMS - 1, -1, -1):  # sum of (-1)^k a^(2k) / (2k + 1), Horner in a^2
        series = 1.0 / (2 * k + 1) - a2 * series
    angle = 4.0 * a * series
    angle = np.where(inverted, _HALF_PI - angle, angle)
    return np.copysign(np.degrees(angle), x)
