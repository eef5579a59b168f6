// A scan's reductions, folded a block of points at a time while the block is in cache: per
// group (group keys: groups.h) status counts, count/mean/std/min/max, histograms on fixed
// bins (equal in the value or its log10), the fraction below a threshold, and the k best points.
//
// Every state is exact or order-free (integer counts, min, max, the k best by a total order)
// except the mean and the squared deviations, which are accumulated in a fixed order into
// their scan block's moments: for a key with a cycle (GroupKey), per position of the cycle over
// the scan block, merged position by position at its end; otherwise 64 points (a kernel block)
// at a time, two-pass within them, merged one after the other (Chan et al.'s update). A scan
// block (scan_block_points) is folded by one thread, in point order, so its moments do not
// depend on the thread count or the chunk size; python/epc_fast/scan/reductions/summaries.py
// merges scan blocks in block order.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "../block.h"
#include "../status.h"
#include "folds.h"
#include "groups.h"
#include "space.h"
#include "states.h"

namespace epc_fast {
namespace detail {

// A histogram's or the quantiles' counts (and, without a cycle, the quantiles' min and max):
// each lane's cell in the counts (its group's row, its slot) and whether it counts (a finite
// value) found in a vector loop, then added lane by lane without a branch.
inline void fold_histogram(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const double* __restrict v = f.outputs[r.of];
    const double* __restrict t = r.log ? f.log10_outputs[r.of] : v;
    const bool octave = r.kind == ReductionKind::quantiles;
    const std::int32_t* __restrict g = f.groups[static_cast<std::size_t>(r.key)];
    const std::int64_t slots = r.slots();
    const std::size_t n = f.n;
    std::int64_t* __restrict counts = s.counts.data();
    // lanes past n (their groups those of an earlier block, or 0): a cell in range, counted 0
    // times
    alignas(64) std::int32_t finite[block_size];
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i)
        finite[i] = counted(i, n, v[i]);
    if (r.groups * slots <= std::numeric_limits<std::int32_t>::max()) {
        // the cells as exact doubles below 2^31, converted to 32-bit integers
        alignas(64) std::int32_t cell[block_size];
        const double row = static_cast<double>(slots);
        if (octave) {
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i)
                cell[i] = static_cast<std::int32_t>(static_cast<double>(g[i]) * row + octave_slot_of(r, v[i]));
        } else {
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i)
                cell[i] = static_cast<std::int32_t>(static_cast<double>(g[i]) * row + slot_of(r, t[i]));
        }
        for (std::size_t i = 0; i < block_size; ++i) counts[cell[i]] += finite[i];
    } else {
        for (std::size_t i = 0; i < block_size; ++i) {
            const double slot = octave ? octave_slot_of(r, v[i]) : slot_of(r, t[i]);
            counts[static_cast<std::int64_t>(g[i]) * slots + static_cast<std::int64_t>(slot)] += finite[i];
        }
    }
    if (r.kind == ReductionKind::histogram)
        for (std::size_t i = 0; i < n; ++i) ++s.points[static_cast<std::size_t>(g[i])];
    if (r.kind != ReductionKind::quantiles || r.cycle > 0) return;
    for (std::size_t i = 0; i < n; ++i) {
        if (!finite[i]) continue;
        const auto k = static_cast<std::size_t>(g[i]);
        s.low[k] = v[i] < s.low[k] ? v[i] : s.low[k];
        s.high[k] = v[i] > s.high[k] ? v[i] : s.high[k];
    }
}

}  // namespace detail

// Folds a scan block's sums per position of the key's cycle into the groups' states, position
// by position (a fixed order), and clears them: at the end of every scan block, before its
// moments are read.
inline void flush_cycle(const Reduction& r, const GroupKey& key, ReductionState& s) {
    if (r.cycle == 0) return;
    CycleSums& c = s.cycle;
    for (std::size_t p = 0; p < r.cycle; ++p) {
        const auto k = static_cast<std::size_t>(key.cycle[p]);
        switch (r.kind) {
            case ReductionKind::summary: {
                const std::uint64_t tally = c.tally[p];
                for (std::size_t j = 0; j < tally_statuses; ++j)
                    s.counts[k * ReductionState::n_status + j] +=
                        static_cast<std::int64_t>((tally >> (tally_bits * j)) & tally_field);
                const auto finite = static_cast<std::int64_t>((tally >> (tally_statuses * tally_bits)) & tally_field);
                if (finite > 0) {
                    // the deviations' sums about the shift give the mean and the squared
                    // deviations about it: sum (x - m)^2 = sum (x - a)^2 - n (m - a)^2
                    const double n = static_cast<double>(finite), mean_shift = c.sum[p] / n;
                    const double m2 = std::max(0.0, c.squares[p] - c.sum[p] * mean_shift);
                    detail::merge_moments(s.block_count[k], s.block_mean[k], s.block_m2[k],
                                          finite, c.shift[p] + mean_shift, m2);
                }
                s.low[k] = std::min(s.low[k], c.low[p]);
                s.high[k] = std::max(s.high[k], c.high[p]);
                break;
            }
            case ReductionKind::quantiles:
                s.low[k] = std::min(s.low[k], c.low[p]);
                s.high[k] = std::max(s.high[k], c.high[p]);
                break;
            case ReductionKind::fraction_below:
                s.counts[k] += static_cast<std::int64_t>(c.count[p]);
                s.points[k] += static_cast<std::int64_t>(c.below[p]);
                break;
            default:
                break;
        }
        c.reset(p);
    }
}

// Folds one kernel block into a thread's state of reduction r.
inline void fold(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    switch (r.kind) {
        case ReductionKind::summary:
            if (r.cycle > 0) detail::fold_summary_cycle(r, f, s);
            else detail::fold_summary(r, f, s);
            return;
        case ReductionKind::histogram: detail::fold_histogram(r, f, s); return;
        case ReductionKind::quantiles:
            detail::fold_histogram(r, f, s);
            if (r.cycle > 0) detail::fold_range_cycle(r, f, s);
            return;
        case ReductionKind::fraction_below:
            if (r.cycle > 0) detail::fold_fraction_below_cycle(r, f, s);
            else detail::fold_fraction_below(r, f, s);
            return;
        case ReductionKind::top_k: detail::fold_top_k(r, f, s); return;
    }
}

// Adds another thread's state `b` into `a` (order-free: counts, min, max, the k best).
inline void combine(const Reduction& r, ReductionState& a, const ReductionState& b) {
    for (std::size_t i = 0; i < a.counts.size(); ++i) a.counts[i] += b.counts[i];
    for (std::size_t i = 0; i < a.points.size(); ++i) a.points[i] += b.points[i];
    for (std::size_t i = 0; i < a.mode_counts.size(); ++i) a.mode_counts[i] += b.mode_counts[i];
    for (std::size_t i = 0; i < a.low.size(); ++i) {
        a.low[i] = std::min(a.low[i], b.low[i]);
        a.high[i] = std::max(a.high[i], b.high[i]);
    }
    if (r.kind == ReductionKind::top_k) {
        a.heap.insert(a.heap.end(), b.heap.begin(), b.heap.end());
        std::sort(a.heap.begin(), a.heap.end());
        if (a.heap.size() > static_cast<std::size_t>(r.k)) a.heap.resize(static_cast<std::size_t>(r.k));
        std::make_heap(a.heap.begin(), a.heap.end());
    }
}

}  // namespace epc_fast
