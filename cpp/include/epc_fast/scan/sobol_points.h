// Scrambled Sobol' uniforms of a scan's points (python/epc_fast/scan/sampling/qmc.py states the
// contract and gives the direction numbers and the scrambling keys; this matches it bit for
// bit): point k of a dimension in Gray-code order, its 32 bits scrambled by B. Burley's hash of
// the reversed bits ("Practical hash-based Owen scrambling", JCGT 9(4), 2020), 20 hashed low
// bits below them, and the uniform (K + 1/2) 2^-52 as the Monte Carlo draws form it. The lane
// loops are 32-bit integer arithmetic with no branch, so that they vectorise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "../block.h"
#include "../constants.h"
#include "philox.h"

namespace epc_fast {

// The Sobol' sampling of a scan: `dimensions` random parameters, 32 direction numbers each
// (directions[32 d + b]), and a scrambling key per replicate and dimension
// (keys[replicates d + r]). `reversed` holds the direction numbers with their bits reversed
// (set_reversed): bit reversal is linear over xor, so the xor of reversed direction numbers is
// the reversed point, which the scrambling hash takes.
struct SobolSampling {
    bool on = false;
    std::uint32_t dimensions = 0;
    std::uint32_t replicates = 1;
    std::vector<std::uint32_t> directions;
    std::vector<std::uint32_t> keys;
    std::vector<std::uint32_t> reversed;
};

// A block's Gray-code bits, shared by every dimension: mask[b][i] is all ones where bit b of
// lane i's Gray code g(k) = k xor (k >> 1) is set. When every lane's k lies in two consecutive
// runs of 64 (a block of consecutive points: `split`), the Gray code's bits from 6 up depend
// only on k div 64, which is `high` or `high + 1` (all ones in `upper`): each dimension's
// point is then its xor over those bits for the two values (two scalars a block) and over
// bits 0 to 5 per lane. Otherwise the masks cover every bit below `bits` (every k < 2^bits).
constexpr int sobol_low_bits = 6;
// `cached` keeps, per dimension, the two upper points of the last `high` they were formed
// for (a scan's consecutive blocks share them for 64 points per replicate and cell).
constexpr std::uint32_t sobol_max_dimensions = 64;
struct SobolLanes {
    int bits = 1;
    bool split = false;
    std::uint32_t high = 0;
    struct Upper {
        std::int64_t high = -1;
        int bits = 0;
        std::uint32_t first = 0, next = 0;
    };
    Upper cached[sobol_max_dimensions];
    alignas(64) std::uint32_t upper[block_size];
    alignas(64) std::uint32_t mask[32][block_size];
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

// The uniform's 20 low bits (qmc.py _low_bits): the high bits of a product by the golden
// ratio's 32 bits, below the scrambled point's 32.
EPC_FAST_INLINE std::uint32_t low_bits(std::uint32_t x) { return x * 0x9E3779B9u; }

}  // namespace sobol

inline void set_reversed(SobolSampling& s) {
    s.reversed.resize(s.directions.size());
    for (std::size_t j = 0; j < s.directions.size(); ++j) s.reversed[j] = sobol::reverse_bits(s.directions[j]);
}

// Sets the Gray-code masks of the lanes' k (each below 2^bits).
inline void set_gray_masks(const std::uint32_t* __restrict k, int bits, SobolLanes& lanes) {
    std::uint32_t low = k[0], top = k[0];
    for (std::size_t i = 1; i < block_size; ++i) {
        low = k[i] < low ? k[i] : low;
        top = k[i] > top ? k[i] : top;
    }
    lanes.bits = bits;
    lanes.high = low >> sobol_low_bits;
    lanes.split = (top >> sobol_low_bits) - lanes.high <= 1;
    const int masked = lanes.split && bits > sobol_low_bits ? sobol_low_bits : bits;
    for (int b = 0; b < masked; ++b) {
        std::uint32_t* __restrict m = lanes.mask[b];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) m[i] = 0u - (((k[i] ^ (k[i] >> 1)) >> b) & 1u);
    }
    if (masked == bits) {
        lanes.split = false;
        return;
    }
    const std::uint32_t high = lanes.high;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) lanes.upper[i] = 0u - ((k[i] >> sobol_low_bits) - high);
}

namespace sobol {

// The xor of the (reversed) direction numbers v over the Gray code's bits from 6 up of the k
// in [64 h, 64 h + 63].
EPC_FAST_INLINE std::uint32_t upper_point(const std::uint32_t* v, std::uint64_t h, int bits) {
    const std::uint64_t k = h << sobol_low_bits;
    const std::uint64_t gray = (k ^ (k >> 1)) >> sobol_low_bits;
    std::uint32_t x = 0;
    for (int b = sobol_low_bits; b < bits; ++b) x ^= v[b] & (0u - static_cast<std::uint32_t>((gray >> (b - sobol_low_bits)) & 1u));
    return x;
}

}  // namespace sobol

// u[i] = the scrambled Sobol' uniform of lane i's point of dimension d under the key of
// replicate replicate[i], for the lanes of a block.
inline void sobol_uniforms(const SobolSampling& s, std::uint32_t d, SobolLanes& lanes,
                           const std::int32_t* __restrict replicate, double* __restrict u) {
    const std::uint32_t* __restrict v = s.reversed.data() + 32u * d;
    const std::uint32_t* __restrict keys = s.keys.data() + static_cast<std::size_t>(s.replicates) * d;
    alignas(64) std::uint32_t x[block_size];
    int masked = lanes.bits;
    if (lanes.split) {
        masked = sobol_low_bits;
        SobolLanes::Upper& c = lanes.cached[d];
        if (c.high != lanes.high || c.bits != lanes.bits) {
            c.high = lanes.high;
            c.bits = lanes.bits;
            c.first = sobol::upper_point(v, lanes.high, lanes.bits);
            c.next = sobol::upper_point(v, std::uint64_t{lanes.high} + 1, lanes.bits) ^ c.first;
        }
        const std::uint32_t first = c.first, next = c.next;
        const std::uint32_t* __restrict upper = lanes.upper;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) x[i] = first ^ (next & upper[i]);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) x[i] = 0;
    }
    for (int b = 0; b < masked; ++b) {
        const std::uint32_t vb = v[b];
        const std::uint32_t* __restrict m = lanes.mask[b];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) x[i] ^= vb & m[i];
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const std::uint32_t key = keys[replicate[i]];
        const std::uint32_t y = sobol::reverse_bits(sobol::owen_hash(x[i], key));
        const std::uint32_t low = sobol::low_bits(y ^ key);
        u[i] = philox::uniform_of(y, low);
    }
}

}  // namespace epc_fast
