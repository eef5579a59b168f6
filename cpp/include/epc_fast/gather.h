// The kernel's gather (kernel.h): a block's parameters read into its lanes, each checked
// against its domain, padding and invalid lanes given harmless stand-ins. A full block of a
// contiguous column is read in place; a broadcast column is checked and spread over its lanes
// by the first block of a layout only (ColumnLayout, block.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "block.h"
#include "constants.h"
#include "parallel.h"
#include "params.h"

namespace epc_fast {
namespace detail {

// The value invalid and padding lanes compute on: no lane sees NaN or loops on garbage.
inline double stand_in(int param) {
    return param == mtf_threshold ? 0.5 : param == lens ? 0.0 : 1.0;
}

// valid[i] &= x[i] in d, for every lane; the domain's open or closed ends are decided once.
// Written as a select (valid where inside, else 0), which the vector code forms by masking the
// flag with the comparisons' all-ones lanes, with no conversion of them to 0/1 first.
inline void check_domain(const Domain& d, const double* __restrict x,
                         LaneFlag<double>* __restrict valid) {
    const double lo = d.lo, hi = d.hi;
    if (d.lo_closed && d.hi_closed) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] = (x[i] >= lo) & (x[i] <= hi) ? valid[i] : 0;
    } else if (d.lo_closed) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] = (x[i] >= lo) & (x[i] < hi) ? valid[i] : 0;
    } else if (d.hi_closed) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] = (x[i] > lo) & (x[i] <= hi) ? valid[i] : 0;
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] = (x[i] > lo) & (x[i] < hi) ? valid[i] : 0;
    }
    if (d.integer) {  // binning and frames: whole numbers only
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] &= x[i] == std::floor(x[i]);
    }
}

inline std::uint64_t bits_of(double v) {
    std::uint64_t x = 0;
    std::memcpy(&x, &v, sizeof x);
    return x;
}

inline bool same_bits(double a, double b) { return bits_of(a) == bits_of(b); }

// Reads the varying column j (stride != 0) of points [begin, begin + n) into lane x[j] (in place
// for a full contiguous block), checking its domain; padding lanes past n get stand-ins.
template <class T>
EPC_FAST_INLINE void gather_varying(const Inputs& in, std::size_t begin, const double* illuminance,
                                    int j, Block<T>& b) {
    const std::size_t n = b.n;
    const bool replaced = j == illuminance_lux && illuminance != nullptr;
    const std::ptrdiff_t stride = replaced ? 1 : in.columns[j].stride;
    const double* src = replaced ? illuminance
                                 : in.columns[j].data + static_cast<std::ptrdiff_t>(begin) * stride;
    double* __restrict x = b.x_store[j];
    b.row_filled &= ~(std::uint32_t{1} << j);
    if (stride == 1 && n == block_size) {
        b.x[j] = src;  // read in place (copied below if a lane turns out invalid)
        check_domain(in.domains[j], src, b.valid);
        return;
    }
    if (stride == 1) {
        for (std::size_t i = 0; i < n; ++i) x[i] = src[i];
    } else {
        for (std::size_t i = 0; i < n; ++i) x[i] = src[static_cast<std::ptrdiff_t>(i) * stride];
    }
    for (std::size_t i = n; i < block_size; ++i) x[i] = stand_in(j);
    check_domain(in.domains[j], x, b.valid);
    b.x[j] = x;
}

// Whether `in`'s columns (and the replacement of the illuminance) are laid out as when the
// Block's broadcast rows were last set up: every column's data and stride (compared as bytes:
// Column has no padding), and each broadcast value's bits, the same.
inline bool same_layout(const Inputs& in, bool replaced, const ColumnLayout& layout) {
    static_assert(sizeof(Column) == sizeof(const double*) + sizeof(std::ptrdiff_t), "no padding");
    if (!layout.set || layout.replaced != replaced) return false;
    if (std::memcmp(in.columns.data(), layout.columns.data(), sizeof layout.columns) != 0) return false;
    bool same = true;
    for (int k = 0; k < layout.n_broadcast; ++k)
        same &= bits_of(in.columns[layout.broadcast[k]].data[0]) == layout.bits[k];
    return same;
}

// Reads points [begin, begin + n); `illuminance_lux`, when given, replaces that column with
// n values of its own (the inverse solvers' trial illuminances). A broadcast column (stride 0)
// is checked once and copied to every lane; padding lanes past n get stand-ins. The broadcast
// columns are set up by the first block of a layout (the Block's ColumnLayout): the blocks
// after it with the same columns read only the varying ones.
template <class T>
void gather(const Inputs& in, std::size_t begin, const double* illuminance, Block<T>& b) {
    const std::size_t n = b.n;
    LaneFlag<double>* __restrict valid = b.valid;
    for (std::size_t i = 0; i < block_size; ++i) valid[i] = i < n;
    ColumnLayout& layout = b.layout;
    const bool replaced_lux = illuminance != nullptr;
    if (same_layout(in, replaced_lux, layout)) {
        if (layout.invalid)
            for (std::size_t i = 0; i < block_size; ++i) valid[i] = 0;
        for (int k = 0; k < layout.n_varying; ++k)
            gather_varying(in, begin, illuminance, layout.varying[k], b);
    } else {
        b.uniform = 0;
        layout.set = true;
        layout.replaced = replaced_lux;
        layout.invalid = false;
        layout.n_varying = layout.n_broadcast = 0;
        layout.columns = in.columns;
        for (int j = 0; j < n_params; ++j) {
            const bool replaced = j == illuminance_lux && replaced_lux;
            const double* src = in.columns[j].data;
            const std::ptrdiff_t stride = replaced ? 1 : in.columns[j].stride;
            if (stride != 0) {
                layout.varying[layout.n_varying++] = j;
                gather_varying(in, begin, illuminance, j, b);
                continue;
            }
            layout.bits[layout.n_broadcast] = bits_of(src[0]);
            layout.broadcast[layout.n_broadcast++] = j;
            // every lane holds the value, or the stand-in if it is invalid, even a lane that is
            // invalid for another parameter (harmless: a value inside the domain)
            double* __restrict x = b.x_store[j];
            const std::uint32_t bit = std::uint32_t{1} << j;
            const double v = src[0];
            const bool ok = in.domains[j].contains(v);
            const double fill = ok ? v : stand_in(j);
            if (!((b.row_filled & bit) != 0 && same_bits(b.row_value[j], fill))) {
                for (std::size_t i = 0; i < block_size; ++i) x[i] = fill;
                b.row_value[j] = fill;
                b.row_filled |= bit;
            }
            if (!ok) {
                layout.invalid = true;
                for (std::size_t i = 0; i < block_size; ++i) valid[i] = 0;
            }
            b.uniform |= bit;
            b.broadcast[j] = fill;
            b.x[j] = x;
        }
    }
    LaneFlag<double> n_valid = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_valid)
    for (std::size_t i = 0; i < block_size; ++i) n_valid += valid[i];
    if (n_valid == block_size) return;
    for (int j = 0; j < n_params; ++j) {
        if (b.is_broadcast(j)) continue;  // already harmless
        double* __restrict x = b.x_store[j];
        if (b.x[j] != x) {  // read in place so far: copy, to hold the stand-ins
            const double* __restrict src = b.x[j];
            for (std::size_t i = 0; i < block_size; ++i) x[i] = src[i];
            b.x[j] = x;
        }
        const double s = stand_in(j);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) x[i] = valid[i] ? x[i] : s;
    }
}

}  // namespace detail
}  // namespace epc_fast
