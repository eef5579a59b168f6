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

// The uniforms of points first .. first + block_size - 1 (every lane; the caller uses the
// first n): one Philox call a lane, a loop the compiler vectorises.
inline void stream_uniforms(std::uint64_t seed, std::uint32_t stream, std::uint64_t first,
                            double* __restrict u) {
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) u[i] = stream_uniform(seed, stream, first + i);
}

}  // namespace epc_fast
