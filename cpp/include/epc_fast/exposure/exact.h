// Arithmetic with the bits of exposure/point.h's formulas, in straight-line code that
// vectorises, for the exposure stage's vector path (stage.h): range checks under which a plain
// product is the scaled one, a correctly rounded quotient from a shared reciprocal, an exact
// product's error, tan from two sines, and hypot without a division.
#pragma once

#include <cmath>
#include <limits>

#include "../constants.h"
#include "../polynomials.h"

namespace epc_fast {
namespace detail {

// Whether a partial product is a normal double. A plain product of positive factors whose every
// partial product is normal equals scaled_product's result bit for bit (the same roundings, no
// scaling needed).
EPC_FAST_INLINE bool normal(double v) {
    return (v >= std::numeric_limits<double>::min()) & (v <= std::numeric_limits<double>::max());
}

// Whether v lies inside 2^-900..2^900, where a quotient formed by divide_by is the correctly
// rounded one (its residual neither underflows nor overflows).
EPC_FAST_INLINE bool moderate(double v) {
    return (v >= 0x1p-900) & (v <= 0x1p900);
}

// a / b, rounded correctly, from inverse_b = 1 / b rounded: one division then serves every
// quotient by b. q = a inverse_b is within an ulp of a / b; the residual a - q b is exact with a
// fused multiply-add, and q + (a - q b) inverse_b, rounded once, is the correctly rounded a / b
// (Markstein, IBM J. Res. Dev. 34(1), 1990) for a, b and a / b inside 2^-900..2^900 (moderate;
// the callers send other lanes to exposure_lane). Checked against the division for 2e8 random
// and adversarial pairs (tests/core/test_exposure.py checks the kernel's results). The
// unfused build divides.
EPC_FAST_INLINE double divide_by(double a, double b, double inverse_b) {
#if EPC_FAST_FMA
    const double q = a * inverse_b;
    return std::fma(std::fma(-q, b, a), inverse_b, q);
#else
    (void)inverse_b;
    return a / b;
#endif
}

#if !EPC_FAST_FMA
// The rounding error a b - fl(a b), exactly (Dekker's product with Veltkamp's split): what
// std::fma(a, b, -a * b) gives, in plain arithmetic that vectorises everywhere. Exact for
// |a|, |b| < 1e300 whose product neither overflows nor underflows. Only in the unfused build:
// under -ffp-contract=fast the compiler could fuse inside the split, and the fused build has
// std::fma at the places that need an exact product.
EPC_FAST_INLINE double product_error(double a, double b) {
    constexpr double split = 134217729.0;  // 2^27 + 1
    const double p = a * b;
    const double ca = split * a, cb = split * b;
    const double a_hi = ca - (ca - a), a_lo = a - a_hi;
    const double b_hi = cb - (cb - b), b_lo = b - b_hi;
    return ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
}
#endif

// tan(angle) for 0 <= angle < pi/2, as sinpi(t) / cospi(t) with t = angle / pi carried in two
// doubles (t_hi + t_lo, Dekker's product): cospi's argument 1/2 - t_hi is exact, and t_lo keeps
// the digits that tan's condition number near pi/2 would otherwise amplify. Within a few ulp
// of the C library's tan of the same angle. Both arguments lie in [0, 1/2], where sinpi
// reduces nothing (round gives 0, 1/2 included: ties to even), so sinpi_reduced gives sinpi's
// bits; for a larger angle the result is meaningless and the caller selects inf instead.
EPC_FAST_INLINE double tan_of_angle(double angle) {
    constexpr double inv_pi_hi = 0.3183098861837907;     // 1/pi rounded
    constexpr double inv_pi_lo = -1.9678676675182486e-17;  // 1/pi - inv_pi_hi
#if EPC_FAST_FMA
    // 1/2 - angle inv_pi_hi exactly, rounded once: no rounding error to carry (and none that a
    // fused t_hi could count twice)
    const double fused_cos_arg = std::fma(-angle, inv_pi_hi, 0.5) - angle * inv_pi_lo;
    return sinpi_reduced(angle * inv_pi_hi + angle * inv_pi_lo) / sinpi_reduced(fused_cos_arg);
#else
    const double t_hi = angle * inv_pi_hi;
    const double t_lo = product_error(angle, inv_pi_hi) + angle * inv_pi_lo;
    const double cos_arg = (0.5 - t_hi) - t_lo;
    return sinpi_reduced(t_hi + t_lo) / sinpi_reduced(cos_arg);
#endif
}

// Above this y, hypot_moderate's y^2 could overflow: the caller redoes the lane.
constexpr double hypot_moderate_max = 0x1p500;

// hypot(x, y) = sqrt(x^2 + y^2) as it reads, with no division, for x in [1e-150, 1e150] (10^(snr/20)
// inside the SNR domain) and 0 <= y <= hypot_moderate_max: x^2 is a normal double, x^2 + y^2
// cannot overflow, and a y^2 that underflows is below 1e-16 of x^2's ulp. x exactly when
// y = 0 (sqrt(fl(x^2)) = x in binary arithmetic), else within 1 ulp.
EPC_FAST_INLINE double hypot_moderate(double x, double y) {
#if EPC_FAST_FMA
    return std::sqrt(std::fma(x, x, y * y));
#else
    return std::sqrt(x * x + y * y);
#endif
}

}  // namespace detail
}  // namespace epc_fast
