// Which lanes' starts are f50 without a step (`settled`: Halley and Newton take a start
// certified within their tolerance as it is), and in float32 which lanes are solved in float32
// at all (the others are `wide`: kernel.h redoes them in float64). A start is certified only
// where every term the lane has is one the starts know (the certifiable predicates of
// aberration.h, denoise.h, lens.h and cfa.h).
#pragma once

#include <cstddef>
#include <type_traits>

#include "../aberration.h"
#include "../block.h"
#include "../cfa.h"
#include "../constants.h"
#include "../denoise.h"
#include "../lens.h"
#include "../parallel.h"
#include "../params.h"
#include "guesses.h"
#include "lengths.h"

namespace epc_fast {

// float32 mode: a lane solves in float32 when its lengths (lambda F, pixel aperture, blur,
// jitter) are 0 or in [2^-40, 2^40] mm. Then f <= f_hi <= 2^40 and every product the MTF and
// its slopes form (length f, length^2, the Halley step) stays inside float32's range.
constexpr double float32_length_lo_mm = 9.094947017729282e-13;  // 2^-40
constexpr double float32_length_hi_mm = 1099511627776.0;        // 2^40

namespace detail {

// Whether a length (mm) is 0 or inside the range float32 lanes solve f50 for.
EPC_FAST_INLINE bool float32_length(double length_mm) {
    return (length_mm == 0.0) | ((length_mm >= float32_length_lo_mm) & (length_mm <= float32_length_hi_mm));
}

// Whether a factor of a length is inside 2^-60..2^60, where float32 multiplies it exactly as
// far as range goes (a product of two such within 2^-40..2^40 never leaves float32's range).
EPC_FAST_INLINE bool float32_factor(double x) {
    return (x >= 8.673617379884035e-19) & (x <= 1152921504606846976.0);  // 2^-60, 2^60
}

// The rows whose certified error, plus the rounding of a float64 start to T, is within
// settle_rtol (bit k: row k); none for a negative settle_rtol.
template <class T>
unsigned certified_rows(double settle_rtol) {
    constexpr double rounding = sizeof(T) == sizeof(double) ? 0.0 : 0x1p-24;  // to nearest float
    unsigned rows = 0;
    for (int k = 0; k < n_start_rows; ++k)
        if (certified_start_error[k] + rounding <= settle_rtol) rows |= 1u << k;
    return rows;
}

// Takes the settled flag off the lanes whose start cannot be certified after all: a binned lane
// with an array factor (its start is the pixel's alone), and a lane with the wavefront error,
// denoising, a lens table or a demosaicker (the starts know none of them). Passes of their
// own, so that a block without them runs the settling loops as they are.
template <class T>
EPC_FAST_INLINE void unsettle_uncertifiable(StartTerms terms,
                                            const double* __restrict bin_pitch, Block<T>& b,
                                            int& n_settled) {
    constexpr std::size_t n = block_size;
    LaneFlag<T>* __restrict settled = b.settled;
    if (terms.binning) {
        for (std::size_t i = 0; i < n; ++i) {
            const bool s_i = settled[i] != 0 && bin_pitch[i] == 0.0;
            n_settled -= (settled[i] != 0) - s_i;
            settled[i] = s_i;
        }
    }
    if (terms.optics) {
        const double* __restrict wavefront = b.x[wavefront_rms_waves];
        const double* __restrict sigma_px = b.x[denoise_sigma_px];
        const bool tables = !(lens_certifiable(b) & demosaic_certifiable(b));
        for (std::size_t i = 0; i < n; ++i) {
            const bool plain =
                aberration_certifiable(wavefront[i]) & denoise_certifiable(sigma_px[i]) & !tables;
            const bool s_i = (settled[i] != 0) & plain;
            n_settled -= (settled[i] != 0) - s_i;
            settled[i] = s_i;
        }
    }
}

// float32: the lanes to solve whose row is certified take their start in float64, from the
// float64 lengths (certified_start_error), rounded once to T: they need neither the bracket
// nor T's lengths. One pass per certified row present (usually one): the start, then whether
// the lane settles: a lane to solve of that row with certified lengths (as in float64,
// settle_starts) and a start that is a normal float, rounded to within 2^-24. Returns whether
// every lane to solve settled (the block then skips the bracket and the other starts).
template <class T>
EPC_FAST_INLINE bool settle_narrow(StartTerms terms, unsigned narrow_rows,
                                   const double* __restrict bin_pitch, Block<T>& b,
                                   int& n_settled) {
    constexpr std::size_t n = block_size;
    const double* __restrict blur_in = b.blur;
    const double* __restrict ap = b.scratch[2];
    const double* __restrict jit = b.scratch[3];
    const double* __restrict d_length = b.scratch[4];
    const LaneFlag<T>* __restrict solve = b.solve;
    const unsigned char* __restrict row_code = b.row_code;
    LaneFlag<T>* __restrict settled = b.settled;
    double* __restrict narrow_start = b.certified_start;
    T* __restrict at = b.at;
    for (std::size_t i = 0; i < n; ++i) settled[i] = 0;  // read by float32's passes below
    if (narrow_rows == 0) return false;
    auto narrow_row = [&](auto row_constant) EPC_FAST_LAMBDA_INLINE {
        constexpr int Row = decltype(row_constant)::value;
        if (!(narrow_rows & (1u << Row))) return;
        int count = 0;
        EPC_FAST_SIMD_REDUCTION(+ : count)
        for (std::size_t i = 0; i < n; ++i) {
            const double f0 = start_guess<false, Row>(d_length[i], ap[i], blur_in[i], jit[i], 1.0, Row);
            const bool s_i = (solve[i] != 0) & (row_code[i] == Row + 1) &
                             certified_lengths(d_length[i], ap[i], blur_in[i], jit[i]) &
                             (f0 >= 0x1p-100) & (f0 <= 0x1p100) ;
            settled[i] = s_i ? 1 : settled[i];
            narrow_start[i] = s_i ? f0 : narrow_start[i];  // read back where settled
            at[i] = s_i ? static_cast<T>(f0) : at[i];
            count += s_i;
        }
        n_settled += count;
    };
    narrow_row(std::integral_constant<int, 0>{});
    narrow_row(std::integral_constant<int, 1>{});
    narrow_row(std::integral_constant<int, 2>{});
    narrow_row(std::integral_constant<int, 3>{});
    narrow_row(std::integral_constant<int, jitter_start_row>{});
    unsettle_uncertifiable(terms, bin_pitch, b, n_settled);
    int n_solve = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_solve)
    for (std::size_t i = 0; i < n; ++i) n_solve += solve[i] != 0;
    return n_settled == n_solve;
}

// float32: the lanes to solve that are not settled and whose lengths float32 cannot hold are
// marked `wide` and taken out of the solve (kernel.h redoes them in float64). The spectrum's
// wavelengths and the f-number enter the polychromatic MTF as separate float32 factors, so
// they too must fit (2^-60..2^60); settled lanes need no float32 lengths. A lens table's and
// denoising's lanes are solved in float64 (the block's redo) too.
template <class T>
EPC_FAST_INLINE void narrow_lanes(const Spectrum& spectrum, double longest_nm,
                                  StartTerms terms, const double* __restrict bin_pitch,
                                  const double* __restrict zero_length, Block<T>& b) {
    constexpr std::size_t n = block_size;
    const bool poly = terms.poly;
    const double* __restrict wavelength = b.x[wavelength_nm];
    const double* __restrict f_num_in = b.x[f_number];
    const double* __restrict sigma_px = b.x[denoise_sigma_px];
    const double* __restrict blur_in = b.blur;
    const double* __restrict lf_short = b.scratch[1];
    const double* __restrict ap = b.scratch[2];
    const double* __restrict jit = b.scratch[3];
    LaneFlag<T>* __restrict solve = b.solve;
    const LaneFlag<T>* __restrict settled = b.settled;
    unsigned char* __restrict wide = b.wide;
    bool lambdas_fit = true;
    for (const double nm : spectrum.wavelengths_nm) lambdas_fit &= float32_factor(nm * nm_to_mm);
    auto fit_lanes = [&](auto binned) EPC_FAST_LAMBDA_INLINE {
        constexpr bool Binned = decltype(binned)::value;  // the array factor's lengths too
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double lf_long = (poly ? longest_nm : wavelength[i]) * nm_to_mm * f_num_in[i];
            bool fits = float32_length(lf_short[i]) & float32_length(lf_long) &
                        float32_length(ap[i]) & float32_length(blur_in[i]) &
                        float32_length(jit[i]) & lambdas_fit &
                        (!poly | float32_factor(f_num_in[i]));
            if (Binned) fits &= float32_length(zero_length[i]) & float32_length(bin_pitch[i]);
            const bool s_i = settled[i] != 0;
            wide[i] = (solve[i] != 0) & !s_i & !fits;
            solve[i] = (solve[i] != 0) & (s_i | fits);
            b.f50[i] = T(0);  // what a wide lane's float32 pass writes out before it is redone
        }
    };
    if (terms.binning) fit_lanes(std::true_type{});
    else fit_lanes(std::false_type{});
    if (terms.denoise | terms.lens) {  // their lanes are solved in float64 (the block's redo)
        for (std::size_t i = 0; i < n; ++i) {
            const bool wider = (solve[i] != 0) & (settled[i] == 0) & (terms.lens | (sigma_px[i] != 0.0));
            wide[i] = wider ? 1 : wide[i];
            solve[i] = wider ? 0 : solve[i];
        }
    }
}

// The settled lanes: Halley and Newton take their start as f50 without a step (b.settled,
// counted in n_settled). float64: a lane to solve whose row is certified, whose start lay
// inside the bracket (else at = f_hi / 2, not the start) and whose lengths are moderate.
// float32: settle_narrow's; brackets_and_starts wrote every lane's `at`, the settled ones take
// theirs back. Returns n_settled with the lanes settled here.
template <class T>
EPC_FAST_INLINE int settle_starts(StartTerms terms, unsigned rows, unsigned certified,
                                  const double* __restrict bin_pitch, Block<T>& b, int n_settled) {
    constexpr std::size_t n = block_size;
    constexpr bool narrow = sizeof(T) != sizeof(double);
    const double* __restrict blur_in = b.blur;
    const double* __restrict ap = b.scratch[2];
    const double* __restrict jit = b.scratch[3];
    const double* __restrict d_length = b.scratch[4];
    const double* __restrict narrow_start = b.certified_start;
    const LaneFlag<T>* __restrict solve = b.solve;
    const unsigned char* __restrict row_code = b.row_code;
    T* __restrict at = b.at;
    const T* __restrict hi = b.hi;
    LaneFlag<T>* __restrict settled = b.settled;
    if constexpr (narrow) {
        if (n_settled > 0) {
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) at[i] = settled[i] ? static_cast<T>(narrow_start[i]) : at[i];
        }
    } else {
        if ((rows & certified) != 0) {
            static_assert(n_start_rows == 5, "a term per row");
            const bool c0 = certified & 1u, c1 = certified & 2u, c2 = certified & 4u,
                       c3 = certified & 8u, c4 = certified & 16u;
            EPC_FAST_SIMD_REDUCTION(+ : n_settled)
            for (std::size_t i = 0; i < n; ++i) {
                const unsigned char code = row_code[i];
                const bool row_certified = ((code == 1) & c0) | ((code == 2) & c1) |
                                           ((code == 3) & c2) | ((code == 4) & c3) |
                                           ((code == 5) & c4);
                const bool s_i = (solve[i] != 0) & row_certified &
                                 certified_lengths(d_length[i], ap[i], blur_in[i], jit[i]) &
                                 (at[i] != T(0.5) * hi[i]) ;
                settled[i] = s_i;
                n_settled += s_i;
            }
            unsettle_uncertifiable(terms, bin_pitch, b, n_settled);
        }
    }
    return n_settled;
}

}  // namespace detail
}  // namespace epc_fast
