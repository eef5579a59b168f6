// The MTF factors (MODEL.md section 5), each 1 at f = 0. Same names as in
// python/epc_fast/reference.py; here each takes the lengths it multiplies f by, precomputed
// per point, because the bisection calls them many times for the same point.
#pragma once

#include <cmath>
#include <limits>

#include "constants.h"
#include "polynomials.h"

namespace epc_fast {

// 1: sin(pi x) / (pi x), 1 at x = 0. Written as a select, not a branch, so that lane loops
// vectorise; sinpi's exact argument reduction keeps its digits near the zeros at integers.
EPC_FAST_INLINE double sinc(double x) {
    const double s = sinpi(x) / (pi * x);
    return x == 0.0 ? 1.0 : s;
}

// 1: circular-pupil diffraction at nu = f lambda F (clamped to 1, where it is 0):
// (2/pi) (acos nu - nu sqrt((1 - nu)(1 + nu))) up to nu = 1/2; above, where those two terms
// cancel, the same function written in z = sqrt((1 - nu)/2) (diffraction_from_half_angle_sine),
// which keeps its relative precision down to the cut-off. Both are computed and one is
// selected, so the lane loops have no branch.
EPC_FAST_INLINE double mtf_diffraction(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    const double acos_v = half_pi - asin_small(v);
    const double low = (2.0 / pi) * (acos_v - v * std::sqrt((1.0 - v) * (1.0 + v)));
    const double high = diffraction_from_half_angle_sine(std::sqrt(0.5 * (1.0 - v)));
    return v <= 0.5 ? low : high;
}

// mm: side of the square light-collecting aperture, sqrt(a) p.
EPC_FAST_INLINE double pixel_aperture_mm(double pixel_pitch_um, double fill_factor) {
    return std::sqrt(fill_factor) * (pixel_pitch_um * um_to_mm);
}

// 1: |sinc(sqrt(a) p f)|.
EPC_FAST_INLINE double mtf_pixel(double f_cyc_per_mm, double aperture_mm) {
    return std::fabs(sinc(aperture_mm * f_cyc_per_mm));
}

// 1: |sinc(b f)| for a linear motion of length b mm.
EPC_FAST_INLINE double mtf_motion(double f_cyc_per_mm, double blur_mm) {
    return std::fabs(sinc(blur_mm * f_cyc_per_mm));
}

// 1: exp(-2 pi^2 (sigma_j f)^2), sigma_j in mm; sigma_j f is formed first so that no huge
// sigma_j squares to infinity.
EPC_FAST_INLINE double mtf_jitter(double f_cyc_per_mm, double jitter_mm) {
    const double t = jitter_mm * f_cyc_per_mm;
    return exp_poly(-2.0 * pi * pi * (t * t));
}

// The Newton and Halley f50 solvers need each factor's slope and curvature. A factor M enters
// the system MTF as a product, so what they add up are its log-derivatives: r = M'/M and
// r' = M''/M - (M'/M)^2, per unit of the factor's own argument (the caller applies the chain
// rule). The slopes only steer the solver: their rounding moves its path, never the root it
// converges to. Few divisions: they are the slowest vector instructions here.
struct Slopes {
    double value, r, dr;
};

// sinc(y), r = pi cot(pi y) - 1/y and r' = 1/y^2 - pi^2 / sin^2(pi y), for 0 <= y < 1 (inside
// f50's bracket). Below y = 1e-3, where those cancel, the series of ln sinc(y) =
// -(pi y)^2/6 - (pi y)^4/180 - ...: r = -pi^2 y/3 - pi^4 y^3/45, r' = -pi^2/3 - pi^4 y^2/15
// and sinc = 1 - (pi y)^2/6 + (pi y)^4/120 (truncation below 1e-12 relative).
EPC_FAST_INLINE Slopes sinc_slopes(double y) {
    constexpr double pi2 = pi * pi, pi4 = pi2 * pi2;
    const double sin_py = sinpi(y);
    const double inv_y = 1.0 / y;
    const double inv_sin = 1.0 / sin_py;
    const double value = sin_py * inv_y * (1.0 / pi);
    const double r = pi * cospi_small(y) * inv_sin - inv_y;
    const double dr = inv_y * inv_y - pi2 * (inv_sin * inv_sin);
    const double y2 = y * y;
    const bool small = y < 1e-3;
    // sinc by its series too where small: 1/y overflows for a subnormal y
    const double series = 1.0 - (pi2 / 6.0) * y2 + (pi4 / 120.0) * (y2 * y2);
    return {small ? series : value, small ? -y * (pi2 / 3.0 + (pi4 / 45.0) * y2) : r,
            small ? -(pi2 / 3.0) - (pi4 / 15.0) * y2 : dr};
}

// The diffraction MTF at nu with its first and second derivatives in nu (not divided by it:
// a spectrum adds them up first): D' = -(4/pi) sqrt(1 - nu^2), D'' = (4/pi) nu / sqrt(1 - nu^2).
struct DiffractionSlopes {
    double value, d1, d2;
};

EPC_FAST_INLINE DiffractionSlopes diffraction_slopes(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    const double root = std::sqrt((1.0 - v) * (1.0 + v));
    return {mtf_diffraction(v), -(4.0 / pi) * root, (4.0 / pi) * v / root};
}

// The diffraction MTF at nu with its log-slopes in nu (one division): r = D'/D and
// r' = D''/D - r^2. `High` = false when the caller knows nu <= 1/2, which skips the
// near-cut-off form (mtf_diffraction).
template <bool High>
EPC_FAST_INLINE Slopes diffraction_log_slopes(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    const double root_squared = (1.0 - v) * (1.0 + v);
    const double root = std::sqrt(root_squared);
    const double acos_v = half_pi - asin_small(v);
    double value = (2.0 / pi) * (acos_v - v * root);
    if (High) {
        const double high = diffraction_from_half_angle_sine(std::sqrt(0.5 * (1.0 - v)));
        value = v <= 0.5 ? value : high;
    }
    const double inv = 1.0 / (root * value);
    const double r = -(4.0 / pi) * root_squared * inv;
    return {value, r, (4.0 / pi) * v * inv - r * r};
}

// cycles/mm: f_hi, the smallest first zero of the factors (diffraction 1/(lambda_min F),
// pixel 1/(sqrt(a) p), motion 1/b) and, with jitter, jitter's own threshold crossing
// sqrt(ln(1/c) / (2 pi^2)) / sigma_j (ln(1/c) is the caller's: the C library's log has no
// place in a lane loop). MTF_sys decreases strictly on [0, f_hi] and is <= threshold at f_hi
// (MODEL.md section 6). Selects, not branches, so that lane loops vectorise.
EPC_FAST_INLINE double f50_bracket(double f_number, double shortest_wavelength_nm,
                                   double aperture_mm, double blur_mm, double jitter_um,
                                   double ln_inv_threshold) {
    const double diffraction_zero = 1.0 / (shortest_wavelength_nm * nm_to_mm * f_number);
    const double pixel_zero = 1.0 / aperture_mm;
    const double motion_zero = blur_mm > 0.0 ? 1.0 / blur_mm : std::numeric_limits<double>::infinity();
    const double jitter_cross = jitter_um > 0.0
                                    ? std::sqrt(ln_inv_threshold * (1.0 / (2.0 * pi * pi))) /
                                          (jitter_um * um_to_mm)
                                    : std::numeric_limits<double>::infinity();
    const double optics = diffraction_zero < pixel_zero ? diffraction_zero : pixel_zero;
    const double blurs = motion_zero < jitter_cross ? motion_zero : jitter_cross;
    return optics < blurs ? optics : blurs;
}

}  // namespace epc_fast
