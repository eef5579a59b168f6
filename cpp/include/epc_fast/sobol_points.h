// Scrambled Sobol' uniforms of a scan's points (python/epc_fast/scan/qmc.py states the
// contract and gives the direction numbers and the scrambling keys; this matches it bit for
// bit): point k of a dimension in Gray-code order, its 32 bits scrambled by B. Burley's hash of
// the reversed bits ("Practical hash-based Owen scrambling", JCGT 9(4), 2020), 20 hashed low
// bits below them, and the uniform (K + 1/2) 2^-52 as the Monte Carlo draws form it. The lane
// loops are 32-bit integer arithmetic with no branch, so that they vectorise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "block.h"
#include "constants.h"
#include "philox.h"

namespace epc_fast {

// The Sobol' sampling of a scan: `dimensions` random parameters, 32 direction numbers each
// (directions[32 d + b]), and a scrambling key per replicate and dimension
// (keys[dimensions r + d]).
struct SobolSampling {
    bool on = false;
    std::uint32_t dimensions = 0;
    std::uint32_t replicates = 1;
    std::vector<std::uint32_t> directions;
    std::vector<std::uint32_t> keys;
};

namespace sobol {

EPC_FAST_INLINE std::uint32_t reverse_bits(std::uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

// Each bit flipped by a function of the bits below it, keyed (qmc.py _owen_hash).
EPC_FAST_INLINE std::uint32_t owen_hash(std::uint32_t x, std::uint32_t key) {
    x += key;
    x ^= x * 0x6C50B47Cu;
    x ^= x * 0xB82F1E52u;
    x ^= x * 0xC7AFE638u;
    x ^= x * 0x8D22F6E6u;
    return x;
}

// C. Wellons' lowbias32 (qmc.py _low_bits).
EPC_FAST_INLINE std::uint32_t low_bits(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7FEB352Du;
    x ^= x >> 15;
    x *= 0x846CA68Bu;
    return x ^ (x >> 16);
}

}  // namespace sobol

// u[i] = the scrambled Sobol' uniform of point k[i] of dimension d under the key of replicate
// replicate[i], for the lanes of a block; `bits` bounds the k (every k < 2^bits), so that the
// Gray code's bits above it are not visited.
inline void sobol_uniforms(const SobolSampling& s, std::uint32_t d, const std::uint32_t* __restrict k,
                           const std::int32_t* __restrict replicate, int bits, double* __restrict u) {
    const std::uint32_t* __restrict v = s.directions.data() + 32u * d;
    const std::uint32_t* __restrict keys = s.keys.data();
    const std::uint32_t dims = s.dimensions;
    alignas(64) std::uint32_t x[block_size];
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) x[i] = 0;
    for (int b = 0; b < bits; ++b) {
        const std::uint32_t vb = v[b];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) {
            const std::uint32_t gray = k[i] ^ (k[i] >> 1);
            x[i] ^= vb & (0u - ((gray >> b) & 1u));
        }
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const std::uint32_t key = keys[dims * static_cast<std::uint32_t>(replicate[i]) + d];
        const std::uint32_t y = sobol::reverse_bits(sobol::owen_hash(sobol::reverse_bits(x[i]), key));
        const std::uint32_t low = sobol::low_bits(y ^ key);
        u[i] = philox::uniform_of(y, low);
    }
}

}  // namespace epc_fast
