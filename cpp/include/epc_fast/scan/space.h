// A scan's design space as the core forms it, a block of points at a time: each parameter
// fixed, drawn (philox.h or sobol_points.h, then draws.h), or read from a discrete axis (a grid
// axis visited in mixed radix, a random choice, or the design axis with its table of
// parameters).
//
// python/epc_fast/scan/running/core_plan.py builds a ScanSpace from a Space; docs/scan.md states
// the draw contract. A point's parameters depend only on the seed and its index.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../block.h"
#include "../params.h"
#include "draws.h"
#include "philox.h"
#include "sobol_points.h"

namespace epc_fast {

// A grid axis (point i is grid cell i mod grid size, mixed radix, last axis fastest) or a
// random choice among `size` values (equal weights, or the cumulative weights c[0..size-2]).
struct DiscreteAxis {
    bool grid = true;
    std::int64_t size = 1;
    std::uint32_t stream = 0;
    std::uint32_t dimension = 0;  // a random choice's Sobol' dimension
    std::vector<double> cumulative;
};

// How one parameter is formed: a fixed value, a draw, or the value of a discrete axis's index.
struct ParamSource {
    enum Kind { fixed, drawn, axis_value };
    Kind kind = fixed;
    double value = 0.0;          // fixed
    std::uint32_t stream = 0;    // drawn
    std::uint32_t dimension = 0; // drawn: its Sobol' dimension
    Draw draw;                   // drawn
    int axis = -1;               // axis_value: index into ScanSpace::axes
    std::vector<double> values;  // axis_value: the parameter at each of the axis's indices
    // axis_value on a grid axis: the parameter at points 0 .. cycle + block_size - 1, whose
    // slice from (i mod cycle) gives the block of consecutive points from i (set_cycles);
    // empty otherwise
    std::vector<double> by_cycle;
};

// The longest cycle of grid cells that a scan keeps tables over (the grid's cycle: the least
// multiple of block_size that the number of cells divides): each table holds a double per
// point of it, per parameter or reduction.
constexpr std::uint64_t max_cycle = 4096;

struct ScanSpace {
    // the domains, the size flag and the spectrum; its columns are set per block (ScanLanes)
    Inputs inputs;
    std::array<ParamSource, n_params> params;
    std::vector<DiscreteAxis> axes;
    std::uint64_t seed = 0;
    // the grid axes' positions in `axes`, in order, and the number of grid cells (set_grid)
    std::vector<std::size_t> grid_axes;
    std::uint64_t grid_cells = 1;
    std::uint64_t cycle = 0;  // the grid's cycle, 0 above max_cycle (set_cycles)
    // Sobol' sampling (off: Monte Carlo): the replicate is the digit of the grid axis
    // `replicate_axis` (the slowest, python/epc_fast/scan/sampling/qmc.py), -1 for one replicate
    SobolSampling sobol;
    int replicate_axis = -1;

    void set_grid() {
        grid_axes.clear();
        grid_cells = 1;
        for (std::size_t a = 0; a < axes.size(); ++a) {
            if (!axes[a].grid) continue;
            grid_axes.push_back(a);
            // saturated at 2^63: point indices are below it, so i mod cells is i either way
            const auto size = static_cast<std::uint64_t>(axes[a].size);
            grid_cells = grid_cells > (std::uint64_t{1} << 63) / size ? std::uint64_t{1} << 63
                                                                    : grid_cells * size;
        }
    }
};

// One block's points: their indices, each discrete axis's index and each parameter's value.
struct ScanLanes {
    std::size_t n = 0;
    alignas(64) std::uint64_t index[block_size];
    alignas(64) double u[block_size];
    alignas(64) std::uint32_t sobol_k[block_size];  // each point's index in its cell and replicate
    SobolLanes sobol;
    alignas(64) double values[n_params][block_size];
    std::vector<std::array<std::int32_t, block_size>> axis_index;

    explicit ScanLanes(const ScanSpace& space) : axis_index(space.axes.size()) {}
};

namespace detail {

// The index of a choice axis at uniform u (docs/scan.md).
inline std::int32_t choice_index(const DiscreteAxis& axis, double u) {
    if (axis.cumulative.empty()) {
        const auto k = static_cast<std::int64_t>(u * static_cast<double>(axis.size));
        return static_cast<std::int32_t>(k < axis.size ? k : axis.size - 1);
    }
    // the number of cumulative weights at or below u, by bisection
    std::int32_t lo = 0, hi = static_cast<std::int32_t>(axis.cumulative.size());
    while (lo < hi) {
        const std::int32_t mid = (lo + hi) / 2;
        if (axis.cumulative[static_cast<std::size_t>(mid)] <= u) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

// floor(a / m) for integers 0 <= a < 2^51 and m >= 1, in doubles: (a + 1/2) / m lies at least
// 1/(2m) from an integer, and (a + 1/2) times 1/m rounded is within 2^-51 a / m of it, less
// than that distance while a < 2^51; so floor gives the quotient exactly. Plain arithmetic, so
// that the lane loops below vectorise (x86 has no vector integer division).
EPC_FAST_INLINE double floor_div(double a, double inverse_m) {
    return std::floor((a + 0.5) * inverse_m);
}

// The grid axes' digits of every lane (mixed radix, the last axis fastest): each lane's cell
// (its index mod the number of cells, from the first lane's when the indices are consecutive)
// divided out axis by axis.
inline void grid_digits(const ScanSpace& space, bool consecutive, ScanLanes& lanes) {
    const std::vector<std::size_t>& grid = space.grid_axes;
    if (grid.empty()) return;
    const std::uint64_t cells = space.grid_cells;
    if (cells >= (std::uint64_t{1} << 51)) {  // beyond floor_div's range: integer division
        for (std::size_t i = 0; i < block_size; ++i) {
            std::uint64_t cell = lanes.index[i] % cells;
            for (std::size_t k = grid.size(); k-- > 0;) {
                const auto size = static_cast<std::uint64_t>(space.axes[grid[k]].size);
                lanes.axis_index[grid[k]][i] = static_cast<std::int32_t>(cell % size);
                cell /= size;
            }
        }
        return;
    }
    alignas(64) double cell[block_size];
    const double g = static_cast<double>(cells), inverse_g = 1.0 / g;
    if (consecutive) {
        // the lanes' cells count up from the first's, wrapping at g (exact doubles below 2^51)
        const double first = static_cast<double>(lanes.index[0] % cells);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) {
            const double c = first + static_cast<double>(i);
            cell[i] = c - g * floor_div(c, inverse_g);
        }
    } else {
        for (std::size_t i = 0; i < block_size; ++i)
            cell[i] = static_cast<double>(lanes.index[i] % cells);
    }
    double stride = 1.0;  // cells per step of the axis: the product of the later axes' sizes
    for (std::size_t k = grid.size(); k-- > 0;) {
        const std::size_t a = grid[k];
        const double size = static_cast<double>(space.axes[a].size);
        const double inverse_stride = 1.0 / stride, inverse_size = 1.0 / size;
        std::int32_t* __restrict digit = lanes.axis_index[a].data();
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) {
            const double q = floor_div(cell[i], inverse_stride);
            digit[i] = static_cast<std::int32_t>(q - size * floor_div(q, inverse_size));
        }
        stride *= size;
    }
}

// Sets lanes.sobol_k: each point's index within its grid cell and replicate, i div (grid cells
// with the replicate axis), and returns the bits that hold every k (at least 1).
inline int sobol_positions(const ScanSpace& space, ScanLanes& lanes) {
    const std::uint64_t cells = space.grid_cells;
    std::uint32_t highest = 0;
    std::uint64_t large = cells >> 51;  // beyond floor_div's range: integer division
    EPC_FAST_SIMD_REDUCTION(| : large)
    for (std::size_t i = 0; i < block_size; ++i) large |= lanes.index[i] >> 51;
    if (large != 0) {
        for (std::size_t i = 0; i < block_size; ++i) {
            lanes.sobol_k[i] = static_cast<std::uint32_t>(lanes.index[i] / cells);
            highest |= lanes.sobol_k[i];
        }
    } else {
        const double inverse = 1.0 / static_cast<double>(cells);
        EPC_FAST_SIMD_REDUCTION(| : highest)
        for (std::size_t i = 0; i < block_size; ++i) {
            // k mod 2^32 (a scan refuses more points than that per replicate and cell)
            const auto k = static_cast<std::uint64_t>(floor_div(static_cast<double>(lanes.index[i]), inverse));
            lanes.sobol_k[i] = static_cast<std::uint32_t>(k);
            highest |= lanes.sobol_k[i];
        }
    }
    int bits = 1;
    while (bits < 32 && (highest >> bits) != 0) ++bits;
    return bits;
}

// Each lane's replicate: the replicate axis's digit, or 0 (one replicate).
inline const std::int32_t* replicates_of(const ScanSpace& space, const ScanLanes& lanes) {
    static const std::array<std::int32_t, block_size> zeros{};
    return space.replicate_axis < 0 ? zeros.data()
                                    : lanes.axis_index[static_cast<std::size_t>(space.replicate_axis)].data();
}

}  // namespace detail

// The cycle of points that repeat with period `period` (the grid's cells, or a key's): the
// least multiple of block_size that the period divides, so that every kernel block starts a
// block of the cycle; 0 above max_cycle.
inline std::uint64_t cycle_length(std::uint64_t period) {
    if (period > max_cycle) return 0;
    std::uint64_t length = block_size;
    while (length % period != 0) length += block_size;
    return length <= max_cycle ? length : 0;
}

// f(lanes) for each block of the points 0 .. points - 1 (a multiple of block_size), the lanes
// holding its indices and grid digits.
template <class F>
inline void for_grid_blocks(const ScanSpace& space, std::uint64_t points, F&& f) {
    ScanLanes lanes(space);
    lanes.n = block_size;
    for (std::uint64_t first = 0; first < points; first += block_size) {
        for (std::size_t i = 0; i < block_size; ++i) lanes.index[i] = first + i;
        detail::grid_digits(space, true, lanes);
        f(lanes);
    }
}

// Sets space.cycle and the by_cycle tables of the parameters read from grid axes, once the
// axes and parameters are set.
inline void set_cycles(ScanSpace& space) {
    for (ParamSource& p : space.params) p.by_cycle.clear();
    space.cycle = cycle_length(space.grid_cells);
    if (space.cycle == 0) return;
    for_grid_blocks(space, space.cycle + block_size, [&](const ScanLanes& lanes) {
        for (ParamSource& p : space.params) {
            if (p.kind != ParamSource::axis_value || !space.axes[static_cast<std::size_t>(p.axis)].grid) continue;
            const std::int32_t* k = lanes.axis_index[static_cast<std::size_t>(p.axis)].data();
            for (std::size_t i = 0; i < block_size; ++i) p.by_cycle.push_back(p.values[static_cast<std::size_t>(k[i])]);
        }
    });
}

// Forms the parameters of the points lanes.index[0 .. lanes.n - 1] (consecutive: each is the
// previous plus one) into `lanes`, and points `in`'s columns at them: a fixed parameter is a
// broadcast column (the kernel drops the terms it zeroes), the others per lane.
inline void form_points(const ScanSpace& space, bool consecutive, ScanLanes& lanes, Inputs& in) {
    const std::size_t n = lanes.n;
    for (std::size_t i = n; i < block_size; ++i) lanes.index[i] = lanes.index[n > 0 ? n - 1 : 0];
    detail::grid_digits(space, consecutive, lanes);
    if (space.sobol.on) set_gray_masks(lanes.sobol_k, detail::sobol_positions(space, lanes), lanes.sobol);
    const auto uniforms = [&](std::uint32_t stream, std::uint32_t dimension) {
        if (space.sobol.on) {
            sobol_uniforms(space.sobol, dimension, lanes.sobol, detail::replicates_of(space, lanes), lanes.u);
        } else {
            stream_uniforms(space.seed, stream, lanes.index, lanes.u);
        }
    };
    for (std::size_t a = 0; a < space.axes.size(); ++a) {
        const DiscreteAxis& axis = space.axes[a];
        if (axis.grid) continue;
        uniforms(axis.stream, axis.dimension);
        for (std::size_t i = 0; i < n; ++i)
            lanes.axis_index[a][i] = detail::choice_index(axis, lanes.u[i]);
    }
    for (int j = 0; j < n_params; ++j) {
        const ParamSource& p = space.params[j];
        double* __restrict x = lanes.values[j];
        if (p.kind == ParamSource::fixed) {
            in.columns[j] = Column{&p.value, 0};
            continue;
        }
        in.columns[j] = Column{x, 1};
        if (p.kind == ParamSource::drawn) {
            uniforms(p.stream, p.dimension);
            draw_values(p.draw, lanes.u, x);
        } else if (consecutive && !p.by_cycle.empty()) {  // a slice of the grid's cycle
            const double* __restrict c = p.by_cycle.data() + lanes.index[0] % space.cycle;
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i) x[i] = c[i];
        } else {
            const std::int32_t* __restrict k = lanes.axis_index[static_cast<std::size_t>(p.axis)].data();
            const double* __restrict v = p.values.data();
            for (std::size_t i = 0; i < n; ++i) x[i] = v[k[i]];
        }
    }
}

}  // namespace epc_fast
