// A scan's reductions, folded a block of points at a time while the block is in cache: per
// group (group keys: scan_groups.h) status counts, count/mean/std/min/max, histograms on fixed
// bins (equal in the value or its log10), the fraction below a threshold, and the k best points.
//
// Every state is exact or order-free (integer counts, min, max, the k best by a total order)
// except the mean and the squared deviations, which are accumulated in a fixed order into
// their scan block's moments: for a key with a cycle (GroupKey), per position of the cycle over
// the scan block, merged position by position at its end; otherwise 64 points (a kernel block)
// at a time, two-pass within them, merged one after the other (Chan et al.'s update). A scan
// block (scan_block_points) is folded by one thread, in point order, so its moments do not
// depend on the thread count or the chunk size; python/epc_fast/scan/summaries.py merges scan
// blocks in block order.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "block.h"
#include "scan_groups.h"
#include "scan_space.h"
#include "status.h"

namespace epc_fast {

// Points a scan block holds: the unit of the moments' merge order (scan.BLOCK_POINTS).
constexpr std::size_t scan_block_points = std::size_t{1} << 16;

enum class ReductionKind { summary, histogram, quantiles, fraction_below, top_k };

// One reduction of one output (`of`, an index into the outputs a scan reads: n_scan_outputs)
// per group of key `key`.
struct Reduction {
    ReductionKind kind = ReductionKind::summary;
    int of = 5;   // rate, electrons, T_MPE, blur, f50, EPC (Outputs order), then the shares
    int key = 0;  // index into the scan's keys (unused by top_k)
    std::int64_t groups = 1;
    // histogram: `bins` equal bins on t in [first, last), t the value or its log10 (histograms.py
    // _Bins); quantiles: `bins` octave bins, the keys first_key .. first_key + bins - 1 of a
    // value's bits shifted right by `shift` (histograms.py _OctaveBins). Slot 0 counts below,
    // slot bins + 1 at or above.
    double first = 0.0, last = 1.0;
    std::int32_t bins = 1;
    double bins_per_t = 1.0;  // bins / (last - first)
    bool log = false;
    std::int64_t first_key = 0;
    int shift = 52;
    double threshold = 0.0;  // fraction_below
    std::int64_t k = 1;      // top_k
    bool largest = true;
    std::size_t cycle = 0;   // the key's cycle length (GroupKey::cycle); 0 without one, and for
                             // a histogram, which keeps no sums per position

    std::int64_t slots() const { return bins + 2; }
};

// The k best points: (order key, point index), the smallest first; order key -value for the
// largest values, the value for the smallest. Ties go to the lower index.
using Candidate = std::pair<double, std::uint64_t>;

// A reduction's sums per position of its key's cycle over the scan block being folded (a
// position takes at most scan_block_points / block_size = 1024 of a scan block's points). Per
// kind (the rest stay empty):
//   summary         tally: its points per status and its finite points, five 12-bit counts
//                   packed in one integer (tally_bits); shift: the first finite value; the sums
//                   of the deviations from the shift and of their squares; min and max
//   quantiles       min and max
//   fraction_below  finite points, those below the threshold
struct CycleSums {
    std::vector<std::uint64_t> tally;
    std::vector<double> count, shift, sum, squares, low, high, below;

    void reset(std::size_t p) {
        if (!tally.empty()) tally[p] = 0;
        for (std::vector<double>* v : {&count, &shift, &sum, &squares, &below})
            if (!v->empty()) (*v)[p] = 0.0;
        if (!low.empty()) {
            low[p] = std::numeric_limits<double>::infinity();
            high[p] = -std::numeric_limits<double>::infinity();
        }
    }
};

// A summary's tally fields: status k (0 .. 3) counts in bits 12k .. 12k + 11, finite points in
// bits 48 .. 59.
constexpr int tally_bits = 12;
constexpr std::uint64_t tally_field = (std::uint64_t{1} << tally_bits) - 1;
static_assert(scan_block_points / block_size <= tally_field, "a position's points fit a field");

// One thread's state of one reduction over the points it folded.
struct ReductionState {
    std::vector<std::int64_t> counts;  // summary: (groups, 4) statuses; histogram, quantiles:
                                       // (groups, slots); fraction_below: (groups,) finite
    std::vector<std::int64_t> points;  // histogram: (groups,) points; fraction_below: below
    std::vector<double> low, high;     // summary, quantiles: finite min and max per group
    // summary: the moments of the scan block being folded, and one kernel block's
    std::vector<std::int64_t> block_count, sub_count;
    std::vector<double> block_mean, block_m2, sub_sum, sub_m2;
    std::vector<std::int32_t> touched;
    std::vector<Candidate> heap;  // top_k: a max-heap of the best k so far
    CycleSums cycle;              // with a key's cycle (Reduction::cycle)

    explicit ReductionState(const Reduction& r) {
        const auto g = static_cast<std::size_t>(r.groups);
        const std::size_t c = r.cycle;
        if (c > 0 && r.kind == ReductionKind::summary) {
            cycle.tally.assign(c, 0);
            for (std::vector<double>* v : {&cycle.shift, &cycle.sum, &cycle.squares, &cycle.low, &cycle.high})
                v->assign(c, 0.0);
        } else if (c > 0 && r.kind == ReductionKind::quantiles) {
            cycle.low.assign(c, 0.0);
            cycle.high.assign(c, 0.0);
        } else if (c > 0 && r.kind == ReductionKind::fraction_below) {
            cycle.count.assign(c, 0.0);
            cycle.below.assign(c, 0.0);
        }
        for (std::size_t p = 0; p < c; ++p) cycle.reset(p);
        switch (r.kind) {
            case ReductionKind::summary:
                counts.assign(g * n_status, 0);
                low.assign(g, inf_value());
                high.assign(g, -inf_value());
                block_count.assign(g, 0);
                sub_count.assign(g, 0);
                block_mean.assign(g, 0.0);
                block_m2.assign(g, 0.0);
                sub_sum.assign(g, 0.0);
                sub_m2.assign(g, 0.0);
                touched.reserve(block_size);
                break;
            case ReductionKind::histogram:
                counts.assign(g * static_cast<std::size_t>(r.slots()), 0);
                points.assign(g, 0);
                break;
            case ReductionKind::quantiles:
                counts.assign(g * static_cast<std::size_t>(r.slots()), 0);
                low.assign(g, inf_value());
                high.assign(g, -inf_value());
                break;
            case ReductionKind::fraction_below:
                counts.assign(g, 0);
                points.assign(g, 0);
                break;
            case ReductionKind::top_k:
                heap.reserve(static_cast<std::size_t>(std::min<std::int64_t>(r.k, 1 << 20)) + 1);
                break;
        }
    }

    static constexpr std::size_t n_status = 4;
    static double inf_value() { return std::numeric_limits<double>::infinity(); }
};

// The outputs a reduction can read, by its `of`: the kernel's six float64 outputs (Outputs
// order) and the four MTF-loss shares (Share order, sensitivity.h).
constexpr int n_scan_outputs = 6 + n_shares;

// What one kernel block gives the reductions: each lane's point index, status, group under
// each key, the outputs and, where a log-binned histogram needs it, log10 of an output.
struct FoldLanes {
    std::size_t n = 0;
    std::uint64_t first = 0;  // lane 0's point index, a multiple of block_size
    const std::uint64_t* index = nullptr;
    const unsigned char* status = nullptr;
    const double* outputs[n_scan_outputs] = {};
    const double* log10_outputs[n_scan_outputs] = {};
    std::vector<const std::int32_t*> groups;  // per key
};

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
    constexpr std::uint64_t finite_one = std::uint64_t{1} << (4 * tally_bits);
    // each lane's tally increment: its status's field, and the finite field if finite
    alignas(64) std::uint64_t add[block_size];
    // (statuses 0 .. 3: a scan has no lens tables, so never Status::beyond_table)
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
                for (std::size_t j = 0; j < ReductionState::n_status; ++j)
                    s.counts[k * ReductionState::n_status + j] +=
                        static_cast<std::int64_t>((tally >> (tally_bits * j)) & tally_field);
                const auto finite = static_cast<std::int64_t>((tally >> (4 * tally_bits)) & tally_field);
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
