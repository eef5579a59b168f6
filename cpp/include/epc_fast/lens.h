// A lens's tabulated MTF (docs/model.md, "Tabulated MTFs"; the names of
// python/epc_fast/reference/lens.py): L(f), interpolated from the table a lane's `lens` index
// picks, in place of the aberration-free diffraction factor D(f) and with it the spectrum. The
// term's pieces: the table a lane takes (lens_table), its factor of the system MTF with the
// log-slopes Newton and Halley need (mtf_lens, lens_factor, f50/system_mtf.h), where f50's
// bracket ends on it and how the start scales (lens_start_lengths, f50/start.h), whether a
// start can be certified with it, and its share's log and log-slope (lens_log_factor,
// sensitivity.h). A call without tables never comes here.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "block.h"
#include "constants.h"
#include "params.h"
#include "tabulated.h"

namespace epc_fast {

// (ln(L / D), f d ln L / df) at f: the lens's factor against the aberration-free diffraction D
// (`diffraction_value`, D(f) over the spectrum), share_lens's numerator, and L's log-slope in
// f, which replaces diffraction's (L moves with neither the f-number nor the wavelength).
// Where D(f) is 0 (a table passing frequencies past the cut-off at the point's f-number),
// ln(L / D) is undefined: the log is ln L (and diffraction's share 0: mtf_log_factors).
struct LensLogFactor {
    double log, f_slope;
};

EPC_FAST_INLINE LensLogFactor lens_log_factor(double f_cyc_per_mm, const MtfTable& table,
                                              double diffraction_value) {
    const TableValue l = tabulated(table, f_cyc_per_mm);
    const bool past = diffraction_value == 0.0;
    return {past ? std::log(l.value) : std::log(l.value) - std::log(diffraction_value),
            f_cyc_per_mm * l.d1 / l.value};
}

namespace detail {

// Whether a block's starts can be certified (f50/start.h): only without tables, which the
// starts do not know.
template <class T>
EPC_FAST_INLINE bool lens_certifiable(const Block<T>& b) {
    return b.lens_tables == nullptr;
}

// A lane's lens table: its index in x[lens], clamped to the tables (a stand-in lane's is 0).
template <class T>
EPC_FAST_INLINE const MtfTable& lens_table(const Block<T>& b, std::size_t i) {
    const std::vector<MtfTable>& tables = *b.lens_tables;
    const double index = b.x[lens][i];
    const std::size_t k = index >= 1.0 ? static_cast<std::size_t>(index) : 0;
    return tables[k < tables.size() ? k : tables.size() - 1];
}

// f50's start on each lane's table (f50/start.h): the bracket's optics zero at the table's end
// (zero_length = 1 / end, in place of the shortest wavelength's lambda F), and the start scaled
// by where the table falls to 1/2, as if diffraction reached 1/2 there (f50_length = nu50 /
// half, in place of lambda F; nu50: where D reaches 1/2).
template <class T>
EPC_FAST_INLINE void lens_start_lengths(const Block<T>& b, double nu50,
                                        double* __restrict zero_length,
                                        double* __restrict f50_length) {
    for (std::size_t i = 0; i < block_size; ++i) {
        const MtfTable& table = lens_table(b, i);
        zero_length[i] = 1.0 / table.end;
        f50_length[i] = nu50 / table.half;
    }
}

// The block's one table, when every lane takes the same (one table, or a broadcast index);
// null when the lanes take several.
template <class T>
EPC_FAST_INLINE const MtfTable* lens_block_table(const Block<T>& b) {
    const std::vector<MtfTable>& tables = *b.lens_tables;
    if (tables.size() == 1) return &tables[0];
    return b.is_broadcast(lens) ? &lens_table(b, 0) : nullptr;
}

// Each lane's L (and with Slopes L', L'') at b.at: one table's lanes in vectorised passes
// (table_lanes), lanes of several tables one by one.
template <bool Slopes, class T>
EPC_FAST_INLINE void lens_values(const Block<T>& b, double* __restrict value, double* __restrict d1,
                                 double* __restrict d2) {
    alignas(64) double f[block_size];
    for (std::size_t i = 0; i < block_size; ++i) f[i] = static_cast<double>(b.at[i]);
    if (const MtfTable* one = lens_block_table(b)) {
        table_lanes<block_size, Slopes>(*one, f, block_size, value, d1, d2);
        return;
    }
    for (std::size_t i = 0; i < block_size; ++i) {
        const TableValue v = tabulated(lens_table(b, i), f[i]);
        value[i] = v.value;
        if (Slopes) {
            d1[i] = v.d1;
            d2[i] = v.d2;
        }
    }
}

// b.mtf = each lane's L at b.at, in place of diffraction (values only).
template <class T>
void mtf_lens(Block<T>& b) {
    alignas(64) double value[block_size];
    lens_values<false>(b, value, nullptr, nullptr);
    for (std::size_t i = 0; i < block_size; ++i) b.mtf[i] = static_cast<T>(value[i]);
}

// L in place of monochromatic diffraction's factor (f50/system_mtf.h diffraction_factor): L
// into b.mtf, L' and L'' into b.slope and b.curvature, and L as their denominator.
template <bool Curvature, class T>
void lens_factor(Block<T>& b) {
    alignas(64) double value[block_size], d1[block_size], d2[block_size];
    lens_values<true>(b, value, d1, d2);
    for (std::size_t i = 0; i < block_size; ++i) {
        b.mtf[i] = static_cast<T>(value[i]);
        b.slope[i] = static_cast<T>(d1[i]);
        if (Curvature) b.curvature[i] = static_cast<T>(d2[i]);
        b.denominator[i] = static_cast<T>(value[i]);
    }
}

}  // namespace detail
}  // namespace epc_fast
