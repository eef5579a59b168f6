// Vectorisable sin(pi x), cos(pi x), acos(x) and exp(x): inlined polynomials instead of calls
// to the C library.
//
// Inside a lane loop, a call to glibc's scalar sin/acos stops vectorisation, and glibc's vector
// variants (libmvec) take special-case paths that couple neighbouring lanes, so that a point's
// last bits would depend on the point next to it. These polynomials are straight-line code:
// every lane gets the same operations, whatever the others hold.
//
// Coefficients: Chebyshev fits in 60-digit arithmetic by tools/fit_polynomials.py, which also
// measures the float64 evaluation against mpmath (sinpi: <= 3 ulp on [-1/2, 1/2]; asin: <= 2 ulp
// on [0, 1/2]; the diffraction MTF near its cut-off: <= 6 ulp, relative, on nu in [1/2, 1)).
// Argument reduction is exact for sinpi.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "constants.h"

namespace epc_fast {
namespace poly {

constexpr double sinpi_coefficients[] = {
    3.141592653589793,
    -5.167712780049969,
    2.5501640398773007,
    -0.5992645293189447,
    0.0821458865731029,
    -0.007370430505916944,
    0.0004662998161898394,
    -2.1903497074626018e-05,
    7.697826768224191e-07,
};
constexpr double asin_coefficients[] = {
    0.16666666666666666,
    0.07500000000000118,
    0.044642857142551895,
    0.03038194447553234,
    0.02237215744350722,
    0.017352816540325496,
    0.01396378001220357,
    0.011566459612121669,
    0.009621842970100282,
    0.009319560794767446,
    0.0030448799094556773,
    0.019554513336123378,
    -0.01924167174674304,
    0.02961201126495512,
};
constexpr double diffraction_coefficients[] = {
    3.3953054526271007,
    -1.0185916357881306,
    -0.18189136353348995,
    -0.07073553027373239,
    -0.03617157740982837,
    -0.02142472178421854,
    -0.013925691684179769,
    -0.009659667582268825,
    -0.006970442160113385,
    -0.005613116142106228,
    -0.0026266874441750396,
    -0.00783091943500316,
    0.006129334829378577,
    -0.010902965352930965,
};

// 1/k!, k = 0..13: exp(r) on |r| <= ln(2)/2 to a truncation error below 4e-18.
constexpr double exp_coefficients[] = {
    1.0, 1.0, 0.5, 0.16666666666666666, 0.041666666666666664, 0.008333333333333333,
    0.001388888888888889, 0.0001984126984126984, 2.48015873015873e-05, 2.7557319223985893e-06,
    2.755731922398589e-07, 2.505210838544172e-08, 2.08767569878681e-09, 1.6059043836821613e-10,
};

// Horner's scheme in the lanes' type T (float64 or float32) over c[Offset .. Offset + Length),
// the coefficients of t^0 .. t^(Length - 1), each rounded to T (at compile time for a constexpr
// table; a spectrum's fitted start, f50/spectrum_fit.h, passes its own row).
template <int Offset, int Length, class T, int N>
EPC_FAST_INLINE T horner_part(const double (&c)[N], T t) {
    static_assert(Offset >= 0 && Length >= 1 && Offset + Length <= N, "a slice of c");
    T acc = static_cast<T>(c[Offset + Length - 1]);
    for (int k = Length - 2; k >= 0; --k) acc = acc * t + static_cast<T>(c[Offset + k]);
    return acc;
}

// Horner's scheme over all of c.
template <class T, int N>
EPC_FAST_INLINE T horner(const double (&c)[N], T t) {
    return horner_part<0, N>(c, t);
}

}  // namespace poly

// The constants of T's format that the bit tricks below need.
template <class T>
struct FloatFormat;
template <>
struct FloatFormat<double> {
    static constexpr double shifter = 6755399441055744.0;  // 1.5 * 2^52
    static constexpr double integral = 2251799813685248.0;  // 2^51: |x| above is an integer
    using Bits = std::uint64_t;
    static constexpr int mantissa_bits = 52, bias = 1023;
};
template <>
struct FloatFormat<float> {
    static constexpr float shifter = 12582912.0f;  // 1.5 * 2^23
    static constexpr float integral = 4194304.0f;  // 2^22
    using Bits = std::uint32_t;
    static constexpr int mantissa_bits = 23, bias = 127;
};

// round(x) to the nearest integer in plain arithmetic (SSE2 has no vector rounding): adding
// and subtracting 1.5 * 2^52 (float: 2^23) rounds any |x| < 2^51 (2^22); larger values are
// integers already.
template <class T>
EPC_FAST_INLINE T round_to_integer(T x) {
    constexpr T shifter = FloatFormat<T>::shifter;
    const T k = (x + shifter) - shifter;
    return std::fabs(x) < FloatFormat<T>::integral ? k : x;
}

// sin(pi r) for |r| <= 1/2, where it needs no argument reduction: the polynomial itself.
template <class T>
EPC_FAST_INLINE T sinpi_reduced(T r) {
    return r * poly::horner(poly::sinpi_coefficients, r * r);
}

// sin(pi x) for any finite x: r = x - round(x) is exact, sin(pi x) = (-1)^round(x) sin(pi r).
template <class T>
EPC_FAST_INLINE T sinpi(T x) {
    const T k = round_to_integer(x);
    const T s = sinpi_reduced(x - k);
    const bool odd = k != T(2) * round_to_integer(T(0.5) * k);
    return odd ? -s : s;
}

// sinpi for x in [-1/2, 3/2], where round(x) is 0 or 1: the same bits as sinpi without its
// general reduction (the f50 solvers' sinc arguments lie in [0, 1], up to a rounding).
template <class T>
EPC_FAST_INLINE T sinpi_unit(T x) {
    const bool past_half = x > T(0.5);  // round(x) = 1 (0.5 itself rounds to even, 0)
    const T s = sinpi_reduced(past_half ? x - T(1) : x);  // x - 1 exact (Sterbenz)
    return past_half ? -s : s;
}

// cos(pi x) for |x| <= 1, as sin(pi (1/2 - |x|)): 1/2 - |x| is exact for |x| >= 1/4
// (Sterbenz), so cos keeps its relative precision near its zero at 1/2; below 1/4 the rounding
// of the subtraction moves cos by at most 1 ulp. 1/2 - |x| lies in [-1/2, 1/2], where sinpi
// needs no reduction (round gives 0, ties to even included).
template <class T>
EPC_FAST_INLINE T cospi_small(T x) {
    return sinpi_reduced(T(0.5) - std::fabs(x));
}

// 2^k for an integer-valued k in T's normal exponent range ([-1022, 1023] for float64,
// [-126, 127] for float32), built from its bits (vectorises where ldexp does not): k + bias
// lands in the low mantissa bits of k + bias + 1.5 * 2^mantissa_bits.
template <class T>
EPC_FAST_INLINE T pow2_integer(T k) {
    using F = FloatFormat<T>;
    const T t = (k + T(F::bias)) + F::shifter;
    typename F::Bits bits;
    std::memcpy(&bits, &t, sizeof bits);
    bits <<= F::mantissa_bits;
    T r;
    std::memcpy(&r, &bits, sizeof r);
    return r;
}

// exp(r) of the reduction x = k ln 2 + r, |r| <= ln(2)/2 (Cody-Waite, ln 2 split so that
// k ln2_hi is exact), by its Taylor polynomial; k is returned in `k`. For |x| below 2^51 ln 2.
template <class T>
EPC_FAST_INLINE T exp_reduced(T x, T& k) {
    constexpr bool wide = sizeof(T) == sizeof(double);
    constexpr T inv_ln2 = T(1.4426950408889634);
    // ln 2 in two parts, the first with few enough significant bits that k ln2_hi is exact
    constexpr T ln2_hi = wide ? T(0.6931471803691238) : T(0.693145751953125);  // 32 / 16 bits
    constexpr T ln2_lo = wide ? T(1.9082149292705877e-10) : T(1.428606765330187e-06);
    k = round_to_integer(x * inv_ln2);
    const T r = (x - k * ln2_hi) - k * ln2_lo;
    return poly::horner(poly::exp_coefficients, r);
}

// exp(x) for x <= 0 (the jitter factor's argument is never positive): exp_reduced's e^r times
// 2^k applied in two halves so that results below the smallest normal underflow gradually. 0
// below -746 (float32: -104), where exp underflows to 0 anyway. float64: <= 2 ulp.
template <class T>
EPC_FAST_INLINE T exp_poly(T x) {
    constexpr bool wide = sizeof(T) == sizeof(double);
    constexpr T lowest = wide ? T(-746.0) : T(-104.0);
    const T xc = x < lowest ? lowest : x;
    T k;
    const T e = exp_reduced(xc, k);
    const T k1 = round_to_integer(T(0.5) * k);
    const T scaled = e * pow2_integer(k1) * pow2_integer(k - k1);
    return x < lowest ? T(0) : scaled;
}

// asin(z) for |z| <= 1/2.
template <class T>
EPC_FAST_INLINE T asin_small(T z) {
    const T t = z * z;
    return z + z * t * poly::horner(poly::asin_coefficients, t);
}

// The diffraction MTF (2/pi)(acos nu - nu sqrt(1 - nu^2)) for nu in [1/2, 1], as a function of
// z = sqrt((1 - nu)/2) = sin(phi/2) in [0, 1/2], nu = cos phi: (4 asin z - sin(4 asin z)) / pi
// = z^3 P(z^2). No two terms cancel, so it keeps its relative precision down to nu = 1, where
// it vanishes as z^3.
template <class T>
EPC_FAST_INLINE T diffraction_from_half_angle_sine(T z) {
    const T t = z * z;
    return z * t * poly::horner(poly::diffraction_coefficients, t);
}

}  // namespace epc_fast
