// Readout modes (python/epc_fast/modes.py): each point takes the mode with the highest EPC.
// best_modes picks it from every mode's EPC, take_modes gathers any output of the modes by that
// pick. Both run over contiguous columns in blocks on the call's threads (for_each_block),
// each point on its own: the results do not depend on the thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "parallel.h"

namespace epc_fast {

// The mode index of a point where no mode has a finite EPC (every mode INVALID or UNREACHABLE).
constexpr std::int16_t no_mode = -1;

// Points a block of best_modes and take_modes covers: enough work to be worth a grab.
constexpr std::size_t mode_block_points = 4096;

// mode[i] for i < n: the first mode with the largest finite EPC among epc[k][i] (NaN and +-inf
// are not finite), no_mode where none is. Never throws.
inline void best_modes(const std::vector<const double*>& epc, std::int16_t* mode, std::size_t n,
                       int threads) noexcept {
    struct None {};
    for_each_block<None>(0, n, mode_block_points, threads,
                         [&](std::size_t first, std::size_t count, None&) {
        alignas(64) double best[mode_block_points];
        std::int16_t* __restrict pick = mode + first;
        for (std::size_t i = 0; i < count; ++i) {
            best[i] = 0.0;
            pick[i] = no_mode;
        }
        for (std::size_t k = 0; k < epc.size(); ++k) {
            const double* __restrict v = epc[k] + first;
            const auto index = static_cast<std::int16_t>(k);
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < count; ++i) {
                // finite: v - v is 0 (NaN for NaN and +-inf)
                const bool better = (v[i] - v[i] == 0.0) & ((pick[i] == no_mode) | (v[i] > best[i]));
                best[i] = better ? v[i] : best[i];
                pick[i] = better ? index : pick[i];
            }
        }
    });
}

// out[i] = values[mode[i]][i] for i < n, elements of `item_bytes` bytes (1, 2, 4 or 8); a point
// of no_mode takes the first mode's. Never throws.
inline void take_modes(const std::int16_t* mode, const std::vector<const void*>& values,
                       std::size_t item_bytes, void* out, std::size_t n, int threads) noexcept {
    struct None {};
    auto take = [&](auto item) {
        using Item = decltype(item);
        Item* to = static_cast<Item*>(out);
        for_each_block<None>(0, n, mode_block_points, threads,
                             [&](std::size_t first, std::size_t count, None&) {
            for (std::size_t i = first; i < first + count; ++i) {
                const std::size_t k = mode[i] > 0 ? static_cast<std::size_t>(mode[i]) : 0;
                to[i] = static_cast<const Item*>(values[k])[i];
            }
        });
    };
    switch (item_bytes) {
        case 1: take(std::uint8_t{}); break;
        case 2: take(std::uint16_t{}); break;
        case 4: take(std::uint32_t{}); break;
        default: take(std::uint64_t{}); break;
    }
}

}  // namespace epc_fast
