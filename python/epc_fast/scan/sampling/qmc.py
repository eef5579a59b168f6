"""How a scan samples its random parameters: plain Monte Carlo or scrambled Sobol' points, in
replicates that give every streamed statistic a standard error.

The NumPy statement of the contract that the C++ core (``cpp/include/epc_fast/sobol_points.h``)
matches bit for bit. With ``R`` replicates and a grid of ``G`` cells, point ``i`` lies in grid
cell ``i mod G``, replicate ``r = (i div G) mod R`` and is the ``k = i div (G R)``-th point of its
cell and replicate. Monte Carlo draws as before (:mod:`epc_fast.scan.sampling.streams`: the
replicate only groups the points). Sobol' sampling gives random parameter number ``d`` (in the order
the space lists its random parameters; a choice counts as one) the uniform
:func:`sobol_uniform` of ``k``: the ``k``-th point of dimension ``d`` of Sobol' sequence in
Gray-code order (``scipy.stats.qmc.Sobol``'s order) with the direction numbers of S. Joe and
F. Y. Kuo (2008, new-joe-kuo-6.21201), under a nested uniform scrambling of its 32 bits by
B. Burley's hash ("Practical hash-based Owen scrambling", J. Comput. Graph. Tech. 9(4), 2020)
keyed per replicate and dimension by :func:`scramble_keys`; the uniform's 20 low bits are a hash
of the scrambled point (:func:`_low_bits`): an Owen-scrambled point's digits past its 32 are
independent and uniform. So a point depends only on the seed and its index, as under Monte Carlo,
and the ``R`` replicates are independent randomisations of the same point set.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Sampling", "SAMPLINGS", "DEFAULT_REPLICATES", "direction_numbers",
           "scramble_keys", "sobol_uniform", "unscrambled_sobol"]

#: The sampling methods of a scan.
SAMPLINGS = ("monte_carlo", "sobol")
#: Replicates by default: 16 independent randomisations, whose spread gives each statistic a
#: standard error with 15 degrees of freedom.
DEFAULT_REPLICATES = 16
#: The most replicates a scan takes.
MAX_REPLICATES = 1024
#: Points of one grid cell and replicate that Sobol' sampling reaches (32-bit points).
MAX_SOBOL_INDEX = 1 << 32

_DATA = Path(__file__).resolve().parents[2] / "data" / "sobol_joe_kuo.csv"
_U32 = np.uint64(0xFFFFFFFF)


@dataclass(frozen=True)
class Sampling:
    """A scan's sampling: ``method`` ("monte_carlo" or "sobol") and ``replicates`` (>= 1).

    With one replicate a scan gives no standard error from replicates (Monte Carlo still gives
    the mean's and the fraction's from their variances).
    """

    method: str = "monte_carlo"
    replicates: int = DEFAULT_REPLICATES

    def __post_init__(self):
        if not isinstance(self.method, str) or self.method not in SAMPLINGS:
            raise ValueError(f"sampling must be one of {', '.join(map(repr, SAMPLINGS))}; "
                             f"got {self.method!r}")
        try:
            if isinstance(self.replicates, (bool, np.bool_)):  # True is no count of replicates
                raise TypeError
            replicates = operator.index(self.replicates)
        except TypeError:
            raise TypeError(f"replicates must be an integer, got {self.replicates!r}") from None
        if not 1 <= replicates <= MAX_REPLICATES:
            raise ValueError(f"replicates must be in [1, {MAX_REPLICATES}], got "
                             f"{self.replicates!r}")
        object.__setattr__(self, "replicates", replicates)

    @property
    def sobol(self) -> bool:
        return self.method == "sobol"


def _joe_kuo_rows() -> list[tuple[int, int, list[int]]]:
    rows = []
    for line in _DATA.read_text().splitlines():
        if line.startswith("#") or line.startswith("d,"):
            continue
        _, s, a, m = line.split(",")
        rows.append((int(s), int(a), [int(v) for v in m.split()]))
    return rows


_ROWS = _joe_kuo_rows()
#: The dimensions the direction numbers cover: random parameters of one space.
MAX_DIMENSIONS = len(_ROWS)


def direction_numbers(dimensions: int) -> np.ndarray:
    """uint32 (dimensions, 32): V[d, b], the b-th direction number of dimension d as a 32-bit
    fraction (bit 31 is 1/2), by Bratley and Fox's recurrence from Joe and Kuo's m_i."""
    if not 0 <= dimensions <= MAX_DIMENSIONS:
        raise ValueError(f"Sobol' sampling covers up to {MAX_DIMENSIONS} random parameters, "
                         f"got {dimensions}")
    v = np.zeros((dimensions, 32), np.uint64)
    for d in range(dimensions):
        s, a, m = _ROWS[d]
        if s == 0:  # van der Corput
            v[d] = [1 << (31 - b) for b in range(32)]
            continue
        for b in range(32):
            if b < s:
                v[d, b] = m[b] << (31 - b)
                continue
            x = int(v[d, b - s]) ^ (int(v[d, b - s]) >> s)
            for k in range(1, s):
                if (a >> (s - 1 - k)) & 1:
                    x ^= int(v[d, b - k])
            v[d, b] = x
    return v.astype(np.uint32)


def _mix64(x: int) -> int:
    """SplitMix64's finaliser (S. Vigna): a bijective mix of 64 bits."""
    x &= (1 << 64) - 1
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & ((1 << 64) - 1)
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & ((1 << 64) - 1)
    return x ^ (x >> 31)


def scramble_keys(seed: int, replicates: int, dimensions: int) -> np.ndarray:
    """uint32 (replicates, dimensions): the scrambling key of each replicate and dimension, a
    hash of the seed, the replicate and the dimension."""
    keys = np.empty((replicates, dimensions), np.uint32)
    for r in range(replicates):
        for d in range(dimensions):
            keys[r, d] = _mix64(_mix64(seed) ^ ((r << 32) | d) ^ 0x5851F42D4C957F2D) & 0xFFFFFFFF
    return keys


def _reverse_bits(x: np.ndarray) -> np.ndarray:
    """The 32 bits of each (uint64 holding a 32-bit word) in reverse order."""
    x = ((x >> np.uint64(1)) & np.uint64(0x55555555)) | ((x & np.uint64(0x55555555)) << np.uint64(1))
    x = ((x >> np.uint64(2)) & np.uint64(0x33333333)) | ((x & np.uint64(0x33333333)) << np.uint64(2))
    x = ((x >> np.uint64(4)) & np.uint64(0x0F0F0F0F)) | ((x & np.uint64(0x0F0F0F0F)) << np.uint64(4))
    x = ((x >> np.uint64(8)) & np.uint64(0x00FF00FF)) | ((x & np.uint64(0x00FF00FF)) << np.uint64(8))
    return ((x >> np.uint64(16)) | (x << np.uint64(16))) & _U32


def _times(x: np.ndarray, c: int) -> np.ndarray:
    """x c mod 2^32 for 32-bit words held in uint64 (the product's low 32 bits)."""
    return (x * np.uint64(c)) & _U32


def _owen_hash(x: np.ndarray, key: np.ndarray) -> np.ndarray:
    """Burley's hash on bit-reversed words: each bit flipped by a function of the bits below it
    (adding, and xoring with products by even constants, carry only upwards), keyed."""
    x = (x + key) & _U32
    x ^= _times(x, 0x6C50B47C)
    x ^= _times(x, 0xB82F1E52)
    x ^= _times(x, 0xC7AFE638)
    x ^= _times(x, 0x8D22F6E6)
    return x


def _low_bits(x: np.ndarray) -> np.ndarray:
    """32 bits whose high 20 are the uniform's low bits: the product of the keyed, scrambled
    point by the golden ratio's 32 bits (their high bits mix all of the point's)."""
    return _times(x, 0x9E3779B9)


def unscrambled_sobol(directions: np.ndarray, k) -> np.ndarray:
    """uint64 words of 32 bits: the k-th point of Sobol' sequence in Gray-code order, in the
    dimension of ``directions`` (uint32 (32,)); k is taken mod 2^32 (a scan refuses more
    points than that per replicate and cell)."""
    k = np.asarray(k, dtype=np.uint64) & _U32  # 32-bit points: k mod 2^32
    gray = k ^ (k >> np.uint64(1))
    x = np.zeros(k.shape, np.uint64)
    for b in range(32):
        x ^= np.where((gray >> np.uint64(b)) & np.uint64(1) != 0, np.uint64(directions[b]),
                      np.uint64(0))
    return x


def sobol_uniform(directions: np.ndarray, key, k) -> np.ndarray:
    """float64: the uniform in (0, 1) of Sobol' point ``k`` (an int array) of the dimension of
    ``directions`` under the scrambling ``key`` (uint32, one or one per point): the scrambled
    point's 32 bits over 20 hashed ones, (K + 1/2) 2^-52 as the Monte Carlo uniforms are."""
    key = np.asarray(key, dtype=np.uint64)
    x = _reverse_bits(_owen_hash(_reverse_bits(unscrambled_sobol(directions, k)), key))
    low = _low_bits(x ^ key)
    bits = (x << np.uint64(20)) | (low >> np.uint64(12))
    return (bits.astype(np.float64) + 0.5) * 2.0 ** -52


def positions(index: np.ndarray, grid_size: int, replicates: int) -> tuple[np.ndarray, np.ndarray]:
    """(k, r): each point's index within its grid cell and replicate, and its replicate."""
    index = np.asarray(index, dtype=np.int64)
    return index // (grid_size * replicates), (index // grid_size) % replicates


def check_points(points: int, grid_size: int, sampling: Sampling, *, cap: bool = False) -> None:
    """A ValueError unless a scan of ``points`` points can be sampled so: at least one point per
    replicate (and grid cell), and for Sobol' sampling a power of two of points per cell and
    replicate (its balance holds at powers of two) below 2^32. ``cap``: the points are a
    stopping rule's cap, reached in powers of two, so any count above one round is taken."""
    unit = grid_size * sampling.replicates
    if points < sampling.replicates:
        raise ValueError(f"replicates ({sampling.replicates}) must not exceed the points "
                         f"({points})")
    if not sampling.sobol:
        return
    per = points // unit
    if per > MAX_SOBOL_INDEX:
        raise ValueError(f"Sobol' sampling takes at most 2^32 points per replicate and grid "
                         f"cell: at most {unit * MAX_SOBOL_INDEX} points here, got {points}")
    if cap:
        return
    if points % unit or per & (per - 1):
        low = unit << max(0, per.bit_length() - 1)
        raise ValueError(f"sampling='sobol' takes points = 2^m x replicates x grid cells "
                         f"({sampling.replicates} x {grid_size}): got {points}; "
                         f"{low} or {2 * low} would do")
