// Counter-based random numbers for scans: Philox4x32-10 (Salmon, Moraes, Dror and Shaw,
// "Parallel random numbers: as easy as 1, 2, 3", SC'11), and the scan's uniforms in (0, 1).
//
// A uniform is a pure function of (seed, stream, point index): the draw contract of docs/scan.md,
// which python/epc_fast/scan/sampling/streams.py reproduces bit for bit. No state carries from one
// point to the next, so any chunking, thread count or machine gives the same draws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

#include "../block.h"
#include "../constants.h"
#include "../parallel.h"

namespace epc_fast {

namespace philox {

// The published constants: round multipliers and key increments (Weyl sequence).
constexpr std::uint64_t m0 = 0xD2511F53u, m1 = 0xCD9E8D57u;
constexpr std::uint64_t w0 = 0x9E3779B9u, w1 = 0xBB67AE85u;
constexpr int rounds = 10;

// The four 32-bit words of a counter or an output, each held in a 64-bit integer: the round's
// 32 x 32 -> 64-bit products then need no widening or narrowing, so that a lane loop over
// philox4x32_10 vectorises to plain 64-bit lanes.
struct Words {
    std::uint64_t x0, x1, x2, x3;
};

// Philox4x32 with `rounds` rounds of counter (c0..c3) under key (k0, k1); the key is bumped
// before rounds 2 to 10.
EPC_FAST_INLINE Words philox4x32_10(Words c, std::uint64_t k0, std::uint64_t k1) {
    constexpr std::uint64_t low = 0xFFFFFFFFu;
    for (int r = 0; r < rounds; ++r) {
        if (r > 0) {
            k0 = (k0 + w0) & low;
            k1 = (k1 + w1) & low;
        }
        const std::uint64_t p0 = m0 * c.x0;
        const std::uint64_t p1 = m1 * c.x2;
        c = Words{(p1 >> 32) ^ c.x1 ^ k0, p1 & low, (p0 >> 32) ^ c.x3 ^ k1, p0 & low};
    }
    return c;
}

// u = (k + 1/2) 2^-52 with k = x0 2^20 + (x1 >> 12): 52 random bits, in (0, 1), exact. k is
// converted through the bits of 2^52 + k (AVX2 has no vector conversion of 64-bit integers).
EPC_FAST_INLINE double uniform_of(std::uint64_t x0, std::uint64_t x1) {
    const std::uint64_t bits = 0x4330000000000000u | (x0 << 20) | (x1 >> 12);  // 2^52 + k
    double two52_plus_k;
    std::memcpy(&two52_plus_k, &bits, sizeof bits);
    return ((two52_plus_k - 0x1p52) + 0.5) * 0x1p-52;
}

}  // namespace philox

// The uniform of point `index` in stream `stream` of the scan seeded with `seed`. One Philox
// call serves a pair of points: point i's counter is (j mod 2^32, j div 2^32, stream, 0) with
// j = i div 2, and an even i takes the output words (x0, x1), an odd i (x2, x3). The words are
// chosen by masks rather than a branch, so that a lane loop over this vectorises.
EPC_FAST_INLINE double stream_uniform(std::uint64_t seed, std::uint32_t stream, std::uint64_t index) {
    const std::uint64_t pair = index >> 1;
    const philox::Words w = philox::philox4x32_10(philox::Words{pair & 0xFFFFFFFFu, pair >> 32, stream, 0u},
                                                  seed & 0xFFFFFFFFu, seed >> 32);
    const std::uint64_t odd = std::uint64_t{0} - (index & 1u);  // all ones for an odd index
    return philox::uniform_of((w.x0 & ~odd) | (w.x2 & odd), (w.x1 & ~odd) | (w.x3 & odd));
}

// Whether a block's indices are first, first + 1, ..., first + block_size - 1 with first even
// and no wrap past 2^64 - 1: then lanes 2k and 2k + 1 are the even and odd point of the pair
// first / 2 + k, and one Philox call gives both their uniforms.
EPC_FAST_INLINE bool block_is_whole_pairs(const std::uint64_t* __restrict index) {
    const std::uint64_t first = index[0], last = first + (block_size - 1);
    // the cheap refusals first, in one branch (an odd first index, a wrap, a last lane out of
    // step: shuffled or padded blocks), then every lane
    if (((first & 1u) | static_cast<std::uint64_t>(last < first) | (index[block_size - 1] ^ last)) != 0)
        return false;
    std::uint64_t differ = 0;
    EPC_FAST_SIMD_REDUCTION(| : differ)
    for (std::size_t i = 0; i < block_size; ++i) differ |= index[i] ^ (first + i);
    return differ == 0;
}

namespace detail {

// The Philox rounds and the uniforms of vectors of lanes with the x86 widening multiply
// (pmuludq: the low 32 bits of each 64-bit lane, a 64-bit product), which compilers do not
// choose for a 64-bit product of values below 2^32 in portable code (they emulate a 64 x 64
// multiply: three multiplies, or AVX-512's slower vpmullq). The same integer operations as
// philox4x32_10 and uniform_of, so the same bits. The uniform is formed as
// (2^52 + k) 2^-52 - (1 - 2^-53) = (k + 1/2) 2^-52: both steps are exact (a power-of-two
// scaling, then a difference that float64 holds), fused or not, so they give uniform_of's
// (k + 1/2) 2^-52 in one operation fewer.
//
// store_uniform writes the uniforms of one vector of bits 2^52 + k; store_pairs writes the
// uniforms of two (the even points' and the odd points'), interleaved: even[0], odd[0],
// even[1], odd[1], ...; select_odd takes, lane by lane, `odd` where the index is odd, else
// `even`.
#if defined(__AVX512F__)
using Lanes = __m512i;
constexpr std::size_t lanes_per_vector = 8;
EPC_FAST_INLINE Lanes load(const std::uint64_t* p) { return _mm512_loadu_si512(p); }
EPC_FAST_INLINE Lanes splat(std::uint64_t v) { return _mm512_set1_epi64(static_cast<long long>(v)); }
EPC_FAST_INLINE Lanes lane_numbers() { return _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7); }
EPC_FAST_INLINE Lanes add(Lanes a, Lanes b) { return _mm512_add_epi64(a, b); }
EPC_FAST_INLINE Lanes mul32(Lanes a, Lanes b) { return _mm512_mul_epu32(a, b); }
EPC_FAST_INLINE Lanes shr(Lanes a, int n) { return _mm512_srli_epi64(a, static_cast<unsigned>(n)); }
EPC_FAST_INLINE Lanes shl(Lanes a, int n) { return _mm512_slli_epi64(a, static_cast<unsigned>(n)); }
EPC_FAST_INLINE Lanes bit_and(Lanes a, Lanes b) { return _mm512_and_si512(a, b); }
EPC_FAST_INLINE Lanes bit_or(Lanes a, Lanes b) { return _mm512_or_si512(a, b); }
EPC_FAST_INLINE Lanes bit_xor(Lanes a, Lanes b) { return _mm512_xor_si512(a, b); }
EPC_FAST_INLINE Lanes select_odd(Lanes index, Lanes even, Lanes odd) {
    return _mm512_mask_blend_epi64(_mm512_test_epi64_mask(index, _mm512_set1_epi64(1)), even, odd);
}
EPC_FAST_INLINE __m512d uniform_of_bits(Lanes bits) {
    const __m512d two52_plus_k = _mm512_castsi512_pd(bits);
    return _mm512_sub_pd(_mm512_mul_pd(two52_plus_k, _mm512_set1_pd(0x1p-52)), _mm512_set1_pd(1.0 - 0x1p-53));
}
EPC_FAST_INLINE void store_uniform(double* u, Lanes bits) { _mm512_storeu_pd(u, uniform_of_bits(bits)); }
EPC_FAST_INLINE void store_pairs(double* u, Lanes even, Lanes odd) {
    const __m512d e = uniform_of_bits(even), o = uniform_of_bits(odd);
    // indices 0..7 pick from e, 8..15 from o
    _mm512_storeu_pd(u, _mm512_permutex2var_pd(e, _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), o));
    _mm512_storeu_pd(u + 8, _mm512_permutex2var_pd(e, _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15), o));
}
#define EPC_FAST_PHILOX_VECTOR 1
#elif defined(__AVX2__)
using Lanes = __m256i;
constexpr std::size_t lanes_per_vector = 4;
EPC_FAST_INLINE Lanes load(const std::uint64_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
EPC_FAST_INLINE Lanes splat(std::uint64_t v) { return _mm256_set1_epi64x(static_cast<long long>(v)); }
EPC_FAST_INLINE Lanes lane_numbers() { return _mm256_setr_epi64x(0, 1, 2, 3); }
EPC_FAST_INLINE Lanes add(Lanes a, Lanes b) { return _mm256_add_epi64(a, b); }
EPC_FAST_INLINE Lanes mul32(Lanes a, Lanes b) { return _mm256_mul_epu32(a, b); }
EPC_FAST_INLINE Lanes shr(Lanes a, int n) { return _mm256_srli_epi64(a, n); }
EPC_FAST_INLINE Lanes shl(Lanes a, int n) { return _mm256_slli_epi64(a, n); }
EPC_FAST_INLINE Lanes bit_and(Lanes a, Lanes b) { return _mm256_and_si256(a, b); }
EPC_FAST_INLINE Lanes bit_or(Lanes a, Lanes b) { return _mm256_or_si256(a, b); }
EPC_FAST_INLINE Lanes bit_xor(Lanes a, Lanes b) { return _mm256_xor_si256(a, b); }
EPC_FAST_INLINE Lanes select_odd(Lanes index, Lanes even, Lanes odd) {
    // blendv_pd chooses by each lane's sign bit: the index's bit 0 shifted there
    return _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(even), _mm256_castsi256_pd(odd),
                                                 _mm256_castsi256_pd(_mm256_slli_epi64(index, 63))));
}
EPC_FAST_INLINE __m256d uniform_of_bits(Lanes bits) {
    const __m256d two52_plus_k = _mm256_castsi256_pd(bits);
    return _mm256_sub_pd(_mm256_mul_pd(two52_plus_k, _mm256_set1_pd(0x1p-52)), _mm256_set1_pd(1.0 - 0x1p-53));
}
EPC_FAST_INLINE void store_uniform(double* u, Lanes bits) { _mm256_storeu_pd(u, uniform_of_bits(bits)); }
EPC_FAST_INLINE void store_pairs(double* u, Lanes even, Lanes odd) {
    const __m256d e = uniform_of_bits(even), o = uniform_of_bits(odd);
    const __m256d low_halves = _mm256_unpacklo_pd(e, o);   // e0 o0 e2 o2
    const __m256d high_halves = _mm256_unpackhi_pd(e, o);  // e1 o1 e3 o3
    _mm256_storeu_pd(u, _mm256_permute2f128_pd(low_halves, high_halves, 0x20));      // e0 o0 e1 o1
    _mm256_storeu_pd(u + 4, _mm256_permute2f128_pd(low_halves, high_halves, 0x31));  // e2 o2 e3 o3
}
#define EPC_FAST_PHILOX_VECTOR 1
#else
#define EPC_FAST_PHILOX_VECTOR 0
#endif

}  // namespace detail

#if EPC_FAST_PHILOX_VECTOR
namespace detail {

// Vectors of lanes whose Philox rounds run side by side in stream_uniforms, so that each
// fills the others' multiply latency: four with AVX-512's 32 registers (1.2x the uniforms a
// second of two, on consecutive and on arbitrary indices), two with AVX2's 16 (1.3x one's;
// four spill and lose 1.15x).
#if defined(__AVX512F__)
constexpr std::size_t interleaved = 4;
#else
constexpr std::size_t interleaved = 2;
#endif

// The counters and then the outputs of `interleaved` vectors of Philox calls.
struct Counters {
    Lanes x0[interleaved], x1[interleaved], x2[interleaved], x3[interleaved];
};

// Philox4x32-10 of every lane of c in place under the key of `seed`; the vectors' rounds
// interleave, so that one's multiplies fill the others' latency. Within the rounds each word
// is right in its low 32 bits only: the products' low halves (x1, x3) are kept whole, so x0
// and x2 carry their high halves too, which the next multiply (of the low 32 bits) and the
// next xor's low bits ignore. The words are cut to 32 bits once, after the last round.
EPC_FAST_INLINE void philox_rounds(Counters& c, std::uint64_t seed) {
    const Lanes low = splat(0xFFFFFFFFu), m0 = splat(philox::m0), m1 = splat(philox::m1);
    std::uint64_t k0 = seed & 0xFFFFFFFFu, k1 = seed >> 32;
    for (int r = 0; r < philox::rounds; ++r) {
        if (r > 0) {
            k0 = (k0 + philox::w0) & 0xFFFFFFFFu;
            k1 = (k1 + philox::w1) & 0xFFFFFFFFu;
        }
        const Lanes key0 = splat(k0), key1 = splat(k1);
        for (std::size_t v = 0; v < interleaved; ++v) {
            const Lanes p0 = mul32(c.x0[v], m0), p1 = mul32(c.x2[v], m1);
            c.x0[v] = bit_xor(bit_xor(shr(p1, 32), c.x1[v]), key0);
            c.x2[v] = bit_xor(bit_xor(shr(p0, 32), c.x3[v]), key1);
            c.x1[v] = p1;
            c.x3[v] = p0;
        }
    }
    for (std::size_t v = 0; v < interleaved; ++v) {
        c.x0[v] = bit_and(c.x0[v], low);
        c.x1[v] = bit_and(c.x1[v], low);
        c.x2[v] = bit_and(c.x2[v], low);
        c.x3[v] = bit_and(c.x3[v], low);
    }
}

// Vector v's counters: (pair mod 2^32, pair div 2^32, stream, 0).
EPC_FAST_INLINE void set_counter(Counters& c, std::size_t v, Lanes pair, Lanes stream_word) {
    c.x0[v] = bit_and(pair, splat(0xFFFFFFFFu));
    c.x1[v] = shr(pair, 32);
    c.x2[v] = stream_word;
    c.x3[v] = splat(0);
}

// The bits of 2^52 + k for output words (xa, xb), k = xa 2^20 + (xb div 2^12) (uniform_of).
EPC_FAST_INLINE Lanes uniform_bits(Lanes xa, Lanes xb) {
    return bit_or(splat(0x4330000000000000u), bit_or(shl(xa, 20), shr(xb, 12)));
}

}  // namespace detail
#endif

// u[i] = stream_uniform(seed, stream, index[i]) for every lane of a block. A block of whole
// pairs (block_is_whole_pairs: consecutive indices from an even one, a scan's full blocks)
// takes one Philox call per two lanes; any other block (arbitrary indices, an odd first
// index, a partial block whose tail lanes repeat an index) one call per lane, the lane's word
// pair chosen by its index's parity.
inline void stream_uniforms(std::uint64_t seed, std::uint32_t stream, const std::uint64_t* __restrict index,
                            double* __restrict u) {
    constexpr std::size_t pairs = block_size / 2;
#if EPC_FAST_PHILOX_VECTOR
    using namespace detail;
    const Lanes stream_word = splat(stream);
    constexpr std::size_t step = interleaved * lanes_per_vector;
    static_assert(pairs % step == 0, "whole steps a block, and a half block");
    Counters c;
    if (block_is_whole_pairs(index)) {
        // `step` calls a step: pairs first_pair + p .. first_pair + p + step - 1, lanes
        // 2 p .. 2 (p + step) - 1
        const std::uint64_t first_pair = index[0] >> 1;
        const Lanes numbers = lane_numbers();
        for (std::size_t p = 0; p < pairs; p += step) {
            for (std::size_t v = 0; v < interleaved; ++v) {
                set_counter(c, v, add(splat(first_pair + p + v * lanes_per_vector), numbers), stream_word);
            }
            philox_rounds(c, seed);
            for (std::size_t v = 0; v < interleaved; ++v)
                store_pairs(u + 2 * (p + v * lanes_per_vector), uniform_bits(c.x0[v], c.x1[v]),
                            uniform_bits(c.x2[v], c.x3[v]));
        }
        return;
    }
    for (std::size_t i = 0; i < block_size; i += step) {
        for (std::size_t v = 0; v < interleaved; ++v) {
            set_counter(c, v, shr(load(index + i + v * lanes_per_vector), 1), stream_word);
        }
        philox_rounds(c, seed);
        for (std::size_t v = 0; v < interleaved; ++v) {
            // the indices loaded again rather than held through the rounds (AVX2 has 16
            // registers)
            const Lanes point = load(index + i + v * lanes_per_vector);
            const Lanes high = select_odd(point, c.x0[v], c.x2[v]), low_word = select_odd(point, c.x1[v], c.x3[v]);
            store_uniform(u + i + v * lanes_per_vector, uniform_bits(high, low_word));
        }
    }
#else
    if (block_is_whole_pairs(index)) {
        const std::uint64_t first_pair = index[0] >> 1;
        EPC_FAST_SIMD
        for (std::size_t p = 0; p < pairs; ++p) {
            const std::uint64_t pair = first_pair + p;
            const philox::Words w = philox::philox4x32_10(
                philox::Words{pair & 0xFFFFFFFFu, pair >> 32, stream, 0u}, seed & 0xFFFFFFFFu, seed >> 32);
            u[2 * p] = philox::uniform_of(w.x0, w.x1);
            u[2 * p + 1] = philox::uniform_of(w.x2, w.x3);
        }
        return;
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) u[i] = stream_uniform(seed, stream, index[i]);
#endif
}

}  // namespace epc_fast
