// Photometry, T_MPE and blur (docs/model.md, "Photometry: from lux to electrons" and
// "Exposure: T_MPE"). Each function is the formula of the same name in
// python/epc_fast/reference/model.py, for one point.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "../brent.h"
#include "../constants.h"

namespace epc_fast {

// The product of `factors` over the product of `divisors`, with no intermediate overflow or
// underflow: the mantissas (std::frexp, in [0.5, 1)) are multiplied in the order given and the
// binary exponents added, then the two are joined once (std::ldexp). It rounds like the plain
// product and is inf or 0 only when the exact value is beyond float64's range.
template <std::size_t N, std::size_t M>
inline double scaled_product(const double (&factors)[N], const double (&divisors)[M]) {
    double mantissa = 1.0;
    int exponent = 0;
    for (const double v : factors) {
        int e = 0;
        mantissa *= std::frexp(v, &e);
        exponent += e;
    }
    for (const double v : divisors) {
        int e = 0;
        mantissa /= std::frexp(v, &e);
        exponent -= e;
    }
    return std::ldexp(mantissa, exponent);
}

// e-/s: photo-electron rate of one pixel, r = L R tau cos^4(theta) / (4 F^2) * K a (p 1e-6)^2.
// cos(theta) is sin(90 deg - |theta|), exact in its argument near 90 deg; the product is a
// scaled_product. A rate below the smallest normal double (2.2e-308 e-/s) is returned as 0, no
// light: it carries too few digits to divide by.
inline double electron_rate(double illuminance_lux, double reflectance, double lens_transmittance,
                            double field_angle_deg, double f_number, double electrons_per_lux_s_m2,
                            double fill_factor, double pixel_pitch_um) {
    const double cos_theta = std::sin((90.0 - std::fabs(field_angle_deg)) * deg_to_rad);
    const double cos2 = cos_theta * cos_theta;
    const double rate = scaled_product(
        {illuminance_lux, reflectance, lens_transmittance, cos2, cos2, electrons_per_lux_s_m2,
         fill_factor, pixel_pitch_um, pixel_pitch_um, um_to_m * um_to_m},
        {4.0, f_number, f_number});
    return rate >= std::numeric_limits<double>::min() ? rate : 0.0;
}

// Binning and bursts (docs/model.md, "Exposure: T_MPE"): the sensor reads k x k pixels as one
// output pixel and sums n frames of T/n each. The output pixel's rate is k^2 r and its dark current k^2 D;
// the PRNU of the sum of k^2 pixels is u / k; the full well is k^2 W a frame, n k^2 W over the
// burst; the read noise is that of n reads of k^2 pixels each (digital binning) or of one
// (charge binning); each frame moves by its own T/n of shake, as a stabilisation n times k.
// With k = n = 1 every one of these is its input, bit for bit.

// 1: k^2, the pixels read as one output pixel.
inline double binned_pixels(double binning) { return binning * binning; }

// e- rms: the read noise of one output pixel of the burst, sigma_r sqrt(n k^2) (readout 0,
// digital) or sigma_r sqrt(n) (readout 1, charge: the k x k pixels' charge summed before the
// read).
inline double burst_read_noise_e(double read_noise_e, double binning, double frames,
                                 double readout) {
    return read_noise_e * std::sqrt(frames * (readout == 1.0 ? 1.0 : binned_pixels(binning)));
}

// The SNR target as the solvers use it: sqrt(s) = 10^(snr_db/20). s itself is never formed: it
// would underflow below -3080 dB and overflow above +3080 dB, where its square root is fine.
struct SnrTarget {
    double root_s;  // 10^(snr_db/20): the target signal / noise

    explicit SnrTarget(double snr_db) : root_s(std::pow(10.0, snr_db / 20.0)) {}

    // u sqrt(s) = p + e exactly (std::fma gives the rounding error e of the product p). e is
    // kept where p is near 1, the only place it can matter (elsewhere 0, which also avoids
    // inf - inf for a huge u).
    struct PrnuProduct {
        double p, e;
    };
    PrnuProduct prnu_product(double prnu) const {
        const double p = prnu * root_s;
        const double e = std::fma(prnu, root_s, -p);
        return {p, std::fabs(p - 1.0) < 0.5 ? e : 0.0};
    }

    // PRNU caps the SNR at 1/u: unreachable when u sqrt(s) >= 1, decided on the exact product
    // (so exactly whenever sqrt(s) is a double, e.g. at 0, 20, 40, ... dB).
    bool capped_by(double prnu) const {
        const PrnuProduct x = prnu_product(prnu);
        return x.p > 1.0 || (x.p == 1.0 && x.e >= 0.0);
    }

    // w = 1 - s u^2 as (1 - u sqrt(s))(1 + u sqrt(s)) from the exact product: 1 - p is exact
    // near the cap, so w keeps its digits however close u sqrt(s) is to 1.
    double prnu_margin(double prnu) const {
#if EPC_FAST_FMA
        // the same from the fused operation: 1 -+ u sqrt(s), each rounded once
        return std::fma(-prnu, root_s, 1.0) * std::fma(prnu, root_s, 1.0);
#else
        const PrnuProduct x = prnu_product(prnu);
        return ((1.0 - x.p) - x.e) * ((1.0 + x.p) + x.e);
#endif
    }
};

// e-: the photo-electrons r T_MPE needed, the positive root of
// r^2 (1 - s u^2) T^2 - s (r + D) T - s sigma_r^2 = 0, written without cancellation:
// r T = q a,  a = sqrt(s) / (2 w) * (sqrt(s) + hypot(sqrt(s), 2 sigma_r sqrt(w) / q)),
// q = 1 + D/r, w = 1 - s u^2 (SnrTarget::prnu_margin). Only positive terms are added and
// nothing is squared; s itself is never formed. q a is formed as a + a D / r (a
// scaled_product), which overflows only when the answer does, and q alone only divides
// (where it overflows, the read-noise term takes its true limit, 0). a >= s >= 1e-300 inside
// the domain (snr_db >= -3000), so the electrons needed are always a normal double.
// Meaningful only for r > 0 and u sqrt(s) < 1.
inline double signal_electrons(double rate_e_per_s, const SnrTarget& target, double read_noise_e,
                               double dark_current_e_per_s, double prnu) {
    const double root_s = target.root_s;
    const double w = target.prnu_margin(prnu);
    const double q = 1.0 + dark_current_e_per_s / rate_e_per_s;
    const double read_term = 2.0 * read_noise_e * std::sqrt(w) / q;
    const double a = root_s / (2.0 * w) * (root_s + std::hypot(root_s, read_term));
    return a + scaled_product({a, dark_current_e_per_s}, {rate_e_per_s});
}

// e-: the same root as signal_electrons, by Brent's method. With E photo-electrons,
// (SNR_target / SNR)^2 - 1 = s variance / E^2 - 1 = w B / E + (sigma_r sqrt(s) / E)^2 - w,
// B = s q / w the electrons shot and dark noise alone would need: it decreases in E and
// vanishes at the root. On the bracket below B / E and (sigma_r sqrt(s) / E)^2 / w lie in
// [0, 1] (no overflow, no underflow that matters, no logarithm), and w is taken whole, so
// nothing cancels near the PRNU cap. With a = w r^2, b = s (r + D), c = s sigma_r^2 the root T
// of a T^2 - b T - c = 0 lies in [max(b/a, sqrt(c/a)), b/a + sqrt(c/a)], so E = r T lies in
// [max(B, C), B + C], C = sigma_r sqrt(s) / sqrt(w). B is formed as s/w + (s/w) D / r.
inline double signal_electrons_brent(double rate_e_per_s, const SnrTarget& target,
                                     double read_noise_e, double dark_current_e_per_s, double prnu,
                                     double rtol) {
    const double root_s = target.root_s;
    const double w = target.prnu_margin(prnu);
    const double shot = root_s * root_s / w;
    const double shot_and_dark =
        shot + scaled_product({shot, dark_current_e_per_s}, {rate_e_per_s});
    const double read = read_noise_e * root_s / std::sqrt(w);
    const double lo = std::fmax(shot_and_dark, read);
    const double hi = shot_and_dark + read;
    auto excess_noise = [&](double electrons) {
        const double read_part = read_noise_e * root_s / electrons;
        return w * (shot_and_dark / electrons) + read_part * read_part - w;
    };
    return brent_root(excess_noise, lo, hi, rtol);
}

// mm: blur length f_L tan(omega / k * T_MPE); +inf once the angle reaches fl(pi/2) (6e-17 below
// pi/2, so an angle of exactly fl(pi/2) counts as unbounded). The angle is a scaled_product: a
// huge shake over a tiny exposure, or the reverse, gives its true size rather than inf * 0.
inline double blur_length_mm(double focal_length_mm, double shake_deg_per_s, double stabilization,
                             double t_mpe_s) {
    const double angle_rad =
        scaled_product({shake_deg_per_s, deg_to_rad, t_mpe_s}, {stabilization});
    return angle_rad < half_pi ? focal_length_mm * std::tan(angle_rad)
                               : std::numeric_limits<double>::infinity();
}

}  // namespace epc_fast
