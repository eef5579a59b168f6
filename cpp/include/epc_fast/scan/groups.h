// A scan's group keys (python/epc_fast/scan/reductions/groups.py): which group each point of a
// block belongs to, from its discrete axes' indices and its parameters, for the per-group
// reductions (reductions.h). A key whose parts are all grid axes repeats with the grid: its groups
// are computed once, for one cycle of points (set_cycle).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../block.h"
#include "space.h"

namespace epc_fast {

// One part of a group key (python/epc_fast/scan/reductions/groups.py): a discrete axis's index, a
// value index looked up from the design index, or a parameter's bin (edges searched, or equal steps
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
//
// A key whose parts are all grid axes (or lookups of them) repeats with the grid: point i's
// group is cycle[i mod cycle.size()] (set_cycle). Its reductions then accumulate per position
// in the cycle with plain vector loops (states.h CycleSums) and fold the positions
// into their groups once per scan block. Empty: the key has no cycle of at most max_cycle
// points.
struct GroupKey {
    std::vector<KeyPart> parts;
    std::int64_t size = 1;
    std::vector<std::int32_t> cycle;
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

// Sets key.cycle: the groups of points 0 .. L - 1, L the least multiple of block_size (so that
// every kernel block starts a cycle's block) that the key's period divides. The period is the
// number of grid cells from the slowest grid axis the key reads (the grid's mixed radix, last
// axis fastest): 1 for a key without parts. Left empty when a part is not a grid axis's or L
// exceeds max_cycle.
inline void set_cycle(GroupKey& key, const ScanSpace& space) {
    key.cycle.clear();
    std::size_t slowest = space.grid_axes.size();
    for (const KeyPart& part : key.parts) {
        if (part.kind != KeyPart::axis && part.kind != KeyPart::lookup) return;
        const auto at = std::find(space.grid_axes.begin(), space.grid_axes.end(),
                                  static_cast<std::size_t>(part.axis_index));
        if (at == space.grid_axes.end()) return;  // a random choice
        slowest = std::min(slowest, static_cast<std::size_t>(at - space.grid_axes.begin()));
    }
    std::uint64_t period = 1;
    for (std::size_t k = slowest; k < space.grid_axes.size(); ++k) {
        period *= static_cast<std::uint64_t>(space.axes[space.grid_axes[k]].size);
        if (period > max_cycle) return;
    }
    const std::uint64_t length = cycle_length(period);
    if (length == 0) return;
    std::vector<std::int32_t> scratch(block_size);
    key.cycle.resize(length);
    for_grid_blocks(space, length, [&](const ScanLanes& lanes) {
        group_indices(key, space, lanes, key.cycle.data() + lanes.index[0], scratch.data());
    });
}

}  // namespace epc_fast
