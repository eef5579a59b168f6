// A scan's reductions' states: what each reduction (Reduction) of a scan keeps per group over
// the points a thread folded (ReductionState), its sums per position of a key's cycle
// (CycleSums), and what one kernel block gives the folds (FoldLanes). The folds:
// folds.h and reductions.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "../block.h"
#include "../params.h"

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
    std::int64_t modes = 0;  // summary: the readout modes whose picks it counts (0: none)

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
// bits 48 .. 59. Status::beyond_table has no field: a scan with lens tables folds its
// summaries without the cycle (register_scan.cpp).
constexpr int tally_bits = 12;
constexpr std::size_t tally_statuses = 4;
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
    // summary with readout modes: (groups, modes + 1) points per picked mode, column 0 none
    std::vector<std::int64_t> mode_counts;

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
                mode_counts.assign(r.modes > 0 ? g * static_cast<std::size_t>(r.modes + 1) : 0, 0);
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

    // the statuses a scan's core counts: 0 .. 4 (Status::beyond_table with lens tables; a frame
    // cap's exposure_limit is the arrays')
    static constexpr std::size_t n_status = 5;
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
    const std::int16_t* mode = nullptr;  // each point's readout mode (no_mode: none); null without
    const double* outputs[n_scan_outputs] = {};
    const double* log10_outputs[n_scan_outputs] = {};
    std::vector<const std::int32_t*> groups;  // per key
};

}  // namespace epc_fast
