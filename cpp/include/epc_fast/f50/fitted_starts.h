// The starts fitted to a call's tables (f50/lens_fit.h, f50/demosaic_fit.h), taken by the lanes
// they fit after start.h has given every lane its start: each lane's from its own inputs and
// its table, whatever tables and terms its neighbours have.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "../block.h"
#include "../constants.h"
#include "../lens.h"
#include "../parallel.h"
#include "../params.h"
#include "../tabulated.h"
#include "guesses.h"
#include "lengths.h"

namespace epc_fast {
namespace detail {

// Each lane of `mine` (a flag per lane) with a threshold of an accurate row (its row_code 1 ..
// 4) takes its start from guess(row, i) where that falls inside its bracket, and is marked to
// step at least twice (b.step_twice: a table's cubics join with jumps in their curvature, so a
// first step's size bounds the error it leaves only for a smooth MTF). One vectorised pass per
// row the lanes to solve take.
template <class T, class Guess>
EPC_FAST_INLINE void take_fitted_starts(Block<T>& b, const unsigned char* __restrict mine, Guess&& guess) {
    constexpr std::size_t n = block_size;
    const unsigned char* __restrict row_code = b.row_code;
    const LaneFlag<T>* __restrict solve = b.solve;
    const T* __restrict hi = b.hi;
    T* __restrict at = b.at;
    LaneFlag<T>* __restrict two = b.step_twice;
    for (int row = 0; row < n_accurate_starts; ++row) {
        const auto code = static_cast<unsigned char>(row + 1);
        int present = 0;
        for (std::size_t i = 0; i < n; ++i) present += (mine[i] != 0) & (row_code[i] == code) & (solve[i] != 0);
        if (present == 0) continue;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const T f0 = guess(row, i);
            const bool take = (mine[i] != 0) & (row_code[i] == code) & (f0 > T(0)) & (f0 < hi[i]);
            at[i] = take ? f0 : at[i];
            two[i] = take ? LaneFlag<T>(1) : two[i];
        }
    }
}

// float64, a lens table per lane and no demosaicker: each lane whose table has a fitted start
// (f50/lens_fit.h), without denoising (a factor the fit does not know, which would leave its
// start no better than the one it replaces), takes that start in place of the start scaled by
// where the table falls to 1/2 (take_fitted_starts). One table's lanes at a time, so that a
// lane's start is the same bits whichever tables its neighbours take.
template <class T>
EPC_FAST_OUTLINED void lens_fitted_starts(Block<T>& b) {
    constexpr std::size_t n = block_size;
    const std::vector<MtfTable>& tables = *b.lens_tables;
    const double* __restrict d_length = b.scratch[4];
    const double* __restrict sigma = b.x[denoise_sigma_px];
    const T* __restrict aperture = b.aperture_mm;
    const T* __restrict blur = b.blur_mm;
    alignas(64) std::int32_t table_of[block_size];
    for (std::size_t i = 0; i < n; ++i) table_of[i] = static_cast<std::int32_t>(&lens_table(b, i) - tables.data());
    alignas(64) unsigned char passed[block_size] = {}, mine[block_size];
    for (std::size_t first = 0; first < n; ++first) {
        if (passed[first] != 0) continue;
        const std::int32_t t = table_of[first];
        for (std::size_t i = 0; i < n; ++i) {
            passed[i] |= table_of[i] == t;
            mine[i] = (table_of[i] == t) & (sigma[i] == 0.0);
        }
        const FittedStart* fitted = tables[static_cast<std::size_t>(t)].start.get();
        if (fitted == nullptr) continue;
        take_fitted_starts(b, mine, [&](int row, std::size_t i) EPC_FAST_LAMBDA_INLINE {
            return fitted_start_guess(fitted->coefficients[row], static_cast<T>(d_length[i]),
                                      aperture[i], blur[i]);
        });
    }
}

// float64, a demosaicker with a fitted start (f50/demosaic_fit.h) and neither a spectrum nor
// lens tables: each lane at full resolution with the full pixel aperture (binning 1, fill
// factor 1), without denoising or a wavefront error (factors the fit does not know), takes that
// start (take_fitted_starts).
template <class T>
EPC_FAST_OUTLINED void demosaic_fitted_starts(Block<T>& b) {
    constexpr std::size_t n = block_size;
    const PixelStart& fitted = *b.demosaic_table->pixel_start;
    const double* __restrict lambda_f = b.scratch[4];
    const double* __restrict pitch = b.x[pixel_pitch_um];
    const double* __restrict fill = b.x[fill_factor];
    const double* __restrict k = b.x[binning];
    const double* __restrict sigma = b.x[denoise_sigma_px];
    const double* __restrict wavefront = b.x[wavefront_rms_waves];
    const T* __restrict blur = b.blur_mm;
    alignas(64) unsigned char plain[block_size];
    for (std::size_t i = 0; i < n; ++i)
        plain[i] = (fill[i] == 1.0) & (k[i] == 1.0) & (sigma[i] == 0.0) & (wavefront[i] == 0.0);
    const T x50 = static_cast<T>(fitted.x50);
    take_fitted_starts(b, plain, [&](int row, std::size_t i) EPC_FAST_LAMBDA_INLINE {
        return pixel_start_guess(fitted.coefficients[row], x50, static_cast<T>(lambda_f[i]),
                                 static_cast<T>(pitch[i] * um_to_mm), blur[i]);
    });
}

// The lanes of a float64 block with a lens table or a demosaicker that take a start fitted to
// it (b.step_twice and b.step_twice_any set): a lens table's where the block has no
// demosaicker (the fit knows none), else a demosaicker's where the block has neither a spectrum
// nor lens tables.
template <class T>
EPC_FAST_OUTLINED void fitted_starts(StartTerms terms, Block<T>& b) {
    const bool lens = terms.lens && b.demosaic_table == nullptr;
    const bool demosaic = b.demosaic_table != nullptr && b.demosaic_table->pixel_start != nullptr &&
                          !terms.lens && !terms.poly;
    if (!lens && !demosaic) return;
    for (std::size_t i = 0; i < block_size; ++i) b.step_twice[i] = 0;
    if (lens) lens_fitted_starts(b);
    else demosaic_fitted_starts(b);
    for (std::size_t i = 0; i < block_size; ++i) b.step_twice_any |= b.step_twice[i] != 0;
}

}  // namespace detail
}  // namespace epc_fast
