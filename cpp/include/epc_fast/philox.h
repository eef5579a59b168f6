// Counter-based random numbers for scans: Philox4x32-10 (Salmon, Moraes, Dror and Shaw,
// "Parallel random numbers: as easy as 1, 2, 3", SC'11), and the scan's uniforms in (0, 1).
//
// A uniform is a pure function of (seed, stream, point index): the draw contract of
// docs/scan.md, which python/epc_fast/scan/streams.py reproduces bit for bit. No state carries
// from one point to the next, so any chunking, thread count or machine gives the same draws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

#include "block.h"
#include "constants.h"
#include "parallel.h"

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

// The uniform of point `index` in stream `stream` of the scan seeded with `seed`.
EPC_FAST_INLINE double stream_uniform(std::uint64_t seed, std::uint32_t stream, std::uint64_t index) {
    const philox::Words w = philox::philox4x32_10(
        philox::Words{index & 0xFFFFFFFFu, index >> 32, stream, 0u}, seed & 0xFFFFFFFFu,
        seed >> 32);
    return philox::uniform_of(w.x0, w.x1);
}

namespace detail {

// The Philox rounds and the uniform of a vector of lanes with the x86 widening multiply
// (pmuludq: the low 32 bits of each 64-bit lane, a 64-bit product), which compilers do not
// choose for a 64-bit product of values below 2^32 in portable code (they emulate a 64 x 64
// multiply: three multiplies, or AVX-512's slower vpmullq). The same integer operations as
// philox4x32_10 and uniform_of, so the same bits.
#if defined(__AVX512F__)
using Lanes = __m512i;
constexpr std::size_t lanes_per_vector = 8;
EPC_FAST_INLINE Lanes load(const std::uint64_t* p) { return _mm512_loadu_si512(p); }
EPC_FAST_INLINE Lanes splat(std::uint64_t v) { return _mm512_set1_epi64(static_cast<long long>(v)); }
EPC_FAST_INLINE Lanes mul32(Lanes a, Lanes b) { return _mm512_mul_epu32(a, b); }
EPC_FAST_INLINE Lanes shr(Lanes a, int n) { return _mm512_srli_epi64(a, static_cast<unsigned>(n)); }
EPC_FAST_INLINE Lanes shl(Lanes a, int n) { return _mm512_slli_epi64(a, static_cast<unsigned>(n)); }
EPC_FAST_INLINE Lanes bit_and(Lanes a, Lanes b) { return _mm512_and_si512(a, b); }
EPC_FAST_INLINE Lanes bit_or(Lanes a, Lanes b) { return _mm512_or_si512(a, b); }
EPC_FAST_INLINE Lanes bit_xor(Lanes a, Lanes b) { return _mm512_xor_si512(a, b); }
EPC_FAST_INLINE void store_uniform(double* u, Lanes bits) {
    const __m512d two52_plus_k = _mm512_castsi512_pd(bits);
    _mm512_storeu_pd(u, _mm512_mul_pd(_mm512_add_pd(_mm512_sub_pd(two52_plus_k, _mm512_set1_pd(0x1p52)),
                                                    _mm512_set1_pd(0.5)),
                                      _mm512_set1_pd(0x1p-52)));
}
#define EPC_FAST_PHILOX_VECTOR 1
#elif defined(__AVX2__)
using Lanes = __m256i;
constexpr std::size_t lanes_per_vector = 4;
EPC_FAST_INLINE Lanes load(const std::uint64_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
EPC_FAST_INLINE Lanes splat(std::uint64_t v) { return _mm256_set1_epi64x(static_cast<long long>(v)); }
EPC_FAST_INLINE Lanes mul32(Lanes a, Lanes b) { return _mm256_mul_epu32(a, b); }
EPC_FAST_INLINE Lanes shr(Lanes a, int n) { return _mm256_srli_epi64(a, n); }
EPC_FAST_INLINE Lanes shl(Lanes a, int n) { return _mm256_slli_epi64(a, n); }
EPC_FAST_INLINE Lanes bit_and(Lanes a, Lanes b) { return _mm256_and_si256(a, b); }
EPC_FAST_INLINE Lanes bit_or(Lanes a, Lanes b) { return _mm256_or_si256(a, b); }
EPC_FAST_INLINE Lanes bit_xor(Lanes a, Lanes b) { return _mm256_xor_si256(a, b); }
EPC_FAST_INLINE void store_uniform(double* u, Lanes bits) {
    const __m256d two52_plus_k = _mm256_castsi256_pd(bits);
    _mm256_storeu_pd(u, _mm256_mul_pd(_mm256_add_pd(_mm256_sub_pd(two52_plus_k, _mm256_set1_pd(0x1p52)),
                                                    _mm256_set1_pd(0.5)),
                                      _mm256_set1_pd(0x1p-52)));
}
#define EPC_FAST_PHILOX_VECTOR 1
#else
#define EPC_FAST_PHILOX_VECTOR 0
#endif

}  // namespace detail

// Vectors of lanes whose Philox rounds run side by side in stream_uniforms: two fill each
// other's multiply latency (1.1x AVX-512's and 1.3x AVX2's uniforms a second of one vector a
// step); more run out of registers.
constexpr std::size_t interleaved = 2;

// u[i] = stream_uniform(seed, stream, index[i]) for every lane of a block.
inline void stream_uniforms(std::uint64_t seed, std::uint32_t stream, const std::uint64_t* __restrict index,
                            double* __restrict u) {
#if EPC_FAST_PHILOX_VECTOR
    using namespace detail;
    const Lanes low = splat(0xFFFFFFFFu), m0 = splat(philox::m0), m1 = splat(philox::m1);
    const Lanes stream_word = splat(stream), exponent = splat(0x4330000000000000u);
    constexpr std::size_t step = interleaved * lanes_per_vector;
    static_assert(block_size % step == 0, "whole steps a block");
    // `interleaved` vectors a step: their rounds interleave, so that one's multiplies fill the
    // others' latency
    for (std::size_t i = 0; i < block_size; i += step) {
        Lanes x0[interleaved], x1[interleaved], x2[interleaved], x3[interleaved];
        for (std::size_t v = 0; v < interleaved; ++v) {
            const Lanes point = load(index + i + v * lanes_per_vector);
            x0[v] = bit_and(point, low);
            x1[v] = shr(point, 32);
            x2[v] = stream_word;
            x3[v] = splat(0);
        }
        std::uint64_t k0 = seed & 0xFFFFFFFFu, k1 = seed >> 32;
        for (int r = 0; r < philox::rounds; ++r) {
            if (r > 0) {
                k0 = (k0 + philox::w0) & 0xFFFFFFFFu;
                k1 = (k1 + philox::w1) & 0xFFFFFFFFu;
            }
            const Lanes key0 = splat(k0), key1 = splat(k1);
            for (std::size_t v = 0; v < interleaved; ++v) {
                const Lanes p0 = mul32(x0[v], m0), p1 = mul32(x2[v], m1);
                x0[v] = bit_xor(bit_xor(shr(p1, 32), x1[v]), key0);
                x2[v] = bit_xor(bit_xor(shr(p0, 32), x3[v]), key1);
                x1[v] = bit_and(p1, low);
                x3[v] = bit_and(p0, low);
            }
        }
        for (std::size_t v = 0; v < interleaved; ++v)
            store_uniform(u + i + v * lanes_per_vector,
                          bit_or(exponent, bit_or(shl(x0[v], 20), shr(x1[v], 12))));
    }
#else
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) u[i] = stream_uniform(seed, stream, index[i]);
#endif
}

}  // namespace epc_fast
