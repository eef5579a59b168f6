// A scan's reductions, folded a block of points at a time while the block is in cache: per
// group (group keys below) status counts, count/mean/std/min/max, histograms on fixed bins
// (equal in the value or its log10), the fraction below a threshold, and the k best points.
//
// Every state is exact or order-free (integer counts, min, max, the k best by a total order)
// except the mean and the squared deviations, which are accumulated in a fixed order: 64
// points (a kernel block) at a time, two-pass within them, merged one after the other into
// their scan block's moments (Chan et al.'s update). A scan block (scan_block_points) is
// folded by one thread, in point order, so its moments do not depend on the thread count or
// the chunk size; python/epc_fast/scan/summaries.py merges scan blocks in block order.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "block.h"
#include "scan_space.h"
#include "status.h"

namespace epc_fast {

// Points a scan block holds: the unit of the moments' merge order (scan.BLOCK_POINTS).
constexpr std::size_t scan_block_points = std::size_t{1} << 16;

// One part of a group key (python/epc_fast/scan/groups.py): a discrete axis's index, a value
// index looked up from the design index, or a parameter's bin (edges searched, or equal steps
// in log10 found arithmetically).
struct KeyPart {
    enum Kind { axis, lookup, binned, binned_log };
    Kind kind = axis;
    int axis_index = -1;  // axis, lookup: index into ScanSpace::axes
    int param = -1;       // binned, binned_log
    std::int32_t size = 1;
    std::vector<std::int32_t> lookup_table;  // lookup: axis index -> group part
    std::vector<double> inner_edges;         // binned: edges[1 .. -2]
    double first = 0.0, scale = 1.0;         // binned_log: log10 of the first edge, 1 / step
};

// Groups are the parts' indices in mixed radix, the last part fastest; no parts: one group.
struct GroupKey {
    std::vector<KeyPart> parts;
    std::int64_t size = 1;
};

namespace detail {

// The part's index of each of the lanes' n points.
inline void part_indices(const KeyPart& part, const ScanSpace& space, const ScanLanes& lanes,
                         std::int32_t* __restrict out) {
    const std::size_t n = lanes.n;
    switch (part.kind) {
        case KeyPart::axis: {
            const std::int32_t* k = lanes.axis_index[static_cast<std::size_t>(part.axis_index)].data();
            for (std::size_t i = 0; i < n; ++i) out[i] = k[i];
            return;
        }
        case KeyPart::lookup: {
            const std::int32_t* k = lanes.axis_index[static_cast<std::size_t>(part.axis_index)].data();
            for (std::size_t i = 0; i < n; ++i) out[i] = part.lookup_table[static_cast<std::size_t>(k[i])];
            return;
        }
        default:
            break;
    }
    const ParamSource& p = space.params[part.param];
    const bool fixed = p.kind == ParamSource::fixed;
    const double* x = lanes.values[part.param];
    for (std::size_t i = 0; i < n; ++i) {
        const double v = fixed ? p.value : x[i];
        if (part.kind == KeyPart::binned) {  // np.searchsorted(inner_edges, v, side="right")
            const auto at = std::upper_bound(part.inner_edges.begin(), part.inner_edges.end(), v);
            out[i] = static_cast<std::int32_t>(at - part.inner_edges.begin());
        } else {  // groups.py _part_indices: floor of the clipped position in bins
            double position = (std::log10(v > 0.0 ? v : 0.0) - part.first) * part.scale;
            const double top = static_cast<double>(part.size - 1);
            position = position >= 0.0 ? (position <= top ? position : top) : 0.0;  // NaN: 0
            out[i] = static_cast<std::int32_t>(position);
        }
    }
}

}  // namespace detail

// Each lane's group under `key` (int32: python refuses keys of 2^31 groups or more).
inline void group_indices(const GroupKey& key, const ScanSpace& space, const ScanLanes& lanes,
                          std::int32_t* __restrict group, std::int32_t* __restrict scratch) {
    const std::size_t n = lanes.n;
    for (std::size_t i = 0; i < n; ++i) group[i] = 0;
    for (const KeyPart& part : key.parts) {
        detail::part_indices(part, space, lanes, scratch);
        for (std::size_t i = 0; i < n; ++i) group[i] = group[i] * part.size + scratch[i];
    }
}

enum class ReductionKind { summary, histogram, quantiles, fraction_below, top_k };

// One reduction of one output (`of`, an index into the kernel's six float outputs) per group
// of key `key`.
struct Reduction {
    ReductionKind kind = ReductionKind::summary;
    int of = 5;   // Outputs order: rate, electrons, T_MPE, blur, f50, EPC
    int key = 0;  // index into the scan's keys (unused by top_k)
    std::int64_t groups = 1;
    // histogram and quantiles: `bins` equal bins on t in [first, last), t the value or its
    // log10; slot 0 counts below, slot bins + 1 at or above (histograms.py _Bins)
    double first = 0.0, last = 1.0;
    std::int32_t bins = 1;
    double bins_per_t = 1.0;  // bins / (last - first)
    bool log = false;
    double threshold = 0.0;  // fraction_below
    std::int64_t k = 1;      // top_k
    bool largest = true;

    std::int64_t slots() const { return bins + 2; }
};

// The k best points: (order key, point index), the smallest first; order key -value for the
// largest values, the value for the smallest. Ties go to the lower index.
using Candidate = std::pair<double, std::uint64_t>;

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

    explicit ReductionState(const Reduction& r) {
        const auto g = static_cast<std::size_t>(r.groups);
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

// What one kernel block gives the reductions: each lane's point index, status, group under
// each key, the outputs and, where a log-binned reduction needs it, log10 of an output.
struct FoldLanes {
    std::size_t n = 0;
    const std::uint64_t* index = nullptr;
    const unsigned char* status = nullptr;
    const double* outputs[6] = {};
    const double* log10_outputs[6] = {};
    std::vector<const std::int32_t*> groups;  // per key
};

namespace detail {

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
// first)) + 1, clipped to [0, bins + 1]; t = -inf (log10 of 0) is slot 0.
EPC_FAST_INLINE std::int64_t slot_of(const Reduction& r, double t) {
    double position = t - r.first;
    position *= r.bins_per_t;
    position += 1.0;
    const double top = static_cast<double>(r.bins) + 1.0;
    position = position >= 0.0 ? (position <= top ? position : top) : 0.0;
    return static_cast<std::int64_t>(position);
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
            const bool in = (i < n) & (g[i] == k) & (std::fabs(v[i]) <= std::numeric_limits<double>::max());
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
            const bool in = (i < n) & (g[i] == k) & (std::fabs(v[i]) <= std::numeric_limits<double>::max());
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

inline void fold_histogram(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    const double* __restrict v = f.outputs[r.of];
    const double* __restrict t = r.log ? f.log10_outputs[r.of] : v;
    const std::int32_t* g = f.groups[static_cast<std::size_t>(r.key)];
    const auto slots = static_cast<std::size_t>(r.slots());
    const bool with_range = r.kind == ReductionKind::quantiles;
    alignas(64) std::int64_t slot[block_size];  // every lane's slot, in a vector loop
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) slot[i] = slot_of(r, t[i]);
    for (std::size_t i = 0; i < f.n; ++i) {
        const auto k = static_cast<std::size_t>(g[i]);
        if (!with_range) ++s.points[k];
        if (!std::isfinite(v[i])) continue;
        ++s.counts[k * slots + static_cast<std::size_t>(slot[i])];
        if (with_range) {
            s.low[k] = v[i] < s.low[k] ? v[i] : s.low[k];
            s.high[k] = v[i] > s.high[k] ? v[i] : s.high[k];
        }
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

}  // namespace detail

// Folds one kernel block into a thread's state of reduction r.
inline void fold(const Reduction& r, const FoldLanes& f, ReductionState& s) {
    switch (r.kind) {
        case ReductionKind::summary: detail::fold_summary(r, f, s); return;
        case ReductionKind::histogram:
        case ReductionKind::quantiles: detail::fold_histogram(r, f, s); return;
        case ReductionKind::fraction_below: detail::fold_fraction_below(r, f, s); return;
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
