// f50's starting guesses for one lane (start.h takes them over a block's lanes), and the error
// each is certified within.
//
// Three starting guesses, all fitted by tools/fit_f50_start.py to the exact f50; the tool writes
// their coefficients to coefficients.h. The guess only decides how many steps the solver takes,
// never where it converges:
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

#include "../constants.h"
#include "../mtf.h"
#include "../polynomials.h"
#include "coefficients.h"

namespace epc_fast {

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
// The coefficients: coefficients.h (accurate_start_coefficients, one row per threshold
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
// The coefficients: coefficients.h (jitter_start_coefficients).

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

// w = v_p^2 - v_m^2 = (p r - m r)(p r + m r) from p, r and m r, its products spelled out: left
// to the compiler, whether p r fuses into the sum and difference depends on whether the cubic
// start also uses it, and a lane's start would change in the last bit with the other lanes of
// its block.
template <class T>
EPC_FAST_INLINE T pixel_minus_motion(T p, T r, T mr) {
#if EPC_FAST_FMA
    return std::fma(p, r, -mr) * std::fma(p, r, mr);
#else
    const T pr = p * r;
    return (pr - mr) * (pr + mr);
#endif
}
template <class T>
EPC_FAST_INLINE StartPoint<T> start_point(T lambda_f_mm, T aperture_mm, T blur_mm, T jitter_mm) {
    const T d = lambda_f_mm * T(1.0 / start_nu50);
    const T p = aperture_mm * T(1.0 / start_x50);
    const T m = blur_mm * T(1.0 / start_x50);
    const T j = jitter_mm * T(1.0 / start_j50);
    const T r = T(1) / std::sqrt(d * d + p * p + m * m + j * j);
    const T pr = p * r, mr = m * r, dr = d * r;
    const T w = pixel_minus_motion(p, r, mr);
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

// The accurate start fitted to a call's optics: to one spectrum (spectrum_fit.h fits it when a
// call's spectrum is first seen), or to one lens table (lens_fit.h). With a spectrum, D is one
// fixed function of f lambda_mean F for every point of the call, and a lens table one fixed
// function of f, so f50 sqrt(S) is again P(a, z) of the accurate start (with lambda F the mean
// wavelength's, or the table's nu50 / half) and only P's coefficients depend on the optics.
// One row per threshold of accurate_start_thresholds, in the accurate start's form.
struct FittedStart {
    double coefficients[detail::n_accurate_starts][detail::accurate_start_terms];
    // each row's largest relative error on the fit's own nodes (spectrum_fit.h)
    double fit_error[detail::n_accurate_starts];
};

namespace detail {

// cycles/mm: a lane's start from its fitted start's row c (a FittedStart row) and its lengths
// (start_point's: the optics length the start was fitted with, lambda F with the spectrum's
// mean wavelength or the lens table's nu50 / half; no jitter).
template <class T>
EPC_FAST_INLINE T fitted_start_guess(const double (&c)[accurate_start_terms], T lambda_f_mm,
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

}  // namespace detail

// The start fitted to a demosaicker's pixel factor Pi(x) = sinc(x) M_dem(x), x = f p
// (demosaic_fit.h fits it when a call's demosaicker is first seen): a polynomial P(a, w) in the
// accurate start's coordinates with x_p = p / X_pi, not even in w.
constexpr int pixel_start_degree = 10;
constexpr int pixel_start_terms = (pixel_start_degree + 1) * (pixel_start_degree + 2) / 2;  // i + j <= 10

// The start fitted to a demosaicker's pixel factor: P's coefficients of a^i w^j (i outer,
// j = 0 .. degree - i) per threshold row, each row's largest relative error on the fit's nodes,
// and X_pi, where sinc(x) M_dem(x) falls to 1/2 (x = f p).
struct PixelStart {
    double coefficients[detail::n_accurate_starts][pixel_start_terms];
    double fit_error[detail::n_accurate_starts];
    double x50;
};

namespace detail {

// Row I of P: sum over j of c_ij w^j, by Horner.
template <int I, class T>
EPC_FAST_INLINE T pixel_start_row(const double (&c)[pixel_start_terms], T w) {
    constexpr int offset = [] {
        int k = 0;
        for (int i = 0; i < I; ++i) k += pixel_start_degree - i + 1;
        return k;
    }();
    return poly::horner_part<offset, pixel_start_degree - I + 1>(c, w);
}

// P(a, w): Horner in a over the rows I .. degree.
template <int I = 0, class T>
EPC_FAST_INLINE T pixel_start_polynomial(const double (&c)[pixel_start_terms], T a, T w) {
    if constexpr (I == pixel_start_degree) {
        return pixel_start_row<I>(c, w);
    } else {
        return pixel_start_row<I>(c, w) + a * pixel_start_polynomial<I + 1>(c, a, w);
    }
}

// The monomials a^i w^j in P's coefficients' order.
inline void pixel_start_monomials(double a, double w, double* out) {
    int k = 0;
    double a_power = 1.0;
    for (int i = 0; i <= pixel_start_degree; ++i) {
        double term = a_power;
        for (int j = 0; j <= pixel_start_degree - i; ++j) {
            out[k++] = term;
            term *= w;
        }
        a_power *= a;
    }
}

// A lane's coordinates: r = 1 / sqrt(S), a and w, from lambda F, the pitch (mm) and the blur.
template <class T>
struct PixelPoint {
    T r, a, w;
};
template <class T>
EPC_FAST_INLINE PixelPoint<T> pixel_point(T lambda_f_mm, T pitch_mm, T blur_mm, T x50) {
    const T d = lambda_f_mm * T(1.0 / start_nu50);
    const T p = pitch_mm / x50;
    const T m = blur_mm * T(1.0 / start_x50);
    const T r = T(1) / std::sqrt(d * d + p * p + m * m);
    return {r, T(2) * (d * r) - T(1), pixel_minus_motion(p, r, m * r)};
}

// cycles/mm: a lane's start from row c of its demosaicker's fitted start.
template <class T>
EPC_FAST_INLINE T pixel_start_guess(const double (&c)[pixel_start_terms], T x50, T lambda_f_mm,
                                    T pitch_mm, T blur_mm) {
    const PixelPoint<T> q = pixel_point(lambda_f_mm, pitch_mm, blur_mm, x50);
    return q.r * pixel_start_polynomial(c, q.a, q.w);
}

}  // namespace detail

}  // namespace epc_fast
