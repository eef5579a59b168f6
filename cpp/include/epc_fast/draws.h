// A scan's random values from its uniforms (philox.h): the inverse of each distribution's CDF,
// as docs/scan.md's draw contract writes it and python/epc_fast/scan/streams.py computes it.
//
// Python builds each distribution's spec (scan/distributions.py stream_spec): which transform,
// its constants, and for a truncated normal or log-normal the CDF's values at the bounds, so
// that the core needs only the inverse normal CDF (ndtri) and exp.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "block.h"
#include "constants.h"
#include "elementary.h"
#include "parallel.h"

namespace epc_fast {

namespace detail {

// AS 241's rational for r = sqrt(-log(min(p, 1 - p))) above 5 (p below about 1e-11).
EPC_FAST_INLINE double ndtri_far(double r) {
    const double rf = r - 5.0;
    return (((((((2.01033439929228813265e-7 * rf + 2.71155556874348757815e-5) * rf +
                 1.24266094738807843860e-3) * rf + 2.65321895265761230930e-2) * rf +
               2.96560571828504891230e-1) * rf + 1.78482653991729133580e+0) * rf +
             5.46378491116411436990e+0) * rf + 6.65790464350110377720e+0) /
           (((((((2.04426310338993978564e-15 * rf + 1.42151175831644588870e-7) * rf +
                 1.84631831751005468180e-5) * rf + 7.86869131145613259100e-4) * rf +
               1.48753612908506148525e-2) * rf + 1.36929880922735805310e-1) * rf +
             5.99832206555887937690e-1) * rf + 1.0);
}

}  // namespace detail

// The inverse of the standard normal CDF for p in (0, 1): Wichura's algorithm AS 241
// (PPND16; Applied Statistics 37(3), 477-484, 1988), relative error about 1e-16. Three
// rational approximations: the centre |p - 1/2| <= 0.425, then r = sqrt(-log(min(p, 1 - p)))
// up to 5 (p down to about 1e-11) and beyond. 1 - p is exact for p >= 1/2 (Sterbenz), so both
// tails keep their precision on the uniforms' grid. Straight-line code with selects, so that a
// lane loop over it vectorises; log is log_any (elementary.h).
//
// ndtri_near takes the near tail's rational for every tail lane and sets `far` where r > 5,
// for the caller to redo with ndtri: lane loops then skip the far rational (p below 1e-11 is
// one draw in 10^11).
EPC_FAST_INLINE double ndtri_near(double p, unsigned char& far) {
    const double q = p - 0.5;
    const bool centre = std::fabs(q) <= 0.425;
    const double rc = 0.180625 - q * q;
    const double central_num =
        q * (((((((2.5090809287301226727e+3 * rc + 3.3430575583588128105e+4) * rc +
                  6.7265770927008700853e+4) * rc + 4.5921953931549871457e+4) * rc +
                1.3731693765509461125e+4) * rc + 1.9715909503065514427e+3) * rc +
              1.3314166789178437745e+2) * rc + 3.3871328727963666080e+0);
    const double central_den =
        (((((((5.2264952788528545610e+3 * rc + 2.8729085735721942674e+4) * rc +
              3.9307895800092710610e+4) * rc + 2.1213794301586595867e+4) * rc +
            5.3941960214247511077e+3) * rc + 6.8718700749205790830e+2) * rc +
          4.2313330701600911252e+1) * rc + 1.0);
    const double tail_p = q < 0.0 ? p : 1.0 - p;
    // central lanes compute the tail on 1/2 (harmless) and take the central rational
    const double r = std::sqrt(-log_any(centre ? 0.5 : tail_p));
    const double rn = r - 1.6;
    const double near_num =
        (((((((7.74545014278341407640e-4 * rn + 2.27238449892691845833e-2) * rn +
              2.41780725177450611770e-1) * rn + 1.27045825245236838258e+0) * rn +
            3.64784832476320460504e+0) * rn + 5.76949722146069140550e+0) * rn +
          4.63033784615654529590e+0) * rn + 1.42343711074968357734e+0);
    const double near_den =
        (((((((1.05075007164441684324e-9 * rn + 5.47593808499534494600e-4) * rn +
              1.51986665636164571966e-2) * rn + 1.48103976427480074590e-1) * rn +
            6.89767334985100004550e-1) * rn + 1.67638483018380384940e+0) * rn +
          2.05319162663775882187e+0) * rn + 1.0);
    far = !centre && r > 5.0;
    // one division for the rational the lane takes
    const double num = centre ? central_num : q < 0.0 ? -near_num : near_num;
    return num / (centre ? central_den : near_den);
}

EPC_FAST_INLINE double ndtri(double p) {
    unsigned char far = 0;
    const double z = ndtri_near(p, far);
    if (!far) return z;
    const double r = std::sqrt(-log_any(p < 0.5 ? p : 1.0 - p));
    return p < 0.5 ? -detail::ndtri_far(r) : detail::ndtri_far(r);
}

// One distribution's transform from a uniform u in (0, 1) (docs/scan.md):
//   affine      clamp(a + u b, low, high)                                   Uniform
//   exp_affine  clamp(exp(a + u b), low, high)                              LogUniform
//   normal      z = ndtri(pa + u (pb - pa)), negated if mirror; clamp(a + b z, low, high)
//   lognormal   the same z; clamp(exp(a + b z), low, high)
//   empirical   samples[min(floor(u m), m - 1)]
enum class DrawKind { affine, exp_affine, normal, lognormal, empirical };

struct Draw {
    DrawKind kind = DrawKind::affine;
    double a = 0.0, b = 0.0, pa = 0.0, pb = 1.0, low = 0.0, high = 0.0;
    bool mirror = false;
    std::vector<double> samples;
};

EPC_FAST_INLINE double clamp_to(double v, double low, double high) {
    return v < low ? low : v > high ? high : v;
}

// values[i] = the transform of u[i], for every lane of a block.
//
// exp's argument a + u b, or a + b z with |z| < 8.3 (p at least 2^-53 from 0 and 1), stays
// within [-|a| - |b| z_max, |a| + |b| z_max]; where that lies within exp_normal_bound, as for
// any distribution of camera parameters, exp_normal gives exp_any's bits at half its cost.
inline void draw_values(const Draw& d, const double* __restrict u, double* __restrict values) {
    const double a = d.a, b = d.b, low = d.low, high = d.high;
    constexpr double z_max = 9.0;
    switch (d.kind) {
        case DrawKind::affine:
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(a + u[i] * b, low, high);
            return;
        case DrawKind::exp_affine:
            if (std::fabs(a) + std::fabs(b) <= exp_normal_bound) {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i)
                    values[i] = clamp_to(exp_normal(a + u[i] * b), low, high);
                return;
            }
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i)
                values[i] = clamp_to(exp_any(a + u[i] * b), low, high);
            return;
        case DrawKind::normal:
        case DrawKind::lognormal: {
            const double pa = d.pa, width = d.pb - d.pa, sign = d.mirror ? -1.0 : 1.0;
            // z, its far lanes redone, then the value
            alignas(64) double z[block_size];
            alignas(64) unsigned char far[block_size];
            int n_far = 0;
            EPC_FAST_SIMD_REDUCTION(+ : n_far)
            for (std::size_t i = 0; i < block_size; ++i) {
                z[i] = sign * ndtri_near(pa + u[i] * width, far[i]);
                n_far += far[i];
            }
            if (n_far > 0)
                for (std::size_t i = 0; i < block_size; ++i)
                    if (far[i]) z[i] = sign * ndtri(pa + u[i] * width);
            if (d.kind == DrawKind::normal) {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(a + b * z[i], low, high);
            } else if (std::fabs(a) + std::fabs(b) * z_max <= exp_normal_bound) {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(exp_normal(a + b * z[i]), low, high);
            } else {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(exp_any(a + b * z[i]), low, high);
            }
            return;
        }
        case DrawKind::empirical: {
            const double* __restrict s = d.samples.data();
            const std::size_t m = d.samples.size();
            const double scale = static_cast<double>(m);
            for (std::size_t i = 0; i < block_size; ++i) {
                const auto k = static_cast<std::size_t>(u[i] * scale);
                values[i] = s[k < m ? k : m - 1];
            }
            return;
        }
    }
}

}  // namespace epc_fast
