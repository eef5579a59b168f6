// f50's bracket and starting abscissa for every lane of a block (f50.h solves from them), and
// the float32 mode's check of which lanes it can solve.
//
// Three starting guesses, all fitted by tools/fit_f50_start.py to the exact f50; the tool writes
// their coefficients to f50_start_coefficients.h. The guess only decides how many steps the
// solver takes, never where it converges:
// - the accurate start, float64, for a lane with one wavelength, no jitter and one of the
//   thresholds MTF50, 30, 20 or 10 (the common scenes): at 1/2 within 4.2e-8 of f50, at 0.3
//   and 0.2 within 1.3e-6 and 5.2e-6, so that Halley's first step lands at float64's precision
//   and the solver stops after one evaluation of the MTF (Newton's stop test asks for a first
//   step below 3e-8 at the default tolerance: it takes two on part of the lanes); at 0.1
//   within 5.2e-5, one or two evaluations;
// - the jitter start, float64, for a lane with one wavelength, jitter and MTF50: within
//   1.3e-6, one evaluation;
// - the cubic start for every other lane, and for float32's lanes whose start is not certified
//   at float32's tolerance (whose tolerance one step from it already meets): within 0.37% at 1/2.
// A start certified within f50_rtol (certified_start_error) is f50: Halley and Newton take it
// without a step (`settled` lanes; float32 computes those starts in float64, rounded once).
#pragma once

#include <cmath>
#include <cstddef>
#include <iterator>
#include <type_traits>

#include "block.h"
#include "f50_start_coefficients.h"
#include "mtf.h"
#include "optics_stage.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"

namespace epc_fast {

// float32 mode: a lane solves in float32 when its lengths (lambda F, pixel aperture, blur,
// jitter) are 0 or in [2^-40, 2^40] mm. Then f <= f_hi <= 2^40 and every product the MTF and
// its slopes form (length f, length^2, the Halley step) stays inside float32's range.
constexpr double float32_length_lo_mm = 9.094947017729282e-13;  // 2^-40
constexpr double float32_length_hi_mm = 1099511627776.0;        // 2^40

namespace detail {

// The cubic start, for the lanes the accurate one does not cover. Each factor alone reaches 1/2
// at its own frequency f_i: diffraction at NU50/(lambda F), a sinc of length l at X50/l, jitter
// at J50/sigma. With x_i = 1/f_i, S = sum x_i^2 and v_i = x_i/sqrt(S), f0 = P(v)/sqrt(S), P a cubic
// in v_d, s = v_pixel + v_motion and t = v_pixel v_motion fitted to the exact f50 (largest
// error 0.37%, median 2.4e-4, over factor ratios e^-7..e^7; jitter enters through S only).
// For c != 1/2 it is scaled by sqrt(ln(1/c) / ln 2), exact for jitter alone. The guess only
// decides how many steps the solver takes, never where it converges.
constexpr double start_nu50 = 0.4039727532995172;   // D(nu) = 1/2
constexpr double start_x50 = 0.6033545644016142;    // sinc(x) = 1/2
constexpr double start_j50 = 0.1873906251292776;    // exp(-2 pi^2 y^2) = 1/2: sqrt(ln 2 / 2) / pi

template <class T>
EPC_FAST_INLINE T start_polynomial(T v_d, T s, T t) {
    // sum of c_ijk v_d^i s^j t^k, in cubic_start_coefficients' (i, j, k) order
    const double (&c)[cubic_start_terms] = cubic_start_coefficients;
    static_assert(cubic_start_terms == 13, "a term per coefficient");
    const T d2 = v_d * v_d, s2 = s * s;
    return T(c[0]) + T(c[1]) * t + T(c[2]) * s + T(c[3]) * (s * t) + T(c[4]) * s2 +
           T(c[5]) * (s2 * s) + T(c[6]) * v_d + T(c[7]) * (v_d * t) + T(c[8]) * (v_d * s) +
           T(c[9]) * (v_d * s2) + T(c[10]) * d2 + T(c[11]) * (d2 * s) + T(c[12]) * (d2 * v_d);
}

// The accurate start. Without jitter the unit vector v has two coordinates, v_d and
// w = v_p^2 - v_m^2, and f50 sqrt(S) = P(v_d, w) is smooth and even in w (pixel and motion are
// both sincs: swapping them changes w's sign). P: a polynomial of total degree 10 in
// a = 2 v_d - 1 and w, i.e. in a and z = w^2, coefficients of a^i z^j (i + 2j <= 10) row by
// row, one set per threshold: the same form holds for any threshold (the x_i stay each factor's
// own 1/f50 at 1/2), the function grows less smooth as c falls (0.1: 5.2e-5).
// The coefficients: f50_start_coefficients.h (accurate_start_coefficients, one row per threshold
// of accurate_start_thresholds, with each row's largest and median relative errors).
constexpr int n_accurate_starts = static_cast<int>(std::size(accurate_start_thresholds));
static_assert(std::size(accurate_start_coefficients) == std::size(accurate_start_thresholds));

// Row I of the accurate start's P with coefficients c (a threshold's row of
// accurate_start_coefficients, or a spectrum's): sum over j of c_ij z^j, by Horner.
template <int I, class T>
EPC_FAST_INLINE T accurate_start_row(const double (&c)[accurate_start_terms], T z) {
    constexpr int offset = [] {
        int k = 0;
        for (int i = 0; i < I; ++i) k += (accurate_start_degree - i) / 2 + 1;
        return k;
    }();
    constexpr int length = (accurate_start_degree - I) / 2 + 1;
    return poly::horner_part<offset, length>(c, z);
}

// P(a, z) with coefficients c: Horner in a over the rows I..degree.
template <int I = 0, class T>
EPC_FAST_INLINE T accurate_start_polynomial_of(const double (&c)[accurate_start_terms], T a, T z) {
    if constexpr (I == accurate_start_degree) {
        return accurate_start_row<I>(c, z);
    } else {
        return accurate_start_row<I>(c, z) + a * accurate_start_polynomial_of<I + 1>(c, a, z);
    }
}

// Threshold Row's P(a, z), from its row of accurate_start_coefficients.
template <int Row, class T>
EPC_FAST_INLINE T accurate_start_polynomial(T a, T z) {
    return accurate_start_polynomial_of(accurate_start_coefficients[Row], a, z);
}

// The jitter start: the accurate start's idea with jitter as a third coordinate, for MTF50
// only. The unit vector then has v_d, v_j and w = v_p^2 - v_m^2 (|w| <= 1 - v_d^2 - v_j^2), P is
// still even in w, and smooth in all three (jitter's Gaussian enters through (f x_j)^2, as the
// sincs do to leading order). P: a polynomial of total degree 8 in a = 2 v_d - 1, u = 2 v_j - 1
// and w, i.e. coefficients of a^i u^k z^j (i + k + 2j <= 8), fitted by
// tools/fit_f50_start.py (fit_jitter) over the whole (v_d, v_j, w) domain: within 1.3e-6, so
// that Halley stops after one evaluation as at MTF30.
// The coefficients: f50_start_coefficients.h (jitter_start_coefficients).

// The row index start_guess takes for the jitter start (after the thresholds' rows).
constexpr int jitter_start_row = n_accurate_starts;
// Rows of starts in all: the thresholds' and the jitter start.
constexpr int n_start_rows = n_accurate_starts + 1;

// Each row's certified error: a bound on the relative distance from its start (computed in
// float64, lengths inside 2^-400..2^400 mm) to the exact f50. The starts are functions on a
// compact domain (the unit vector v), so their error is a smooth function there, measured
// densely: tools/fit_f50_start.py's largest errors (400,000 random points and the edges) are
// 4.20e-8, 1.32e-6, 5.20e-6, 5.19e-5 and 1.27e-6 (jitter); a denser check (`python
// tools/fit_f50_start.py --check`: 4e6 random points and a 1001^2 grid, jitter 4e6 and 101^3)
// finds 4.199e-8, 1.317e-6, 5.198e-6, 5.190e-5 and 1.274e-6. The bound is twice the largest
// found, rounded up. A lane whose start is certified within f50_rtol is solved: Halley and
// Newton take the start as f50 without evaluating the MTF (start_f50's settled lanes), so that
// a tolerance of 1e-7 and above, and float32's floor of 2^-21, cost no MTF evaluation at MTF50
// without jitter.
constexpr double certified_start_error[n_start_rows] = {1e-7, 3e-6, 1.2e-5, 1.2e-4, 3e-6};
// The lengths (mm) inside which a float64 start is certified: the squares in start_point stay
// normal doubles (a tiny length beside a moderate one only drops out of S, as it should).
constexpr double certified_length_lo_mm = 0x1p-400;
constexpr double certified_length_hi_mm = 0x1p400;

// Whether a lane's lengths (mm: lambda F, the pixel aperture, the blur, the jitter) are those a
// certified start needs: lambda F inside the range above, the others below its top.
EPC_FAST_INLINE bool certified_lengths(double lambda_f_mm, double aperture_mm, double blur_mm,
                                       double jitter_mm) {
    return (lambda_f_mm >= certified_length_lo_mm) & (lambda_f_mm <= certified_length_hi_mm) &
           (aperture_mm <= certified_length_hi_mm) & (blur_mm <= certified_length_hi_mm) &
           (jitter_mm <= certified_length_hi_mm);
}

// The coefficients' offset of the terms a^I u^K z^j (in jitter_start_coefficients' order).
constexpr int jitter_start_offset(int I, int K) {
    int offset = 0;
    for (int i = 0; i <= I; ++i)
        for (int k = 0; k + i <= jitter_start_degree; ++k) {
            if (i == I && k == K) return offset;
            offset += (jitter_start_degree - i - k) / 2 + 1;
        }
    return offset;
}
static_assert(jitter_start_offset(jitter_start_degree + 1, 0) == jitter_start_terms);

// The jitter start's P(a, u, z): Horner in z (innermost), u, then a.
template <int I, int K, class T>
EPC_FAST_INLINE T jitter_start_z(T z) {
    constexpr int offset = jitter_start_offset(I, K);
    constexpr int length = (jitter_start_degree - I - K) / 2 + 1;
    return poly::horner_part<offset, length>(jitter_start_coefficients, z);
}
template <int I, int K = 0, class T>
EPC_FAST_INLINE T jitter_start_u(T u, T z) {
    if constexpr (I + K == jitter_start_degree) {
        return jitter_start_z<I, K>(z);
    } else {
        return jitter_start_z<I, K>(z) + u * jitter_start_u<I, K + 1>(u, z);
    }
}
template <int I = 0, class T>
EPC_FAST_INLINE T jitter_start_polynomial(T a, T u, T z) {
    if constexpr (I == jitter_start_degree) {
        return jitter_start_u<I>(u, z);
    } else {
        return jitter_start_u<I>(u, z) + a * jitter_start_polynomial<I + 1>(a, u, z);
    }
}

// The accurate start a float64, monochromatic lane takes, as a code: k + 1 for row k (without
// jitter, its threshold's index in accurate_start_thresholds; with jitter at threshold 1/2,
// jitter_start_row), 0 for none (the cubic start: no row for that threshold, or jitter at
// another threshold). A lane's start depends on its own inputs only. Byte arithmetic rather
// than a chain of selects, which vectorises poorly: the conditions exclude each other, so one
// term at most is not 0.
EPC_FAST_INLINE unsigned char accurate_start_code(double jitter_mm, double mtf_threshold) {
    static_assert(n_accurate_starts == 4 && jitter_start_row == 4, "a term per row");
    static_assert(accurate_start_thresholds[0] == 0.5, "the jitter start is MTF50's");
    const double c = mtf_threshold;
    const bool none = jitter_mm == 0.0, some = jitter_mm > 0.0;
    return static_cast<unsigned char>(
        (none & (c == accurate_start_thresholds[0])) + 2 * (none & (c == accurate_start_thresholds[1])) +
        3 * (none & (c == accurate_start_thresholds[2])) + 4 * (none & (c == accurate_start_thresholds[3])) +
        5 * (some & (c == accurate_start_thresholds[0])));
}

// Where a lane sits on the unit sphere of the starts, from the lengths (mm) its frequency
// multiplies: lambda F (with a spectrum, the mean wavelength's), the pixel aperture, the blur
// and the jitter, each in units of its factor's own f50's inverse, x_i = 1 / f_i. r = 1 /
// sqrt(S), the unit vector's coordinates v_i = x_i r, and the accurate starts' a = 2 v_d - 1 and
// z = w^2, w = v_p^2 - v_m^2 (the compiler drops what a caller does not use).
template <class T>
struct StartPoint {
    T r, v_d, v_p, v_m, v_j, a, z;
};
template <class T>
EPC_FAST_INLINE StartPoint<T> start_point(T lambda_f_mm, T aperture_mm, T blur_mm, T jitter_mm) {
    const T d = lambda_f_mm * T(1.0 / start_nu50);
    const T p = aperture_mm * T(1.0 / start_x50);
    const T m = blur_mm * T(1.0 / start_x50);
    const T j = jitter_mm * T(1.0 / start_j50);
    const T r = T(1) / std::sqrt(d * d + p * p + m * m + j * j);
    const T pr = p * r, mr = m * r, dr = d * r;
    // w's products spelled out: left to the compiler, whether p r fuses into the sum and
    // difference depends on whether the cubic start also uses it, and a lane's start would
    // change in the last bit with the other lanes of its block
#if EPC_FAST_FMA
    const T w = std::fma(p, r, -mr) * std::fma(p, r, mr);
#else
    const T w = (pr - mr) * (pr + mr);
#endif
    return {r, dr, pr, mr, j * r, T(2) * dr - T(1), w * w};
}

// cycles/mm: one lane's starting guess from the lengths (mm) its frequency multiplies: lambda F
// (with a spectrum, the mean wavelength's), the pixel aperture, the blur and the jitter, and
// scale = sqrt(ln(1/c) / ln 2). Row >= 0 computes that row's accurate start, Cubic the cubic
// one; with both, a lane takes the accurate start if `row` (its accurate_start_code - 1) is Row.
// Overflow or underflow in the lengths' squares gives 0, inf or NaN, which the caller replaces
// by f_hi / 2.
template <bool Cubic, int Row, class T>
EPC_FAST_INLINE T start_guess(T lambda_f_mm, T aperture_mm, T blur_mm, T jitter_mm, T scale,
                              int row) {
    static_assert(Cubic || Row >= 0, "a start to compute");
    const StartPoint<T> q = start_point(lambda_f_mm, aperture_mm, blur_mm, jitter_mm);
    T f0 = T(0);
    if (Cubic) f0 = q.r * start_polynomial(q.v_d, q.v_p + q.v_m, q.v_p * q.v_m) * scale;
    if constexpr (Row >= 0) {
        T f_accurate;
        if constexpr (Row == jitter_start_row) {
            f_accurate = q.r * jitter_start_polynomial(q.a, T(2) * q.v_j - T(1), q.z);
        } else {
            f_accurate = q.r * accurate_start_polynomial<Row>(q.a, q.z);
        }
        f0 = Cubic ? (row == Row ? f_accurate : f0) : f_accurate;
    }
    return f0;
}

// One lane's start with its row chosen at run time: that row's accurate start, or the cubic one
// for row -1.
template <class T>
T start_guess_of_row(T lambda_f_mm, T aperture_mm, T blur_mm, T jitter_mm, T scale, int row) {
    switch (row) {
        case 0: return start_guess<false, 0>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, row);
        case 1: return start_guess<false, 1>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, row);
        case 2: return start_guess<false, 2>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, row);
        case 3: return start_guess<false, 3>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, row);
        case jitter_start_row:
            return start_guess<false, jitter_start_row>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, row);
        default: return start_guess<true, -1>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, row);
    }
}

}  // namespace detail

// The accurate start fitted to one spectrum (spectrum_start.h fits it when a call's spectrum is
// first seen): with a spectrum, D is one fixed function of f lambda_mean F for every point of
// the call, so f50 sqrt(S) is again P(a, z) of the accurate start, with lambda F the mean
// wavelength's, and only P's coefficients depend on the spectrum. One row per threshold of
// accurate_start_thresholds, in the accurate start's form.
struct SpectrumStart {
    double coefficients[detail::n_accurate_starts][detail::accurate_start_terms];
    // each row's largest relative error on the fit's own nodes (spectrum_start.h)
    double fit_error[detail::n_accurate_starts];
};

namespace detail {

// cycles/mm: a polychromatic lane's start from its spectrum's row c (a SpectrumStart row) and
// its lengths (start_point's, lambda F with the spectrum's mean wavelength; no jitter).
template <class T>
EPC_FAST_INLINE T spectrum_start_guess(const double (&c)[accurate_start_terms], T lambda_f_mm,
                                       T aperture_mm, T blur_mm) {
    const StartPoint<T> q = start_point(lambda_f_mm, aperture_mm, blur_mm, T(0));
    return q.r * accurate_start_polynomial_of(c, q.a, q.z);
}

constexpr double ln2 = 0.6931471805599453;

// ln(1/c) for threshold c, in T: the C library's log only for c other than 1/2.
template <class T>
T ln_inverse_threshold(double c) {
    return static_cast<T>(c == 0.5 ? ln2 : std::log(1.0 / c));
}

// The cubic start's factor for threshold c, from ln(1/c): sqrt(ln(1/c) / ln 2), 1 at c = 1/2.
template <class T>
EPC_FAST_INLINE T start_scale_of(T ln_inverse_c) {
    return std::sqrt(ln_inverse_c * T(1.0 / ln2));
}

// cycles/mm: the start start_f50 gives a monochromatic float64 lane (the formula alone, for
// tests: the accurate start of the lane's threshold where it has one and there is no jitter,
// the jitter start for jitter at MTF50, else the cubic one).
inline double f50_start(double lambda_f_mm, double aperture_mm, double blur_mm, double jitter_mm,
                        double mtf_threshold) {
    const double scale = start_scale_of(ln_inverse_threshold<double>(mtf_threshold));
    return start_guess_of_row(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale,
                              int{accurate_start_code(jitter_mm, mtf_threshold)} - 1);
}

// cycles/mm: the cubic start for any lane (the formula alone, for tests).
inline double f50_cubic_start(double lambda_f_mm, double aperture_mm, double blur_mm,
                              double jitter_mm, double mtf_threshold) {
    const double scale = start_scale_of(ln_inverse_threshold<double>(mtf_threshold));
    return start_guess_of_row(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale, -1);
}

// Whether a length (mm) is 0 or inside the range float32 lanes solve f50 for.
EPC_FAST_INLINE bool float32_length(double length_mm) {
    return (length_mm == 0.0) | ((length_mm >= float32_length_lo_mm) & (length_mm <= float32_length_hi_mm));
}

// Whether a factor of a length is inside 2^-60..2^60, where float32 multiplies it exactly as
// far as range goes (a product of two such within 2^-40..2^40 never leaves float32's range).
EPC_FAST_INLINE bool float32_factor(double x) {
    return (x >= 8.673617379884035e-19) & (x <= 1152921504606846976.0);  // 2^-60, 2^60
}

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
    constexpr std::size_t n = block_size;
    constexpr bool narrow = sizeof(T) != sizeof(double);
    const auto& x = b.x;
    const bool poly = spectrum.polychromatic();
    const Spectrum::Extent extent = spectrum.extent();
    const double shortest_nm = extent.shortest_nm, longest_nm = extent.longest_nm;
    // ln(1/c) for the jitter bracket and sqrt(ln(1/c) / ln 2) for the start's scaling; the C
    // library's log only for a threshold other than 1/2, once for a broadcast threshold.
    T* __restrict ln_inv_c = b.mtf;  // scratch until the solver runs
    T* __restrict start_scale = b.slope;
    if (b.is_broadcast(mtf_threshold)) {
        const T l = ln_inverse_threshold<T>(b.broadcast[mtf_threshold]);
        const T scale = start_scale_of(l);
        for (std::size_t i = 0; i < n; ++i) ln_inv_c[i] = l;
        for (std::size_t i = 0; i < n; ++i) start_scale[i] = scale;
    } else {
        for (std::size_t i = 0; i < n; ++i) ln_inv_c[i] = ln_inverse_threshold<T>(x[mtf_threshold][i]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) start_scale[i] = start_scale_of(ln_inv_c[i]);
    }
    // a burst's alignment residual is a Gaussian, as jitter is: the two are one (gaussian_blur_mm)
    const bool any_alignment = !(b.broadcast_is(alignment_error_um, 0.0) || b.broadcast_is(frames, 1.0));
    const bool any_jitter = !b.broadcast_is(jitter_um, 0.0) || any_alignment;
    const bool any_binning = !b.broadcast_is(binning, 1.0);
    // the wavefront error and denoising (optics.h): a lane with either takes no certified
    // start (the starts know neither factor), and float32 leaves denoising's lanes to float64
    // (its transfer's phases 2 pi f p i lose float32's digits at large i)
    const bool any_aberration = !b.broadcast_is(wavefront_rms_waves, 0.0);
    const bool any_denoise = !b.broadcast_is(denoise_sigma_px, 0.0);
    // a lens table (every lane of the call has one) takes the place of diffraction: the
    // bracket ends at the table's end, the start scales by where it falls to 1/2, no start is
    // certified, and float32 leaves its lanes to float64
    const bool any_lens = b.lens_tables != nullptr;
    // (a demosaicker's table: no certified start either, as the starts do not know it)
    const bool any_optics = any_aberration | any_denoise | any_lens | (b.demosaic_table != nullptr);
    const double* __restrict wavefront = x[wavefront_rms_waves];
    const double* __restrict sigma_px = x[denoise_sigma_px];
    const double* __restrict wavelength = x[wavelength_nm];
    const double* __restrict f_num_in = x[f_number];
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict fill = x[fill_factor];
    const double* __restrict jitter_um_ = x[jitter_um];
    const double* __restrict threshold_in = x[mtf_threshold];
    const double* __restrict blur_in = b.blur;
    LaneFlag<T>* __restrict solve = b.solve;
    unsigned char* __restrict wide = b.wide;
    T* __restrict lambda_f = b.lambda_f_mm;
    T* __restrict aperture = b.aperture_mm;
    T* __restrict jitter_mm = b.jitter_mm;
    T* __restrict blur = b.blur_mm;
    T* __restrict threshold = b.threshold;
    T* __restrict f_num = b.f_number;
    T* __restrict lo = b.lo;
    T* __restrict hi = b.hi;
    T* __restrict at = b.at;
    const double mean_mm = extent.mean_nm * nm_to_mm;
    // every length in float64 first, then rounded once to T (float32: after checking it fits);
    // two loops, each of one type, as GCC vectorises them
    double* __restrict lf = b.scratch[0];
    double* __restrict lf_short = b.scratch[1];
    double* __restrict ap = b.scratch[2];
    double* __restrict jit = b.scratch[3];
    double* __restrict d_length = b.scratch[4];
    if (b.is_broadcast(fill_factor)) {  // pixel_aperture_mm, one sqrt
        const double root_fill = std::sqrt(b.broadcast[fill_factor]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) ap[i] = root_fill * (pitch[i] * um_to_mm);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) ap[i] = pixel_aperture_mm(pitch[i], fill[i]);
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double f_number_i = f_num_in[i];
        lf[i] = wavelength[i] * nm_to_mm * f_number_i;
        lf_short[i] = (poly ? shortest_nm : wavelength[i]) * nm_to_mm * f_number_i;
        jit[i] = jitter_um_[i] * um_to_mm;
        d_length[i] = poly ? mean_mm * f_number_i : lf[i];
    }
    if (any_lens) {  // 1/lf_short is the bracket's optics zero, start_nu50 / d_length its f50
        for (std::size_t i = 0; i < n; ++i) {
            const MtfTable& table = lens_table(b, i);
            lf_short[i] = 1.0 / table.end;
            d_length[i] = start_nu50 / table.half;
        }
    }
    if (any_alignment) {
        const double* __restrict residual = x[alignment_error_um];
        const double* __restrict frames_in = x[frames];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i)
            jit[i] = gaussian_blur_mm(jitter_um_[i], residual[i], frames_in[i]);
    }
    // Binning: the binned pixel's lengths (binned_lengths_mm); the bracket's pixel zero is at
    // 1 / (k p) where a < 1 (the array factor's, below sqrt(a) p's), 1 / ap elsewhere. A lane
    // with an array factor takes the start of the pixel alone, never certified: not settled.
    alignas(64) double bin_pitch[n], zero_length[n];
    if (any_binning) {
        const double* __restrict k = x[binning];
        for (std::size_t i = 0; i < n; ++i) {
            const BinnedLengths<double> l = binned_lengths_mm(ap[i], pitch[i], fill[i], k[i]);
            ap[i] = l.aperture_mm;
            bin_pitch[i] = l.pitch_mm;
            zero_length[i] = l.pitch_mm > 0.0 ? k[i] * l.pitch_mm : l.aperture_mm;
        }
    }

    // The accurate start's row each lane takes, as accurate_start_code (float64, one
    // wavelength; no jitter and a threshold with a row, or jitter at MTF50), 0 for the cubic
    // start: a lane's start depends on its own inputs only. A block
    // computes the starts its lanes to solve need: the cubic one if any lane takes it, and each
    // row present (usually one, the call's threshold); a lane that is not solved may take any.
    unsigned char* __restrict row_code = b.row_code;
    int n_cubic = 0;
    unsigned rows = 0;  // bit k: a lane to solve takes row k
    // With a spectrum fitted (spectrum_start.h), float64: a lane without jitter whose threshold
    // has a row takes the spectrum's start of that row (its accurate_start_code), in a pass per
    // row present after the main loop; the main loop computes the cubic start only if a lane to
    // solve takes it (jitter, or a threshold without a row).
    const SpectrumStart* fitted = !narrow && poly ? spectrum.start.get() : nullptr;
    unsigned spectrum_rows = 0;  // bit k: a lane to solve takes the spectrum's row k
    unsigned narrow_rows = 0;  // float32: bit k: a lane to solve takes row k, certified
    // The rows whose start is certified at this tolerance (a spectrum's never is). float32 takes
    // only these (computed in float64 in a pass of their own, below); every other lane to
    // solve takes the cubic start.
    const unsigned certified = !poly ? certified_rows<T>(settle_rtol) : 0u;
    if (!poly && (!narrow || certified != 0) && b.is_broadcast(mtf_threshold) &&
        b.is_broadcast(jitter_um) && !any_alignment) {
        // one row for every lane (the lanes' own choice, made once; a burst's alignment
        // residual joins the jitter lane by lane)
        const unsigned char code = accurate_start_code(b.broadcast[jitter_um] * um_to_mm,
                                                       b.broadcast[mtf_threshold]);
        const int row = int{code} - 1;
        int n_solve = 0;
        EPC_FAST_SIMD_REDUCTION(+ : n_solve)
        for (std::size_t i = 0; i < n; ++i) n_solve += solve[i] != 0;
        for (std::size_t i = 0; i < n; ++i) row_code[i] = code;
        n_cubic = row < 0 ? n_solve : 0;
        rows = row >= 0 && n_solve > 0 ? 1u << row : 0u;
    } else if (!poly && (!narrow || certified != 0)) {
        rows = start_rows(jit, threshold_in, solve, row_code, n_cubic);
    } else if (fitted != nullptr) {
        int no_row = 0;  // lanes to solve whose threshold has no row
        const unsigned present = start_rows(jit, threshold_in, solve, row_code, no_row);
        // the thresholds' rows only: a spectrum has no jitter start
        spectrum_rows = present & ((1u << n_accurate_starts) - 1u);
        n_cubic = no_row > 0 || (present & (1u << jitter_start_row)) != 0 ? 1 : 0;
    } else {
        for (std::size_t i = 0; i < n; ++i) row_code[i] = 0;
        n_cubic = 1;
    }
    if (narrow) {  // the rows present become the certified pass's; the others take the cubic start
        narrow_rows = rows & certified;
        n_cubic = n_cubic > 0 || (rows & ~certified) != 0 ? 1 : 0;
        rows = 0;
    }
    LaneFlag<T>* __restrict settled = b.settled;
    int n_settled = 0;
    // a lane with the wavefront error, denoising, a lens table or a demosaicker is never
    // settled either (the starts know none of them); a pass of its own, so that a block without
    // them runs the settling loops as they are
    auto unsettle_optics = [&]() {
        if (!any_optics) return;
        const bool tables = any_lens | (b.demosaic_table != nullptr);
        for (std::size_t i = 0; i < n; ++i) {
            const bool plain = (wavefront[i] == 0.0) & (sigma_px[i] == 0.0) & !tables;
            const bool s_i = (settled[i] != 0) & plain;
            n_settled -= (settled[i] != 0) - s_i;
            settled[i] = s_i;
        }
    };
    // a binned lane with an array factor is never settled (its start is not certified)
    auto unsettle_binned = [&]() {
        if (!any_binning) return;
        for (std::size_t i = 0; i < n; ++i) {
            const bool s_i = settled[i] != 0 && bin_pitch[i] == 0.0;
            n_settled -= (settled[i] != 0) - s_i;
            settled[i] = s_i;
        }
    };
    // float32: the lanes to solve whose row is certified take their start in float64, from the
    // float64 lengths (certified_start_error), rounded once to T: they need neither the bracket
    // nor T's lengths. A block whose every lane to solve is settled so skips `finish` below.
    bool all_settled = false;
    double* __restrict narrow_start = b.certified_start;
    if (narrow)  // read by float32's passes below (float64 sets it after its bracket)
        for (std::size_t i = 0; i < n; ++i) settled[i] = 0;
    if (narrow && narrow_rows != 0) {
        // one pass per certified row present (usually one): the start, then whether the lane
        // settles: a lane to solve of that row with certified lengths (as in float64, below)
        // and a start that is a normal float, rounded to within 2^-24
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
        unsettle_binned();
        unsettle_optics();
        int n_solve = 0;
        EPC_FAST_SIMD_REDUCTION(+ : n_solve)
        for (std::size_t i = 0; i < n; ++i) n_solve += solve[i] != 0;
        all_settled = n_settled == n_solve;
    }
    if (narrow && !all_settled) {
        // the spectrum's wavelengths and the f-number enter the polychromatic MTF as separate
        // float32 factors, so they too must fit (2^-60..2^60); settled lanes need no float32
        // lengths
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
        if (any_binning) fit_lanes(std::true_type{});
        else fit_lanes(std::false_type{});
        if (any_denoise | any_lens) {  // their lanes are solved in float64 (the block's redo)
            for (std::size_t i = 0; i < n; ++i) {
                const bool wider = (solve[i] != 0) & (settled[i] == 0) & (any_lens | (sigma_px[i] != 0.0));
                wide[i] = wider ? 1 : wide[i];
                solve[i] = wider ? 0 : solve[i];
            }
        }
    } else {
        for (std::size_t i = 0; i < n; ++i) wide[i] = 0;
    }
    // the first row present goes into the main loop (with the cubic start if needed), any
    // further rows into a pass of their own each
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
    b.aberration = b.denoise = false;
    if (all_settled) {  // float32, every lane to solve settled: no bracket, no other start
        b.n_settled = n_settled;
        return 0;  // no lane left for the solver: no terms
    }
    if (any_jitter) starts(yes{});
    else starts(no{});
    if (any_binning) {
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
    if constexpr (!narrow) {
        for (int k = 0; k < n_accurate_starts; ++k) {
            if (!(spectrum_rows & (1u << k))) continue;
            const double(&c)[accurate_start_terms] = fitted->coefficients[k];
            const unsigned char code = static_cast<unsigned char>(k + 1);
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) {
                const T f0 = spectrum_start_guess(c, d_length[i], aperture[i], blur[i]);
                const T f_hi = hi[i];
                const T start = (f0 > T(0)) & (f0 < f_hi) ? f0 : T(0.5) * f_hi;
                at[i] = row_code[i] == code ? start : at[i];
            }
        }
    }
    // Settled lanes. float64: a lane to solve whose row is certified, whose start lay inside the
    // bracket (else at = f_hi / 2, not the start) and whose lengths are moderate. float32: the
    // certified pass above; `finish` wrote every lane's `at`, the settled ones take theirs back.
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
            unsettle_binned();
            unsettle_optics();
        }
    }
    b.n_settled = n_settled;
    if (b.demosaic_table != nullptr) demosaic_lanes(b);
    if (any_aberration | any_denoise) optics_lanes(b, any_aberration, any_denoise, ln_inv_c);
    int motion = 0, jitter = 0;
    EPC_FAST_SIMD_REDUCTION(+ : motion)
    for (std::size_t i = 0; i < n; ++i) motion += (solve[i] != 0) & (blur[i] > T(0));
    if (any_jitter) {  // else every jitter_mm is a broadcast 0's (+-0): none
        EPC_FAST_SIMD_REDUCTION(+ : jitter)
        for (std::size_t i = 0; i < n; ++i) jitter += (solve[i] != 0) & (jitter_mm[i] > T(0));
    }
    int binned = 0;
    if (any_binning)
        for (std::size_t i = 0; i < n; ++i) binned += (solve[i] != 0) & (bin_pitch[i] > 0.0);
    return (motion > 0 ? 1 : 0) | (jitter > 0 ? 2 : 0) | (binned > 0 ? 4 : 0);
}

}  // namespace detail
}  // namespace epc_fast
