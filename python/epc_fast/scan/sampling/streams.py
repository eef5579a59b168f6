"""The draw contract of a scan, in NumPy: the reference that the C++ core matches bit for bit.

Every random value of a scan is a function of the seed, the parameter and the point's index
only. The generator is Philox4x32-10 (J. K. Salmon, M. A. Moraes, R. O. Dror and D. E. Shaw,
"Parallel random numbers: as easy as 1, 2, 3", SC'11, 2011), keyed by the seed
``(seed mod 2^32, seed div 2^32)``. One call serves two consecutive points: point ``i`` of
parameter stream ``s`` has the counter ``(j mod 2^32, j div 2^32, s, 0)`` with ``j = i div 2``,
``s = crc32(name)`` (zlib's CRC-32 of the parameter's name in UTF-8); an even ``i`` takes the
output words ``(x0, x1)``, an odd ``i`` the words ``(x2, x3)``. The two words give one uniform
on a grid of 2^52 values in (0, 1), never 0 or 1, and the parameter's value is the inverse of
its distribution's CDF at that uniform (:func:`transform`), with Wichura's AS 241 for the
inverse normal CDF (:func:`ndtri`).
"""

from __future__ import annotations

import math
import operator
import zlib

import numpy as np

__all__ = ["philox4x32_10", "stream_id", "uniforms", "ndtri", "normal_cdf", "transform"]

#: Philox4x32's round multipliers and key increments (the Weyl sequence's constants: the
#: golden ratio's and sqrt(3) - 1's first 32 fractional bits), as published.
PHILOX_M0 = 0xD2511F53
PHILOX_M1 = 0xCD9E8D57
PHILOX_W0 = 0x9E3779B9
PHILOX_W1 = 0xBB67AE85
PHILOX_ROUNDS = 10

_MASK32 = np.uint64(0xFFFFFFFF)
_SHIFT32 = np.uint64(32)
#: Points per piece of :func:`uniforms`' work.
_PIECE = 1 << 14


def _philox_rounds(x0, x1, x2, x3, k0: int, k1: int) -> tuple:
    """Philox4x32-10 of the counters (x0, x1, x2, x3): uint64 arrays or scalars holding 32-bit
    words, so that each 32 x 32 -> 64-bit product fits. Returns the four output words."""
    m0, m1 = np.uint64(PHILOX_M0), np.uint64(PHILOX_M1)
    for round_ in range(PHILOX_ROUNDS):
        if round_:
            # The key is bumped by the Weyl increments before rounds 2 to 10.
            k0 = (k0 + PHILOX_W0) & 0xFFFFFFFF
            k1 = (k1 + PHILOX_W1) & 0xFFFFFFFF
        product0 = m0 * x0
        product1 = m1 * x2
        # (x0, x1, x2, x3) <- (hi1 ^ x1 ^ k0, lo1, hi0 ^ x3 ^ k1, lo0)
        x0 = (product1 >> _SHIFT32) ^ x1 ^ np.uint64(k0)
        x1 = product1 & _MASK32
        x2 = (product0 >> _SHIFT32) ^ x3 ^ np.uint64(k1)
        x3 = product0 & _MASK32
    return x0, x1, x2, x3


def philox4x32_10(counter, key) -> np.ndarray:
    """Philox4x32-10 of each counter under one key.

    Parameters
    ----------
    counter : uint32 array_like, shape (..., 4); the counters' words (x0, x1, x2, x3).
    key : pair of ints in [0, 2^32), the key's words (k0, k1).

    Returns
    -------
    uint32 array, shape (..., 4): the output words of each counter.
    """
    counter = np.asarray(counter)
    if counter.shape[-1:] != (4,):
        raise ValueError(f"a Philox4x32 counter has 4 words, got shape {counter.shape}")
    if counter.dtype.kind not in "ui" or (counter.size and not (
            0 <= counter.min() and counter.max() <= 0xFFFFFFFF)):
        raise ValueError("a Philox4x32 counter's words are integers in [0, 2**32)")
    words = (counter[..., j].astype(np.uint64) for j in range(4))
    k0, k1 = (operator.index(k) for k in key)
    if not (0 <= k0 <= 0xFFFFFFFF and 0 <= k1 <= 0xFFFFFFFF):
        raise ValueError(f"a Philox4x32 key's words are in [0, 2**32), got {key!r}")
    return np.stack(_philox_rounds(*words, k0, k1), axis=-1).astype(np.uint32)


def stream_id(name: str) -> int:
    """The stream of parameter ``name``: zlib's CRC-32 of the name in UTF-8, in [0, 2^32)."""
    return zlib.crc32(name.encode("utf-8"))


def _checked_seed(seed) -> int:
    try:
        value = operator.index(seed)
    except TypeError:
        raise ValueError(f"the seed must be an integer in [0, 2**64), got {seed!r}") from None
    if not 0 <= value < 1 << 64:
        raise ValueError(f"the seed must be an integer in [0, 2**64), got {seed!r}")
    return value


def _checked_index(index) -> np.ndarray:
    """The point indices as a uint64 array, refusing any outside [0, 2^64)."""
    array = np.asarray(index)
    if array.dtype.kind == "u" or array.size == 0:
        return array.astype(np.uint64)
    if array.dtype.kind in "fO" and not isinstance(index, np.ndarray):
        # Python integers that no NumPy integer type holds together (2^64 - 1 with 0 or -1)
        # become floats or objects: each is checked as a Python integer.
        try:
            values = [operator.index(v) for v in np.asarray(index, dtype=object).flat]
        except TypeError:
            raise ValueError(f"point indices are integers, got {index!r}") from None
        if not all(0 <= v < 1 << 64 for v in values):
            raise ValueError(f"point indices are in [0, 2**64), got {min(values)} .. "
                             f"{max(values)}")
        return np.array(values, dtype=np.uint64).reshape(array.shape)
    if array.dtype.kind != "i":
        raise ValueError(f"point indices are integers, got dtype {array.dtype}")
    if array.min() < 0:
        raise ValueError(f"point indices are in [0, 2**64), got {array.min()}")
    return array.astype(np.uint64)


def uniforms(seed: int, stream: int, index) -> np.ndarray:
    """The uniforms of stream ``stream`` at points ``index``.

    Parameters
    ----------
    seed : int in [0, 2^64), the scan's seed (the Philox key).
    stream : int in [0, 2^32), the parameter's stream (:func:`stream_id` of its name).
    index : int array_like, the point indices, each in [0, 2^64).

    Returns
    -------
    float64 array of ``index``'s shape, each ``(k + 0.5) * 2^-52`` with
    ``k = xa * 2^20 + xb div 2^12`` from the output words of the counter of point ``i``'s pair
    ``i div 2``: ``(xa, xb) = (x0, x1)`` for an even ``i``, ``(x2, x3)`` for an odd one. In
    (0, 1), exact, on a grid symmetric about 1/2.
    """
    seed = _checked_seed(seed)
    stream = operator.index(stream)
    if not 0 <= stream < 1 << 32:
        raise ValueError(f"a stream is in [0, 2**32), got {stream!r}")
    index = _checked_index(index)
    shape = index.shape
    index = index.reshape(-1)
    key = (seed & 0xFFFFFFFF, seed >> 32)
    out = np.empty(index.size, dtype=np.float64)
    # Pieces of _PIECE points keep the rounds' temporaries in cache; each point's uniform
    # depends on its own counter only, so the pieces change nothing but the speed.
    for lo in range(0, index.size, _PIECE):
        i = index[lo:lo + _PIECE]
        pair = i >> np.uint64(1)
        x0, x1, x2, x3 = _philox_rounds(pair & _MASK32, pair >> _SHIFT32, np.uint64(stream),
                                        np.uint64(0), *key)
        odd = (i & np.uint64(1)).astype(bool)
        high, low = np.where(odd, x2, x0), np.where(odd, x3, x1)
        # k < 2^52, so k + 0.5 takes 53 bits: exact in float64, as is the scaling by 2^-52.
        k = (high << np.uint64(20)) | (low >> np.uint64(12))
        out[lo:lo + _PIECE] = (k.astype(np.float64) + 0.5) * 2.0**-52
    return out.reshape(shape)


# Wichura's AS 241, PPND16: M. J. Wichura, "Algorithm AS 241: The percentage points of the
# normal distribution", Applied Statistics 37(3), 477-484, 1988. Rational approximations in
# three ranges of p, each coefficient list from the constant term up.
_SPLIT1 = 0.425
_SPLIT2 = 5.0
_CONST1 = 0.180625
_CONST2 = 1.6
#: |p - 1/2| <= 0.425: the central range, in r = 0.180625 - (p - 1/2)^2.
_A = (3.3871328727963666080e0, 1.3314166789178437745e2, 1.9715909503065514427e3,
      1.3731693765509461125e4, 4.5921953931549871457e4, 6.7265770927008700853e4,
      3.3430575583588128105e4, 2.5090809287301226727e3)
_B = (1.0, 4.2313330701600911252e1, 6.8718700749205790830e2, 5.3941960214247511077e3,
      2.1213794301586595867e4, 3.9307895800092710610e4, 2.8729085735721942674e4,
      5.2264952788528545610e3)
#: r = sqrt(-log(min(p, 1 - p))) <= 5, in r - 1.6: the intermediate tails (p >= about 1.4e-11).
_C = (1.42343711074968357734e0, 4.63033784615654529590e0, 5.76949722146069140550e0,
      3.64784832476320460504e0, 1.27045825245236838258e0, 2.41780725177450611770e-1,
      2.27238449892691845833e-2, 7.74545014278341407640e-4)
_D = (1.0, 2.05319162663775882187e0, 1.67638483018380384940e0, 6.89767334985100004550e-1,
      1.48103976427480074590e-1, 1.51986665636164571966e-2, 5.47593808499534494600e-4,
      1.05075007164441684324e-9)
#: r > 5, in r - 5: the far tails.
_E = (6.65790464350110377720e0, 5.46378491116411436990e0, 1.78482653991729133580e0,
      2.96560571828504891230e-1, 2.65321895265761230930e-2, 1.24266094738807843860e-3,
      2.71155556874348757815e-5, 2.01033439929228813265e-7)
_F = (1.0, 5.99832206555887937690e-1, 1.36929880922735805310e-1, 1.48753612908506148525e-2,
      7.86869131145613259100e-4, 1.84631831751005468180e-5, 1.42151175831644588870e-7,
      2.04426310338993978564e-15)


def _horner(coefficients, x):
    result = np.full_like(x, coefficients[-1])
    for c in reversed(coefficients[:-1]):
        result = result * x + c
    return result


def ndtri(p) -> np.ndarray:
    """Phi^-1(p), the standard normal quantile: Wichura's AS 241 (PPND16), relative error about
    1e-16.

    Parameters
    ----------
    p : float array_like, probabilities in [0, 1]; 0 gives -inf, 1 gives +inf.

    Returns
    -------
    float64 array of ``p``'s shape: z with Phi(z) = p.
    """
    p = np.asarray(p, dtype=np.float64)
    q = p - 0.5
    z = np.empty_like(p)
    central = np.abs(q) <= _SPLIT1
    if central.any():
        qc = q[central]
        r = _CONST1 - qc * qc
        z[central] = qc * _horner(_A, r) / _horner(_B, r)
    tails = ~central
    if tails.any():
        qt = q[tails]
        # The smaller of p and 1 - p; 1 - p is exact for p >= 1/2 (Sterbenz).
        tail = np.where(qt < 0.0, p[tails], 1.0 - p[tails])
        with np.errstate(divide="ignore"):
            r = np.sqrt(-np.log(tail))
        near = r <= _SPLIT2
        value = np.empty_like(r)
        rn = r[near] - _CONST2
        value[near] = _horner(_C, rn) / _horner(_D, rn)
        rf = r[~near] - _SPLIT2
        with np.errstate(invalid="ignore"):
            value[~near] = _horner(_E, rf) / _horner(_F, rf)
        value[tail == 0.0] = np.inf
        z[tails] = np.where(qt < 0.0, -value, value)
    return z


def normal_cdf(z: float) -> float:
    """Phi(z) = erfc(-z / sqrt(2)) / 2, the standard normal CDF: accurate relative to itself in
    the lower tail (erfc does not round 1 - tiny)."""
    return 0.5 * math.erfc(-z / math.sqrt(2.0))


def transform(spec: dict, u) -> np.ndarray:
    """A distribution's values at uniforms ``u``: the inverse of its CDF.

    Parameters
    ----------
    spec : dict, a distribution's ``stream_spec()``: ``kind`` and the floats ``a``, ``b``,
        ``pa``, ``pb``, ``low``, ``high``, the bool ``mirror`` and ``samples`` (float64 array or
        None). By kind:

        - ``"affine"``: ``clamp(a + u b, low, high)``;
        - ``"exp_affine"``: ``clamp(exp(a + u b), low, high)``;
        - ``"normal"``: ``z = Phi^-1(pa + u (pb - pa))``, negated if ``mirror``, then
          ``clamp(a + b z, low, high)``;
        - ``"lognormal"``: as ``"normal"``, then ``clamp(exp(a + b z), low, high)``;
        - ``"empirical"``: ``samples[min(floor(u m), m - 1)]`` of the m samples.
    u : float64 array_like, uniforms in (0, 1).

    Returns
    -------
    float64 array of ``u``'s shape, in the distribution's unit.
    """
    u = np.asarray(u, dtype=np.float64)
    kind = spec["kind"]
    if kind == "empirical":
        samples = spec["samples"]
        m = samples.size
        return samples[np.minimum(np.floor(u * m).astype(np.intp), m - 1)]
    a, b = spec["a"], spec["b"]
    if kind == "affine":
        value = a + u * b
    elif kind == "exp_affine":
        value = np.exp(a + u * b)
    elif kind in ("normal", "lognormal"):
        pa, pb = spec["pa"], spec["pb"]
        z = ndtri(pa + u * (pb - pa))
        if spec["mirror"]:
            z = -z
        value = a + b * z
        if kind == "lognormal":
            value = np.exp(value)
    else:
        raise ValueError(f"unknown distribution kind {kind!r}")
    return np.clip(value, spec["low"], spec["high"])
