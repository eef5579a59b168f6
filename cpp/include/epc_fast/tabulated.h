// Tabulated MTFs (docs/model.md, "Tabulated MTFs"; python/epc_fast/mtf_table.py checks and
// builds them): a falling curve interpolated by the monotone piecewise cubic of Fritsch and
// Carlson, each segment k stored as y_k + d_k s + c2_k s^2 + c3_k s^3 in s = f - f_k, so that
// the core evaluates the NumPy reference's polynomial. Past the last frequency it holds its last
// value.
//
// A lookup finds a frequency's segment in O(1): a uniform grid over [0, f_m] stores, per cell,
// a segment at or below every frequency in the cell, and a fixed number of forward steps
// (`steps`, usually 1) reaches the segment std::upper_bound would give. The lane loops
// (table_lanes) are branch-free passes that vectorise with gathers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "constants.h"
#include "parallel.h"

namespace epc_fast {

struct FittedStart;  // f50/guesses.h
struct PixelStart;   // f50/demosaic_fit.h

struct MtfTable {
    std::vector<double> knots;         // f_0 = 0 < f_1 < ... < f_m
    std::vector<double> coefficients;  // 4 per segment: y_k, d_k, c2_k, c3_k
    double last_value = 0.0;           // the MTF at f_m
    double end = 0.0;   // where f50's bracket ends on it: its first knot of MTF 0, else f_m
    double half = 0.0;  // where it falls to 1/2 (f_m if it never does): f50's start's scale
    // the interpolant at end (1 - 1e-6), at least its value anywhere from there on (it never
    // rises): a bound on the table's factor at f50's bracket end (f50/stage.h beyond_tables)
    double near_end = 0.0;
    // the lookup grid (finish_table): cell j = floor(f cells_per_unit) of [0, f_m] starts its
    // search at segment first_segment[j]; `steps` forward steps reach any f's segment
    double cells_per_unit = 0.0;
    std::vector<std::int32_t> first_segment;
    int steps = 0;
    // a lens table's fitted f50 start (f50/lens_fit.h; null: none, or not a lens's table)
    std::shared_ptr<const FittedStart> start;
    // a demosaicker's table's fitted f50 start (f50/demosaic_fit.h; null: none, or not one)
    std::shared_ptr<const PixelStart> pixel_start;
};

// The most cells a table's grid has: twice as many cells as the table's narrowest segment
// fits, up to this.
constexpr std::size_t max_table_cells = 4096;

// f's cell of the grid: floor(f cells_per_unit) within [0, last_cell] (NaN: 0).
EPC_FAST_INLINE std::int32_t grid_cell(double f, double cells_per_unit, std::int32_t last_cell) {
    const double g = f * cells_per_unit;
    return g >= static_cast<double>(last_cell) ? last_cell : g > 0.0 ? static_cast<std::int32_t>(g) : 0;
}

// f's segment k (0 <= k < m): the last knot <= f, and m - 1 at or past f_m (std::upper_bound's,
// found from the grid in `steps` branch-free steps). NaN takes segment 0's cell.
EPC_FAST_INLINE std::int32_t table_segment(const MtfTable& t, double f) {
    const std::int32_t m = static_cast<std::int32_t>(t.knots.size()) - 1;
    const std::int32_t last_cell = static_cast<std::int32_t>(t.first_segment.size()) - 1;
    std::int32_t k = t.first_segment[static_cast<std::size_t>(grid_cell(f, t.cells_per_unit, last_cell))];
    for (int step = 0; step < t.steps; ++step)
        k += static_cast<std::int32_t>((k + 1 < m) & (f >= t.knots[static_cast<std::size_t>(k + 1)]));
    return k;
}

// The interpolant and its first two derivatives in f.
struct TableValue {
    double value, d1, d2;
};

// A segment's cubic y + d s + c2 s^2 + c3 s^3 (its coefficients c) and its two derivatives at s:
// the one arithmetic of `tabulated` and table_lanes, so that both give the same bits.
EPC_FAST_INLINE TableValue segment_cubic(const double* c, double s) {
    return {c[0] + s * (c[1] + s * (c[2] + s * c[3])), c[1] + s * (2.0 * c[2] + 3.0 * c[3] * s),
            2.0 * c[2] + 6.0 * c[3] * s};
}

inline TableValue tabulated(const MtfTable& t, double f) {
    const std::size_t m = t.knots.size() - 1;  // segments
    if (f > t.knots[m]) return {t.last_value, 0.0, 0.0};
    const std::size_t k = static_cast<std::size_t>(table_segment(t, f));
    return segment_cubic(&t.coefficients[4 * k], f - t.knots[k]);
}

// The interpolant at the first n <= MaxLanes of f into value (and with Slopes its derivatives
// into d1, d2), as `tabulated` gives them lane by lane, bit for bit: the segments in passes over the
// lanes (the grid's cell, then each step), then the cubic's gathered coefficients.
template <std::size_t MaxLanes, bool Slopes>
EPC_FAST_INLINE void table_lanes(const MtfTable& t, const double* __restrict f, std::size_t n,
                                 double* __restrict value, double* __restrict d1,
                                 double* __restrict d2) {
    const std::int32_t m = static_cast<std::int32_t>(t.knots.size()) - 1;
    const std::int32_t last_cell = static_cast<std::int32_t>(t.first_segment.size()) - 1;
    const double* __restrict knots = t.knots.data();
    const double* __restrict c = t.coefficients.data();
    const std::int32_t* __restrict first = t.first_segment.data();
    const double per_unit = t.cells_per_unit, f_m = knots[m], last_value = t.last_value;
    alignas(64) std::int32_t k[MaxLanes];
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) k[i] = first[grid_cell(f[i], per_unit, last_cell)];
    for (int step = 0; step < t.steps; ++step) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const std::int32_t next = k[i] + 1 < m ? k[i] + 1 : m;
            k[i] += static_cast<std::int32_t>((k[i] + 1 < m) & (f[i] >= knots[next]));
        }
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const TableValue v = segment_cubic(c + 4 * k[i], f[i] - knots[k[i]]);
        const bool past = f[i] > f_m;
        value[i] = past ? last_value : v.value;
        if (Slopes) {
            d1[i] = past ? 0.0 : v.d1;
            d2[i] = past ? 0.0 : v.d2;
        }
    }
}

// The lookup grid of a table whose knots are set: cells of width f_m / cells, each starting at
// the segment of its left edge less a margin (a cell an f lands in by rounding starts no
// higher than f's segment), and the most knots past that start any cell can reach, as steps.
inline void table_grid(MtfTable& t) {
    const std::size_t m = t.knots.size() - 1;
    const double f_m = t.knots[m];
    double narrowest = f_m;
    for (std::size_t k = 1; k <= m; ++k) narrowest = std::min(narrowest, t.knots[k] - t.knots[k - 1]);
    const double wanted = std::ceil(2.0 * f_m / narrowest);
    const std::size_t cells = wanted >= static_cast<double>(max_table_cells) ? max_table_cells
                              : wanted >= 1.0 ? static_cast<std::size_t>(wanted) : 1;
    t.cells_per_unit = static_cast<double>(cells) / f_m;
    const double width = f_m / static_cast<double>(cells), margin = 1e-9 * f_m;
    t.first_segment.assign(cells, 0);
    int steps = 0;
    // both ends only move up from cell to cell: one sweep of the knots, O(cells + m)
    std::size_t k = 0, reach = 0;
    for (std::size_t j = 0; j < cells; ++j) {
        const double left = static_cast<double>(j) * width - margin;
        const double right = static_cast<double>(j + 1) * width + margin;
        while (k + 1 < m && t.knots[k + 1] <= left) ++k;
        t.first_segment[j] = static_cast<std::int32_t>(k);
        reach = std::max(reach, k);
        while (reach + 1 < m && t.knots[reach + 1] <= right) ++reach;
        steps = std::max(steps, static_cast<int>(reach - k));
    }
    // the last cell also holds f_m and beyond (and NaN the first): no more steps than the
    // knots past its start, which the count above includes
    t.steps = steps;
}

// `end` and `half` of a table whose knots, coefficients and last value are set. The interpolant
// never rises (the Python side refuses a table that does), so its 1/2 crossing is found by
// bisection to adjacent doubles.
inline void finish_table(MtfTable& t) {
    table_grid(t);
    const std::size_t m = t.knots.size() - 1;
    t.end = t.knots[m];
    for (std::size_t k = 1; k <= m; ++k) {
        const double v = k < m ? t.coefficients[4 * k] : t.last_value;
        if (v == 0.0) {
            t.end = t.knots[k];
            break;
        }
    }
    t.near_end = tabulated(t, t.end * (1.0 - 1e-6)).value;
    if (!(tabulated(t, t.end).value < 0.5)) {
        t.half = t.end;
        return;
    }
    double lo = 0.0, hi = t.end;
    for (int step = 0; step < 2200; ++step) {
        const double mid = lo + 0.5 * (hi - lo);
        if (!(mid > lo && mid < hi)) break;
        (tabulated(t, mid).value > 0.5 ? lo : hi) = mid;
    }
    t.half = hi;
}

}  // namespace epc_fast
