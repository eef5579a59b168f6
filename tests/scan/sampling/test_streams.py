"""The draw contract's NumPy reference: Philox4x32-10, the uniforms, Phi^-1 and the transforms."""

import math
import re
import zlib

from mpmath import mp
import numpy as np
import pytest
from scipy import stats

from epc_fast.scan import Normal, Truncated
from epc_fast.scan.sampling import streams

#: The smallest and largest uniforms: k = 0 and k = 2^52 - 1.
U_MIN = 2.0**-53
U_MAX = 1.0 - 2.0**-53


def _mp_ndtri(p):
    """Phi^-1(p) at the working precision of mpmath: Newton's method on Phi(z) = p from the
    float64 estimate, in the lower tail's terms above 1/2 (Phi^-1(p) = -Phi^-1(1 - p), 1 - p
    exact at this precision)."""
    p = mp.mpf(p)
    if p > 0.5:
        return -_mp_ndtri(1 - p)
    z = mp.mpf(float(streams.ndtri(float(p))))
    for _ in range(20):
        step = (mp.ncdf(z) - p) / mp.npdf(z)
        z -= step
        if abs(step) <= abs(z) * mp.mpf(2) ** (-mp.prec + 8):
            return z
    raise AssertionError(f"Newton's method did not converge at p = {p}")


# Random123's known-answer vectors (kat_vectors, philox4x32 with 10 rounds): counter, key,
# output, in hex.
KAT = [
    ((0x00000000, 0x00000000, 0x00000000, 0x00000000), (0x00000000, 0x00000000),
     (0x6627e8d5, 0xe169c58d, 0xbc57ac4c, 0x9b00dbd8)),
    ((0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff), (0xffffffff, 0xffffffff),
     (0x408f276d, 0x41c83b0e, 0xa20bc7c6, 0x6d5451fd)),
    ((0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344), (0xa4093822, 0x299f31d0),
     (0xd16cfe09, 0x94fdcceb, 0x5001e420, 0x24126ea1)),
]


@pytest.mark.parametrize("counter, key, expected", KAT)
def test_philox_passes_the_random123_known_answers(counter, key, expected):
    out = streams.philox4x32_10(np.array(counter, dtype=np.uint32), key)
    assert out.dtype == np.uint32
    assert tuple(int(w) for w in out) == expected


def test_philox_is_vectorised_over_leading_axes():
    counters = np.array([c for c, _, _ in KAT], dtype=np.uint32)
    key = (0xa4093822, 0x299f31d0)
    rows = np.array([streams.philox4x32_10(c, key) for c in counters])
    assert np.array_equal(streams.philox4x32_10(counters, key), rows)
    grid = np.stack([counters, counters[::-1]])
    assert np.array_equal(streams.philox4x32_10(grid, key), np.stack([rows, rows[::-1]]))


def test_a_stream_is_the_crc32_of_the_name_in_utf8():
    # "123456789" is CRC-32's published check input, 0xCBF43926 its check value.
    assert streams.stream_id("123456789") == 0xCBF43926
    assert streams.stream_id("") == 0
    assert streams.stream_id("design") == zlib.crc32(b"design")
    assert streams.stream_id("µ") == zlib.crc32("µ".encode("utf-8"))


def _uniform_of_words(high, low):
    """The contract's uniform of two Philox output words, with Python integers."""
    k = high * 2**20 + low // 2**12
    assert 0 <= k < 2**52
    return (k + 0.5) * 2.0**-52


def _hand_uniform(seed, stream, i):
    """The contract's uniform, spelled with Python integers from the Philox output words of the
    counter of i's pair i div 2: (x0, x1) for an even i, (x2, x3) for an odd one."""
    j = i // 2
    counter = np.array([j % 2**32, j // 2**32, stream, 0], dtype=np.uint32)
    x0, x1, x2, x3 = (int(w) for w in streams.philox4x32_10(counter, (seed % 2**32, seed // 2**32)))
    return _uniform_of_words(x2, x3) if i % 2 else _uniform_of_words(x0, x1)


def test_a_uniform_is_k_plus_a_half_over_2_to_the_52_from_two_words_of_its_pairs_call():
    # Seed 0, stream 0 (the empty name), points 0 and 1: both from counter (0, 0, 0, 0),
    # Random123's first known answer, point 0 from its first two words and point 1 from its
    # last two.
    even = (0x6627e8d5 * 2**20 + 0xe169c58d // 2**12 + 0.5) / 2**52
    odd = (0xbc57ac4c * 2**20 + 0x9b00dbd8 // 2**12 + 0.5) / 2**52
    assert streams.uniforms(0, 0, [0, 1]).tolist() == [even, odd]
    seed = 0x0123456789ABCDEF
    stream = streams.stream_id("illuminance_lux")
    index = np.array([0, 1, 2, 3, 2**32 - 1, 2**32, 2**32 + 5, 2**33 - 1, 2**33, 2**63 + 7,
                      2**64 - 2, 2**64 - 1], dtype=np.uint64)
    expected = [_hand_uniform(seed, stream, int(i)) for i in index]
    assert streams.uniforms(seed, stream, index).tolist() == expected
    assert streams.uniforms(2**64 - 1, 2**32 - 1, [3])[0] == _hand_uniform(2**64 - 1,
                                                                          2**32 - 1, 3)


# (seed, stream, pair j): the pair's points are 2j and 2j + 1; j = 2^31 - 1, 2^31 put the pair
# on either side of point 2^32, j = 2^32 - 1, 2^32 on either side of the counter's second word
# (point 2^33), j = 2^63 - 1 is the last pair (points 2^64 - 2 and 2^64 - 1).
PAIRS = [(0, 0, 0), (2009, streams.stream_id("shake_deg_per_s"), 1),
         (2**32 + 5, streams.stream_id("design"), 2**31 - 1), (7, 0xFFFFFFFF, 2**31),
         (2**64 - 1, streams.stream_id("illuminance_lux"), 2**32 - 1), (1, 2, 2**32),
         (0x0123456789ABCDEF, 12345, 2**63 - 1)]


@pytest.mark.parametrize("seed, stream, j", PAIRS)
def test_one_philox_call_gives_the_uniforms_of_a_pair_of_points(seed, stream, j):
    counter = np.array([j % 2**32, j // 2**32, stream, 0], dtype=np.uint32)
    x0, x1, x2, x3 = (int(w) for w in streams.philox4x32_10(counter, (seed % 2**32, seed // 2**32)))
    index = np.array([2 * j, 2 * j + 1], dtype=np.uint64)
    assert streams.uniforms(seed, stream, index).tolist() == [_uniform_of_words(x0, x1),
                                                             _uniform_of_words(x2, x3)]
    # each point alone, and in the other order: a uniform depends on its own index only
    assert streams.uniforms(seed, stream, index[::-1]).tolist() == [_uniform_of_words(x2, x3),
                                                                    _uniform_of_words(x0, x1)]
    assert streams.uniforms(seed, stream, index[1:])[0] == _uniform_of_words(x2, x3)


def test_uniforms_are_on_the_half_integer_grid_strictly_inside_0_1():
    u = streams.uniforms(7, streams.stream_id("x"), np.arange(10**6))
    assert u.dtype == np.float64 and u.min() > 0.0 and u.max() < 1.0
    k = u * 2.0**52 - 0.5
    assert np.array_equal(k, np.floor(k))
    # The grid is symmetric: 1 - u is exact and on it.
    assert np.array_equal((1.0 - u) * 2.0**52 - 0.5, np.floor((1.0 - u) * 2.0**52 - 0.5))


def test_uniforms_depend_only_on_seed_stream_and_index():
    seed, stream = 2**40 + 3, streams.stream_id("shake_deg_per_s")
    index = np.arange(2**32 - 70_000, 2**32 + 70_000, dtype=np.int64)
    whole = streams.uniforms(seed, stream, index)
    cuts = [0, 1, 17, 16_384, 16_385, 65_536, 100_003, index.size]
    pieces = [streams.uniforms(seed, stream, index[a:b]) for a, b in zip(cuts, cuts[1:])]
    assert np.array_equal(np.concatenate(pieces), whole)
    order = np.random.default_rng(0).permutation(index.size)
    assert np.array_equal(streams.uniforms(seed, stream, index[order]), whole[order])
    assert np.array_equal(streams.uniforms(seed, stream, index.reshape(400, 350)),
                          whole.reshape(400, 350))
    assert np.array_equal(streams.uniforms(seed, stream, index.astype(np.uint64)), whole)
    # Another seed or stream gives other uniforms: equal ones at a point are a chance of 2^-52,
    # 3e-11 over these 140 000 points.
    assert not np.any(streams.uniforms(seed + 1, stream, index) == whole)
    assert not np.any(streams.uniforms(seed, stream + 1, index) == whole)


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, "1"])
def test_a_seed_outside_0_2_to_the_64_is_refused_by_name(seed):
    with pytest.raises(ValueError, match=re.escape(f"got {seed!r}")):
        streams.uniforms(seed, 0, [0])


def test_negative_point_indices_are_refused():
    with pytest.raises(ValueError, match="point indices"):
        streams.uniforms(0, 0, [3, -1])


NDTRI_POINTS = [2.0**-52, 2.0**-53, 2.0**-1074, 1e-300, 1e-200, 1e-100, 1e-20, 1e-10,
                math.exp(-25.0), 0.075, 0.0750001, 0.25, 0.5 - 2.0**-54, 0.5 + 2.0**-53,
                0.5 - 1e-10, 0.5 + 1e-10, 0.6, 0.924999, 0.925, 0.999, 1.0 - 1e-10,
                1.0 - 1e-15, 1.0 - 2.0**-53]


def test_ndtri_matches_mpmath_to_1e_15_relative_from_1e_300_to_1_minus_1e_16():
    p = np.concatenate([NDTRI_POINTS, np.logspace(-300, -0.302, 600),
                        1.0 - np.logspace(-16, -0.302, 200), np.linspace(0.01, 0.99, 198)])
    z = streams.ndtri(p)
    with mp.workdps(40):
        exact = [_mp_ndtri(float(x)) for x in p]
        error = np.array([float(abs((zi - e) / e)) for zi, e in zip(z, exact)])
    # AS 241's rational functions are accurate to about 1e-16 (Wichura 1988); evaluated in
    # float64 they add a few roundings: 1e-15 relative bounds both.
    assert error.max() <= 1e-15, (error.max(), p[error.argmax()])


def test_ndtri_is_exact_at_the_ends_and_the_middle_and_antisymmetric_on_the_uniform_grid():
    assert streams.ndtri(0.5) == 0.0
    assert streams.ndtri(0.0) == -math.inf and streams.ndtri(1.0) == math.inf
    # The uniforms, their ends and the grid's neighbours of AS 241's split at p = 0.075.
    split = (math.floor(0.075 * 2**52) + np.array([-1.5, -0.5, 0.5, 1.5])) * 2.0**-52
    u = np.concatenate([streams.uniforms(3, 0, np.arange(100_000)), [U_MIN, U_MAX], split])
    # p - 1/2 and 1 - p are exact on the uniforms' grid, so Phi^-1(1 - u) is exactly
    # -Phi^-1(u).
    assert np.array_equal(streams.ndtri(1.0 - u), -streams.ndtri(u))
    assert streams.ndtri(np.array([[0.5, 0.5]])).shape == (1, 2)


@pytest.mark.parametrize("z", [-37.5, -30.0, -10.0, -5.0, -1.0, 0.0, 0.3, 2.0, 8.0])
def test_normal_cdf_is_accurate_in_the_lower_tail(z):
    with mp.workdps(40):
        exact = float(mp.ncdf(z))
    # Phi's relative condition number in the lower tail is about z^2 (z phi(z) / Phi(z)) and
    # z / sqrt(2) is rounded once; erfc adds a few ulp: (z^2 + 4) ulp bounds the sum.
    assert streams.normal_cdf(z) == pytest.approx(exact, rel=(z * z + 4.0) * 2.0**-52, abs=0.0)


def _truncated_normal_spec(mean, std, z_low, z_high):
    """The contract's truncated normal, written from its table: mirrored when z_low >= 0."""
    if z_low >= 0.0:
        pa, pb, mirror = streams.normal_cdf(-z_high), streams.normal_cdf(-z_low), True
    else:
        pa, pb, mirror = streams.normal_cdf(z_low), streams.normal_cdf(z_high), False
    return {"kind": "normal", "a": mean, "b": std, "pa": pa, "pb": pb, "mirror": mirror,
            "low": mean + std * z_low, "high": mean + std * z_high, "samples": None}


def _mp_truncated_quantile(mean, std, z_low, z_high, u):
    """The truncated normal's quantile at u, at the working precision of mpmath."""
    u = mp.mpf(u)
    lo, hi = mp.ncdf(z_low), mp.ncdf(z_high)
    if z_low >= 0:
        # Phi(-z) in the upper half is 1 - Phi(z) computed without cancellation.
        lo, hi = mp.ncdf(-z_high), mp.ncdf(-z_low)
        return mean - std * _mp_ndtri(lo + u * (hi - lo))
    return mean + std * _mp_ndtri(lo + u * (hi - lo))


@pytest.mark.parametrize("z_low, z_high", [(5.0, 6.0), (-6.0, -5.0), (8.0, 9.0), (-1.0, 2.0)])
def test_a_tail_truncated_normal_stays_inside_and_matches_mpmath(z_low, z_high):
    mean, std = 20.0, 2.0
    spec = _truncated_normal_spec(mean, std, z_low, z_high)
    u = np.array([U_MIN, 2.0**-40, 1e-6, 0.25, 0.5, 0.75, 1.0 - 1e-6, 1.0 - 2.0**-40, U_MAX])
    values = streams.transform(spec, u)
    assert np.all((values >= spec["low"]) & (values <= spec["high"]))
    # Distinct values, increasing in u, or decreasing where the contract mirrors the quantile.
    assert np.all(np.diff(values) < 0.0 if spec["mirror"] else np.diff(values) > 0.0)
    with mp.workdps(40):
        exact = [_mp_truncated_quantile(mean, std, z_low, z_high, x) for x in u]
        error = np.array([float(abs((v - e) / e)) for v, e in zip(values, exact)])
    # pa and pb carry erfc's few ulp, Phi^-1 1e-16, and the quantile's condition number in p
    # is below 1 at z > 1: 1e-13 relative is a margin of 100 over the sum.
    assert error.max() <= 1e-13, error


@pytest.mark.parametrize("z_low, z_high", [(5.0, 6.0), (-6.0, -5.0)])
def test_a_far_tail_truncated_normal_draws_its_distribution(z_low, z_high):
    spec = _truncated_normal_spec(0.0, 1.0, z_low, z_high)
    draws = streams.transform(spec, streams.uniforms(11, streams.stream_id("z"),
                                                     np.arange(10**6)))
    # A transform that loses precision (p = 1 - tiny, rounded) repeats values; these 10^6
    # draws repeat only where two round to the same float64, about 1e-3 pairs expected.
    assert np.unique(draws).size == draws.size
    expected = stats.truncnorm(z_low, z_high)
    # p > 1e-4: a correct transform fails 1 time in 10^4.
    assert stats.kstest(draws, expected.cdf).pvalue > 1e-4
    mean, var, kurtosis = (float(x) for x in expected.stats(moments="mvk"))
    # Five standard errors of the mean and of the variance (whose variance is
    # (mu4 - var^2) / n): a false alarm about 1 time in 10^6 each.
    mu4 = (kurtosis + 3.0) * var**2
    assert abs(draws.mean() - mean) <= 5.0 * math.sqrt(var / draws.size)
    assert abs(draws.var() - var) <= 5.0 * math.sqrt((mu4 - var**2) / draws.size)


def test_truncated_builds_the_contract_spec_mirrored_in_the_upper_half():
    mean, std = 4.0, 1.5
    upper = Truncated(Normal(mean, std), mean + 3.5 * std, mean + 4.5 * std).stream_spec()
    assert upper == _truncated_normal_spec(mean, std, 3.5, 4.5)
    assert upper["mirror"] and upper["pa"] == streams.normal_cdf(-4.5)
    lower = Truncated(Normal(mean, std), -math.inf, mean - 3.5 * std).stream_spec()
    assert not lower["mirror"] and (lower["pa"], lower["pb"]) == (0.0,
                                                                   streams.normal_cdf(-3.5))
    whole = Normal(mean, std).stream_spec()
    assert (whole["pa"], whole["pb"], whole["mirror"]) == (0.0, 1.0, False)
    # Untruncated, p is u itself: pa + u (pb - pa) = u exactly.
    u = streams.uniforms(1, 0, np.arange(1000))
    assert np.array_equal(Normal(mean, std).from_uniform(u), mean + std * streams.ndtri(u))


def test_transform_clamps_and_indexes_as_the_table_says():
    u = np.array([U_MIN, 0.25, 0.5, U_MAX])
    affine = {"kind": "affine", "a": 2.0, "b": 3.0, "pa": 0.0, "pb": 0.0, "mirror": False,
              "low": 2.0, "high": 5.0, "samples": None}
    assert np.array_equal(streams.transform(affine, u), 2.0 + u * 3.0)
    log = {**affine, "kind": "exp_affine", "a": math.log(10.0), "b": math.log(1e4),
           "low": 10.0, "high": 1e5}
    values = streams.transform(log, u)
    assert values.min() >= 10.0 and values.max() <= 1e5
    assert values[2] == pytest.approx(1e3, rel=1e-15)
    samples = np.array([5.0, 1.0, 3.0])
    empirical = {**affine, "kind": "empirical", "a": 0.0, "b": 0.0, "low": 1.0, "high": 5.0,
                 "samples": samples}
    assert streams.transform(empirical, [U_MIN, 1 / 3 - 1e-9, 1 / 3, 2 / 3, U_MAX]).tolist() \
        == [5.0, 5.0, 1.0, 3.0, 3.0]
    with pytest.raises(ValueError, match="unknown distribution kind"):
        streams.transform({**affine, "kind": "gamma"}, u)
