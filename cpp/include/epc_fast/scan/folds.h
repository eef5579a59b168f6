// The folds of one kernel block into a thread's reduction states (reductions.h, whose
// header says what they keep and in which order): counts, moments, ranges and fractions,
// without and with a key's cycle (groups.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "../block.h"
#include "../status.h"
#include "groups.h"
#include "states.h"

namespace epc_fast {
namespace detail {

// Whether lane i of a kernel block of n points holds a point whose value x is finite: the
// points that moments, ranges, fractions and histograms count.
EPC_FAST_INLINE bool counted(std::size_t i, std::size_t n, double x) {
    return (i < n) & (std::fabs(x) <= std::numeric_limits<double>::max());
}

// Chan et al.'s update of (count, mean, m2) by another set's (count_b, mean_b, m2_b): the
// formula of summaries.py _Moments.add.
EPC_FAST_INLINE void merge_moments(std::int64_t& count, double& mean, double& m2,
                                   std::int64_t count_b, double mean_b, double m2_b) {
    const std::int64_t total = count + count_b;
    const double weight = static_cast<double>(count_b) / static_cast<double>(total);
    const double delta = mean_b - mean;
    mean += delta * weight;
    m2 += m2_b + delta * delta * static_cast<double>(count) * weight;
    count = total;
}

// The slot of t on the bins (histograms.py _Bins.slot): floor((t - first) bins / (last -
// first)) + 1, clipped to [0, bins + 1]; t = -inf (log10 of 0) is slot 0. As a double, an
// integer, so that a lane loop over it vectorises without 64-bit integer conversions (AVX2
// has none).
EPC_FAST_INLINE double slot_of(const Reduction& r, double t) {
    double position = t - r.first;
    position *= r.bins_per_t;
    position += 1.0;
    const double top = static_cast<double>(r.bins) + 1.0;
    position = position >= 0.0 ? (position <= top ? position : top) : 0.0;
    return std::floor(position);
}

// The slot of value v on quantiles' octave bins (histograms.py _OctaveBins.slot): v's key, its
// bits shifted right by `shift`, less first_key, plus 1, clipped to [0, bins + 1]; 0 for v <= 0
// or NaN. The key (below 2^52: shift >= 12) becomes a double exactly through the bits of
// 2^52 + key, and the rest is integer arithmetic on exact doubles: NumPy's integers give the
// same slot. A double, as slot_of's, so that the lane loop vectorises on AVX2 too.
EPC_FAST_INLINE double octave_slot_of(const Reduction& r, double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    const std::uint64_t key_bits = 0x4330000000000000u | (bits >> r.shift);
    double key = 0.0;
    std::memcpy(&key, &key_bits, sizeof key);
    double position = (key - 0x1p52) - static_cast<double>(r.first_key - 1);
    const double top = static_cast<double>(r.bins) + 1.0;
    position = position >= 0.0 ? (position <= top ? position : top) : 0.0;
    return v > 0.0 ? position : 0.0;
}

// Groups up to this many are summarised group by group with vector loops over the block's
// lanes (fold_summary_few); more, lane by lane with the groups each lane touches.
constexpr std::int64_t few_groups = 8;

// fold_summary's moments for a key of few groups: for each group, its lanes' count, sum, min
// and max, then their squared deviations from the mean, each a masked vector reduction over
// the 64 lanes (the same order for every block: the results depend only on the lanes' values).
inline void fold_moments_few(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const double* __restrict v = f.outputs[r.of];
    const std::int32_t* __restrict g = f.groups[static_cast<std::size_t>(r.key)];
    const std::size_t n = f.n;
    for (std::int32_t k = 0; k < static_cast<std::int32_t>(r.groups); ++k) {
        std::int64_t count = 0;
        double sum = 0.0, low = s.low[static_cast<std::size_t>(k)], high = s.high[static_cast<std::size_t>(k)];
        EPC_FAST_PRAGMA(omp simd reduction(+ : count, sum) reduction(min : low) reduction(max : high))
        for (std::size_t i = 0; i < block_size; ++i) {
            const bool in = counted(i, n, v[i]) & (g[i] == k);
            count += in;
            sum += in ? v[i] : 0.0;
            low = in && v[i] < low ? v[i] : low;
            high = in && v[i] > high ? v[i] : high;
        }
        if (count == 0) continue;
        const double mean = sum / static_cast<double>(count);
        double m2 = 0.0;
        EPC_FAST_SIMD_REDUCTION(+ : m2)
        for (std::size_t i = 0; i < block_size; ++i) {
            const bool in = counted(i, n, v[i]) & (g[i] == k);
            const double d = in ? v[i] - mean : 0.0;
            m2 += d * d;
        }
        const auto kk = static_cast<std::size_t>(k);
        s.low[kk] = low;
        s.high[kk] = high;
        merge_moments(s.block_count[kk], s.block_mean[kk], s.block_m2[kk], count, mean, m2);
    }
}

inline void fold_summary(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const double* v = f.outputs[r.of];
    const std::int32_t* g = f.groups[static_cast<std::size_t>(r.key)];
    for (std::size_t i = 0; i < f.n; ++i)
        ++s.counts[static_cast<std::size_t>(g[i]) * ReductionState::n_status + f.status[i]];
    if (r.modes > 0) {  // each point's picked mode, column 0 for none (mode -1)
        const auto width = static_cast<std::size_t>(r.modes + 1);
        for (std::size_t i = 0; i < f.n; ++i)
            ++s.mode_counts[static_cast<std::size_t>(g[i]) * width + static_cast<std::size_t>(f.mode[i] + 1)];
    }
    if (r.groups <= few_groups) {
        fold_moments_few(r, f, s);
        return;
    }
    // this kernel block's count and mean per group, then its squared deviations (two passes
    // over 64 values in cache), merged into the scan block's moments group by group
    s.touched.clear();
    for (std::size_t i = 0; i < f.n; ++i) {
        if (!std::isfinite(v[i])) continue;
        const auto k = static_cast<std::size_t>(g[i]);
        if (s.sub_count[k] == 0) s.touched.push_back(g[i]);
        ++s.sub_count[k];
        s.sub_sum[k] += v[i];
        s.low[k] = v[i] < s.low[k] ? v[i] : s.low[k];
        s.high[k] = v[i] > s.high[k] ? v[i] : s.high[k];
    }
    for (std::int32_t k : s.touched)
        s.sub_sum[static_cast<std::size_t>(k)] /= static_cast<double>(s.sub_count[static_cast<std::size_t>(k)]);
    for (std::size_t i = 0; i < f.n; ++i) {
        if (!std::isfinite(v[i])) continue;
        const auto k = static_cast<std::size_t>(g[i]);
        const double d = v[i] - s.sub_sum[k];
        s.sub_m2[k] += d * d;
    }
    for (std::int32_t t : s.touched) {
        const auto k = static_cast<std::size_t>(t);
        merge_moments(s.block_count[k], s.block_mean[k], s.block_m2[k], s.sub_count[k],
                      s.sub_sum[k], s.sub_m2[k]);
        s.sub_count[k] = 0;
        s.sub_sum[k] = 0.0;
        s.sub_m2[k] = 0.0;
    }
}

inline void fold_fraction_below(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const double* v = f.outputs[r.of];
    const std::int32_t* g = f.groups[static_cast<std::size_t>(r.key)];
    for (std::size_t i = 0; i < f.n; ++i) {
        if (!std::isfinite(v[i])) continue;
        const auto k = static_cast<std::size_t>(g[i]);
        ++s.counts[k];
        s.points[k] += v[i] < r.threshold;
    }
}

inline void fold_top_k(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const double* v = f.outputs[r.of];
    const auto k = static_cast<std::size_t>(r.k);
    for (std::size_t i = 0; i < f.n; ++i) {
        if (!std::isfinite(v[i])) continue;
        const Candidate c{r.largest ? -v[i] : v[i], f.index[i]};
        if (s.heap.size() < k) {
            s.heap.push_back(c);
            std::push_heap(s.heap.begin(), s.heap.end());
        } else if (c < s.heap.front()) {
            std::pop_heap(s.heap.begin(), s.heap.end());
            s.heap.back() = c;
            std::push_heap(s.heap.begin(), s.heap.end());
        }
    }
}

// The kernel block's position in its key's cycle: its lanes are positions p .. p + 63.
EPC_FAST_INLINE std::size_t cycle_position(const Reduction& r, const FoldLanes& f) {
    return static_cast<std::size_t>(f.first % r.cycle);
}

// fold_summary with a cycle: each lane's values added to its position's sums, one vector loop.
// A position's deviations are taken from its first finite value in the scan block, a value of
// the same group, so that the sum of squares loses little to cancellation (flush_cycle).
inline void fold_summary_cycle(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const std::size_t p = cycle_position(r, f), n = f.n;
    CycleSums& c = s.cycle;
    const double* __restrict v = f.outputs[r.of];
    const unsigned char* __restrict status = f.status;
    std::uint64_t* __restrict tally = c.tally.data() + p;
    double* __restrict shift = c.shift.data() + p;
    double* __restrict sum = c.sum.data() + p;
    double* __restrict squares = c.squares.data() + p;
    double* __restrict low = c.low.data() + p;
    double* __restrict high = c.high.data() + p;
    constexpr std::uint64_t finite_one = std::uint64_t{1} << (tally_statuses * tally_bits);
    // each lane's tally increment: its status's field, and the finite field if finite
    alignas(64) std::uint64_t add[block_size];
    // (statuses 0 .. 3: a scan with lens tables, which may give Status::beyond_table, folds
    // its summaries without the cycle)
    for (std::size_t i = 0; i < block_size; ++i) add[i] = status[i] & 3u;  // widened
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const std::uint64_t k = add[i];
        const std::uint64_t status_one = (k == 0 ? std::uint64_t{1} : 0) + (k == 1 ? std::uint64_t{1} << tally_bits : 0) +
                                         (k == 2 ? std::uint64_t{1} << (2 * tally_bits) : 0) +
                                         (k == 3 ? std::uint64_t{1} << (3 * tally_bits) : 0);
        add[i] = (i < n ? status_one : 0) + (counted(i, n, v[i]) ? finite_one : 0);
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double x = v[i];
        const bool in = add[i] >= finite_one;
        const double from = tally[i] >= finite_one ? shift[i] : x;  // a finite point before
        const double d = in ? x - from : 0.0;
        shift[i] = from;  // x itself (unused until a finite point comes) or the kept shift
        tally[i] += add[i];
        sum[i] += d;
        squares[i] += d * d;
        low[i] = in && x < low[i] ? x : low[i];
        high[i] = in && x > high[i] ? x : high[i];
    }
}

// fold_fraction_below with a cycle.
inline void fold_fraction_below_cycle(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const std::size_t p = cycle_position(r, f), n = f.n;
    const double* __restrict v = f.outputs[r.of];
    double* __restrict count = s.cycle.count.data() + p;
    double* __restrict below = s.cycle.below.data() + p;
    const double threshold = r.threshold;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const bool in = counted(i, n, v[i]);
        count[i] += in ? 1.0 : 0.0;
        below[i] += in && v[i] < threshold ? 1.0 : 0.0;
    }
}

// The quantiles' finite min and max with a cycle.
inline void fold_range_cycle(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const std::size_t p = cycle_position(r, f), n = f.n;
    const double* __restrict v = f.outputs[r.of];
    double* __restrict low = s.cycle.low.data() + p;
    double* __restrict high = s.cycle.high.data() + p;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const bool in = counted(i, n, v[i]);
        low[i] = in && v[i] < low[i] ? v[i] : low[i];
        high[i] = in && v[i] > high[i] ? v[i] : high[i];
    }
}

}  // namespace detail
}  // namespace epc_fast
