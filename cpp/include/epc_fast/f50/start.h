// f50's bracket and starting abscissa for every lane of a block (solvers.h solves from them),
// and the float32 mode's check of which lanes it can solve: start_f50, in steps. The starts are
// guesses.h's; each term beyond the paper's camera brings its own pieces (its lengths, whether
// a start can be certified with it, its per-lane inputs): lens.h, cfa.h, aberration.h and
// denoise.h.
#pragma once

#include <cstddef>
#include <type_traits>

#include "../aberration.h"
#include "../block.h"
#include "../cfa.h"
#include "../constants.h"
#include "../denoise.h"
#include "../parallel.h"
#include "../params.h"
#include "fitted_starts.h"
#include "guesses.h"
#include "lengths.h"
#include "settle.h"

namespace epc_fast {
namespace detail {

// Each lane's accurate_start_code into row_code, from its jitter (mm) and threshold; returns
// which rows the lanes to solve take (bit k: row k) and counts into n_cubic those that take the
// cubic start.
template <class Flag>
EPC_FAST_INLINE unsigned start_rows(const double* __restrict jitter_mm,
                                    const double* __restrict threshold,
                                    const Flag* __restrict solve,
                                    unsigned char* __restrict row_code, int& n_cubic) {
    static_assert(n_start_rows == 5, "a count per row");
    int n_row0 = 0, n_row1 = 0, n_row2 = 0, n_row3 = 0, n_row4 = 0, cubic = 0;
    EPC_FAST_SIMD_REDUCTION(+ : cubic, n_row0, n_row1, n_row2, n_row3, n_row4)
    for (std::size_t i = 0; i < block_size; ++i) {
        const unsigned char code = accurate_start_code(jitter_mm[i], threshold[i]);
        const bool s_i = solve[i] != 0;
        row_code[i] = code;
        n_row0 += s_i & (code == 1);
        n_row1 += s_i & (code == 2);
        n_row2 += s_i & (code == 3);
        n_row3 += s_i & (code == 4);
        n_row4 += s_i & (code == 5);
        cubic += s_i & (code == 0);
    }
    n_cubic += cubic;
    return (n_row0 > 0 ? 1u : 0u) | (n_row1 > 0 ? 2u : 0u) | (n_row2 > 0 ? 4u : 0u) |
           (n_row3 > 0 ? 8u : 0u) | (n_row4 > 0 ? 16u : 0u);
}

// The starts a block computes (choose_rows).
struct StartRows {
    int n_cubic = 0;  // lanes to solve that take the cubic start (or 1 for some)
    unsigned rows = 0;  // bit k: a lane to solve takes row k
    unsigned fitted_rows = 0;  // bit k: a lane to solve takes the fitted start's row k
    unsigned narrow_rows = 0;  // float32: bit k: a lane to solve takes row k, certified
    unsigned certified = 0;  // the rows whose start is certified at this tolerance
    const FittedStart* fitted = nullptr;  // a spectrum's fitted start (float64)
};

// The accurate start's row each lane takes, as accurate_start_code into b.row_code (float64,
// one wavelength; no jitter and a threshold with a row, or jitter at MTF50), 0 for the cubic
// start: a lane's start depends on its own inputs only. A block computes the starts its lanes
// to solve need: the cubic one if any lane takes it, and each row present (usually one, the
// call's threshold); a lane that is not solved may take any.
//
// With a spectrum fitted (spectrum_fit.h), float64: a lane without jitter whose threshold has
// a row takes the spectrum's start of that row (its accurate_start_code), in a pass per row
// present after the main loop; the main loop computes the cubic start only if a lane to solve
// takes it (jitter, or a threshold without a row). (A lens table's or a demosaicker's fitted
// start comes after: fitted_starts.h.)
//
// The rows whose start is certified at settle_rtol (a spectrum's never is): float32 takes only
// these (computed in float64 in a pass of their own: settle_narrow); every other lane to solve
// takes the cubic start.
template <class T>
EPC_FAST_INLINE StartRows choose_rows(const Spectrum& spectrum, double settle_rtol,
                                      StartTerms terms, Block<T>& b) {
    constexpr std::size_t n = block_size;
    constexpr bool narrow = sizeof(T) != sizeof(double);
    const bool poly = terms.poly;
    const double* __restrict threshold_in = b.x[mtf_threshold];
    const double* __restrict jit = b.scratch[3];
    const LaneFlag<T>* __restrict solve = b.solve;
    unsigned char* __restrict row_code = b.row_code;
    StartRows r;
    r.fitted = !narrow && poly ? spectrum.start.get() : nullptr;
    r.certified = !poly ? certified_rows<T>(settle_rtol) : 0u;
    if (!poly && (!narrow || r.certified != 0) && b.is_broadcast(mtf_threshold) &&
        b.is_broadcast(jitter_um) && !terms.alignment) {
        // one row for every lane (the lanes' own choice, made once; a burst's alignment
        // residual joins the jitter lane by lane)
        const unsigned char code = accurate_start_code(b.broadcast[jitter_um] * um_to_mm,
                                                       b.broadcast[mtf_threshold]);
        const int row = int{code} - 1;
        int n_solve = 0;
        EPC_FAST_SIMD_REDUCTION(+ : n_solve)
        for (std::size_t i = 0; i < n; ++i) n_solve += solve[i] != 0;
        for (std::size_t i = 0; i < n; ++i) row_code[i] = code;
        r.n_cubic = row < 0 ? n_solve : 0;
        r.rows = row >= 0 && n_solve > 0 ? 1u << row : 0u;
    } else if (!poly && (!narrow || r.certified != 0)) {
        r.rows = start_rows(jit, threshold_in, solve, row_code, r.n_cubic);
    } else if (r.fitted != nullptr) {
        int no_row = 0;  // lanes to solve whose threshold has no row
        const unsigned present = start_rows(jit, threshold_in, solve, row_code, no_row);
        // the thresholds' rows only: a spectrum has no jitter start
        r.fitted_rows = present & ((1u << n_accurate_starts) - 1u);
        r.n_cubic = no_row > 0 || (present & (1u << jitter_start_row)) != 0 ? 1 : 0;
    } else {
        for (std::size_t i = 0; i < n; ++i) row_code[i] = 0;
        r.n_cubic = 1;
    }
    if (narrow) {  // the rows present become the certified pass's; the others take the cubic start
        r.narrow_rows = r.rows & r.certified;
        r.n_cubic = r.n_cubic > 0 || (r.rows & ~r.certified) != 0 ? 1 : 0;
        r.rows = 0;
    }
    return r;
}

// Every lane's solve inputs in T, lo = 0, hi = f_hi (the bracket) and its starting abscissa
// `at`: the start of its row or the cubic one, or the bracket's middle where the start falls
// outside the bracket. The first row present goes into the main loop (with the cubic start if
// needed), any further rows into a pass of their own each; a spectrum's rows (float64) after
// them. Binning: where there is an array factor the bracket ends at its zero 1 / (k p), below
// the aperture's, and a start past it becomes the bracket's middle.
template <class T>
EPC_FAST_INLINE void brackets_and_starts(StartTerms terms, StartRows r,
                                         const double* __restrict bin_pitch,
                                         const double* __restrict zero_length, Block<T>& b) {
    constexpr std::size_t n = block_size;
    constexpr bool narrow = sizeof(T) != sizeof(double);
    const auto& x = b.x;
    const double* __restrict f_num_in = x[f_number];
    const double* __restrict threshold_in = x[mtf_threshold];
    const double* __restrict blur_in = b.blur;
    const double* __restrict lf = b.scratch[0];
    const double* __restrict lf_short = b.scratch[1];
    const double* __restrict ap = b.scratch[2];
    const double* __restrict jit = b.scratch[3];
    const double* __restrict d_length = b.scratch[4];
    const unsigned char* __restrict row_code = b.row_code;
    const T* __restrict ln_inv_c = b.mtf;
    const T* __restrict start_scale = b.slope;
    T* __restrict lambda_f = b.lambda_f_mm;
    T* __restrict aperture = b.aperture_mm;
    T* __restrict jitter_mm = b.jitter_mm;
    T* __restrict blur = b.blur_mm;
    T* __restrict threshold = b.threshold;
    T* __restrict f_num = b.f_number;
    T* __restrict lo = b.lo;
    T* __restrict hi = b.hi;
    T* __restrict at = b.at;
    const unsigned rows = r.rows;
    const int n_cubic = r.n_cubic;
    int first_row = -1;
    for (int k = 0; k < n_start_rows && first_row < 0; ++k)
        if (rows & (1u << k)) first_row = k;
    auto finish = [&](auto with_jitter, auto with_cubic, auto row_constant) EPC_FAST_LAMBDA_INLINE {
        constexpr bool J = decltype(with_jitter)::value, Cubic = decltype(with_cubic)::value;
        constexpr int Row = decltype(row_constant)::value;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            // float32: a lane not solved computes on rounded stand-ins, harmlessly
            f_num[i] = static_cast<T>(f_num_in[i]);
            threshold[i] = static_cast<T>(threshold_in[i]);
            blur[i] = static_cast<T>(blur_in[i]);
            lambda_f[i] = static_cast<T>(lf[i]);
            aperture[i] = static_cast<T>(ap[i]);
            jitter_mm[i] = static_cast<T>(jit[i]);
            lo[i] = T(0);
            const T f_hi = f50_bracket<J>(static_cast<T>(lf_short[i]), aperture[i], blur[i],
                                          jitter_mm[i], ln_inv_c[i]);
            hi[i] = f_hi;
            // neither start: every lane to solve takes a spectrum's start, from its pass below
            T f0 = T(0);
            if constexpr (Cubic || Row >= 0)
                f0 = start_guess<Cubic, Row>(static_cast<T>(d_length[i]), aperture[i], blur[i],
                                             jitter_mm[i], start_scale[i], int{row_code[i]} - 1);
            at[i] = (f0 > T(0)) & (f0 < f_hi) ? f0 : T(0.5) * f_hi;
        }
    };
    auto extra_row = [&](auto row_constant) EPC_FAST_LAMBDA_INLINE {
        constexpr int Row = decltype(row_constant)::value;
        if (Row <= first_row || !(rows & (1u << Row))) return;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const T f0 = start_guess<false, Row>(static_cast<T>(d_length[i]), aperture[i],
                                                 blur[i], jitter_mm[i], start_scale[i], Row);
            const T f_hi = hi[i];
            const T start = (f0 > T(0)) & (f0 < f_hi) ? f0 : T(0.5) * f_hi;
            at[i] = row_code[i] == Row + 1 ? start : at[i];
        }
    };
    using yes = std::true_type;
    using no = std::false_type;
    auto starts = [&](auto with_jitter) EPC_FAST_LAMBDA_INLINE {
        auto with_row = [&](auto with_cubic) EPC_FAST_LAMBDA_INLINE {
            switch (first_row) {
                case 0: finish(with_jitter, with_cubic, std::integral_constant<int, 0>{}); break;
                case 1: finish(with_jitter, with_cubic, std::integral_constant<int, 1>{}); break;
                case 2: finish(with_jitter, with_cubic, std::integral_constant<int, 2>{}); break;
                case 3: finish(with_jitter, with_cubic, std::integral_constant<int, 3>{}); break;
                case jitter_start_row:
                    finish(with_jitter, with_cubic, std::integral_constant<int, jitter_start_row>{});
                    break;
            }
        };
        if (first_row < 0 && n_cubic == 0) finish(with_jitter, no{}, std::integral_constant<int, -1>{});
        else if (first_row < 0) finish(with_jitter, yes{}, std::integral_constant<int, -1>{});
        else if (n_cubic == 0) with_row(no{});
        else with_row(yes{});
    };
    if (terms.jitter) starts(yes{});
    else starts(no{});
    if (terms.binning) {
        // the array factor's lengths in T; where there is one, the bracket ends at its zero
        // 1 / (k p), below the aperture's, and a start past it becomes the bracket's middle
        const double* __restrict k = x[binning];
        T* __restrict bin_pitch_t = b.bin_pitch_mm;
        T* __restrict bin_k = b.bin_k;
        for (std::size_t i = 0; i < n; ++i) {
            bin_pitch_t[i] = static_cast<T>(bin_pitch[i]);
            bin_k[i] = static_cast<T>(k[i]);
            const T f_hi = f50_bracket<true>(static_cast<T>(lf_short[i]),
                                             static_cast<T>(zero_length[i]), blur[i],
                                             jitter_mm[i], ln_inv_c[i]);
            const bool array = bin_pitch[i] > 0.0;
            hi[i] = array ? f_hi : hi[i];
            at[i] = !array || ((at[i] > T(0)) & (at[i] < f_hi)) ? at[i] : T(0.5) * f_hi;
        }
    }
    extra_row(std::integral_constant<int, 1>{});
    extra_row(std::integral_constant<int, 2>{});
    extra_row(std::integral_constant<int, 3>{});
    extra_row(std::integral_constant<int, jitter_start_row>{});
    if constexpr (!narrow) {  // a spectrum's rows
        for (int k = 0; k < n_accurate_starts; ++k) {
            if (!(r.fitted_rows & (1u << k))) continue;
            const double(&c)[accurate_start_terms] = r.fitted->coefficients[k];
            const unsigned char code = static_cast<unsigned char>(k + 1);
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) {
                const T f0 = fitted_start_guess(c, d_length[i], aperture[i], blur[i]);
                const T f_hi = hi[i];
                const T start = (f0 > T(0)) & (f0 < f_hi) ? f0 : T(0.5) * f_hi;
                at[i] = row_code[i] == code ? start : at[i];
            }
        }
    }
}

// The terms' per-lane inputs for the solve (the demosaicker's, the wavefront error's,
// denoising's), and which terms the block's lanes to solve use, as bits (1 motion, 2 jitter, 4
// binning's array factor).
template <class T>
EPC_FAST_INLINE int solve_terms(StartTerms terms, const double* __restrict bin_pitch,
                                Block<T>& b) {
    constexpr std::size_t n = block_size;
    const LaneFlag<T>* __restrict solve = b.solve;
    const T* __restrict blur = b.blur_mm;
    const T* __restrict jitter_mm = b.jitter_mm;
    if (b.demosaic_table != nullptr) demosaic_lanes(b);
    if (terms.aberration) aberration_lanes(b);
    if (terms.denoise) denoise_lanes(b, static_cast<const T*>(b.mtf));
    int motion = 0, jitter = 0;
    EPC_FAST_SIMD_REDUCTION(+ : motion)
    for (std::size_t i = 0; i < n; ++i) motion += (solve[i] != 0) & (blur[i] > T(0));
    if (terms.jitter) {  // else every jitter_mm is a broadcast 0's (+-0): none
        EPC_FAST_SIMD_REDUCTION(+ : jitter)
        for (std::size_t i = 0; i < n; ++i) jitter += (solve[i] != 0) & (jitter_mm[i] > T(0));
    }
    int binned = 0;
    if (terms.binning)
        for (std::size_t i = 0; i < n; ++i) binned += (solve[i] != 0) & (bin_pitch[i] > 0.0);
    return (motion > 0 ? 1 : 0) | (jitter > 0 ? 2 : 0) | (binned > 0 ? 4 : 0);
}

// Sets lo = 0, hi = f_hi, the starting abscissa and the solve's inputs in T for every lane;
// returns which terms the block's lanes to solve use, as bits (1 motion, 2 jitter, 4 binning's
// array factor). With T = float32, a lane to solve whose lengths float32 cannot hold is marked
// `wide` and taken out of the solve (kernel.h redoes it in float64).
//
// settle_rtol: the tolerance of a solver that takes a start as f50 when it is certified within
// it (Halley and Newton, at their effective f50_rtol; -1 for the others). A monochromatic lane
// whose accurate or jitter start is so certified (certified_start_error, from a float64 start:
// in float32 too, then rounded once) is marked `settled`, with its start in `at`.
template <class T>
int start_f50(const Spectrum& spectrum, double settle_rtol, Block<T>& b) {
    constexpr bool narrow = sizeof(T) != sizeof(double);
    b.step_twice_any = false;  // (fitted_starts.h)
    threshold_terms(b);
    const StartTerms terms = start_terms(spectrum, b);
    const Spectrum::Extent extent = spectrum.extent();
    alignas(64) double bin_pitch[block_size], zero_length[block_size];
    start_lengths(extent, terms, b, bin_pitch, zero_length);
    const StartRows rows = choose_rows(spectrum, settle_rtol, terms, b);
    int n_settled = 0;
    bool all_settled = false;
    if constexpr (narrow)
        all_settled = settle_narrow(terms, rows.narrow_rows, bin_pitch, b, n_settled);
    if (narrow && !all_settled) {
        narrow_lanes(spectrum, extent.longest_nm, terms, bin_pitch, zero_length, b);
    } else {
        for (std::size_t i = 0; i < block_size; ++i) b.wide[i] = 0;
    }
    b.aberration = b.denoise = false;
    if (all_settled) {  // float32, every lane to solve settled: no bracket, no other start
        b.n_settled = n_settled;
        return 0;  // no lane left for the solver: no terms
    }
    brackets_and_starts(terms, rows, bin_pitch, zero_length, b);
    if constexpr (!narrow) {
        if (b.lens_tables != nullptr || b.demosaic_table != nullptr) fitted_starts(terms, b);
    }
    b.n_settled = settle_starts(terms, rows.rows, rows.certified, bin_pitch, b, n_settled);
    return solve_terms(terms, bin_pitch, b);
}

}  // namespace detail
}  // namespace epc_fast
