// exp and log for any float64 argument as straight-line code, so that a lane loop calling them
// vectorises (glibc's scalar exp and log stop it; its vector variants couple lanes:
// polynomials.h). For a scan's draws (scan/draws.h) and its log-binned reductions.
//
// exp: Cody-Waite reduction x = k ln 2 + r, |r| <= ln(2)/2, Taylor polynomial (polynomials.h's
// exp_poly), 2^k applied in two halves: within 2 ulp, underflowing gradually below -708, +inf
// above 709.78. log: x = 2^e m with m in [sqrt(1/2), sqrt(2)), log m = 2 atanh(s), s = (m - 1)/(m +
// 1), by its odd series; within 2 ulp for positive normal and subnormal x, -inf at 0, NaN below 0
// or for NaN, +inf at +inf. tests/scan/running/test_core_plan.py measures both against mpmath.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "constants.h"
#include "polynomials.h"

namespace epc_fast {

EPC_FAST_INLINE double exp_any(double x) {
    constexpr double highest = 710.0;  // exp(710) overflows: the two halves of 2^1024 give inf
    const double xc = x > highest ? highest : x;
    const double e = exp_poly(xc);  // clamps below -746 to 0 itself
    return x > highest ? std::numeric_limits<double>::infinity() : e;
}

// exp_normal(x) takes arguments within this bound, where exp(x) is a normal number.
constexpr double exp_normal_bound = 700.0;

// exp(x) for |x| <= exp_normal_bound: exp_poly's reduction (exp_reduced), scaled by 2^k in
// one step, which is exact for a normal result: the same bits as exp_any, without the clamps
// and the two-step scaling that exp_any needs for the rest of the line. For a scan's draws,
// whose arguments are bounded (scan/draws.h).
EPC_FAST_INLINE double exp_normal(double x) {
    double k;
    const double e = exp_reduced(x, k);
    return e * pow2_integer(k);
}

namespace detail {

// 2 atanh(s) / s - 2 = sum over k >= 1 of 2 s^(2k) / (2k + 1): the coefficients of t = s^2,
// t^1 .. t^10 (|s| <= 0.1716: the next term is below 2e-19 of the first).
constexpr double atanh_series[] = {
    0.0, 2.0 / 3, 2.0 / 5, 2.0 / 7, 2.0 / 9, 2.0 / 11, 2.0 / 13, 2.0 / 15, 2.0 / 17, 2.0 / 19,
    2.0 / 21,
};

}  // namespace detail

EPC_FAST_INLINE double log_any(double x) {
    constexpr double ln2_hi = 0.6931471803691238;      // 32 significant bits: e ln2_hi exact
    constexpr double ln2_lo = 1.9082149292705877e-10;  // ln 2 - ln2_hi
    constexpr double sqrt_half = 0.70710678118654752440;
    const bool subnormal = x < std::numeric_limits<double>::min();
    const double xs = subnormal ? x * 0x1p54 : x;  // subnormal x scaled to a normal
    std::uint64_t bits;
    std::memcpy(&bits, &xs, sizeof bits);
    // the exponent and a mantissa in [1, 2), then m in [sqrt(1/2), sqrt(2))
    // the biased exponent as a double through the bits of 2^52 + it (AVX2 has no vector
    // conversion of 64-bit integers)
    const std::uint64_t exponent_bits = 0x4330000000000000u | (bits >> 52);
    double biased;
    std::memcpy(&biased, &exponent_bits, sizeof biased);
    double e = (biased - 0x1p52) - 1023.0 - (subnormal ? 54.0 : 0.0);
    const std::uint64_t mantissa_bits = (bits & 0x000FFFFFFFFFFFFFull) | 0x3FF0000000000000ull;
    double m;
    std::memcpy(&m, &mantissa_bits, sizeof m);
    const bool high = m * 0.5 >= sqrt_half;
    m = high ? m * 0.5 : m;
    e = high ? e + 1.0 : e;
    const double f = m - 1.0;  // exact (Sterbenz)
    const double s = f / (2.0 + f);
    const double t = s * s;
    const double series = poly::horner(detail::atanh_series, t);  // 2 atanh(s)/s - 2
    // log m = 2s + s series = f - (f - 2s) + s series; f - 2s = s f exactly in real numbers
    const double log_m = f - (s * f - s * series);
    const double result = e * ln2_hi + (log_m + e * ln2_lo);
    return x > 0.0 ? (x < std::numeric_limits<double>::infinity() ? result : x)
                   : x == 0.0 ? -std::numeric_limits<double>::infinity()
                              : std::numeric_limits<double>::quiet_NaN();
}

// log10(x) as log_any(x) / ln 10 (within 3 ulp).
EPC_FAST_INLINE double log10_any(double x) {
    constexpr double inv_ln10 = 0.43429448190325182765;
    return log_any(x) * inv_ln10;
}

}  // namespace epc_fast
