// The MTF factors (MODEL.md section 5), each 1 at f = 0. Same names as in
// python/epc_fast/reference.py; here each takes the lengths it multiplies f by, precomputed
// per point, because the bisection calls them many times for the same point.
#pragma once

#include <cmath>

#include "constants.h"
#include "polynomials.h"

namespace epc_fast {

// 1: sin(pi x) / (pi x), 1 at x = 0. Written as a select, not a branch, so that lane loops
// vectorise; sinpi's exact argument reduction keeps its digits near the zeros at integers.
inline double sinc(double x) {
    const double s = sinpi(x) / (pi * x);
    return x == 0.0 ? 1.0 : s;
}

// 1: circular-pupil diffraction at nu = f lambda F (clamped to 1, where it is 0):
// (2/pi) (acos nu - nu sqrt((1 - nu)(1 + nu))) up to nu = 1/2; above, where those two terms
// cancel, the same function written in z = sqrt((1 - nu)/2) (diffraction_from_half_angle_sine),
// which keeps its relative precision down to the cut-off. Both are computed and one is
// selected, so the lane loops have no branch.
inline double mtf_diffraction(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    const double acos_v = half_pi - asin_small(v);
    const double low = (2.0 / pi) * (acos_v - v * std::sqrt((1.0 - v) * (1.0 + v)));
    const double high = diffraction_from_half_angle_sine(std::sqrt(0.5 * (1.0 - v)));
    return v <= 0.5 ? low : high;
}

// mm: side of the square light-collecting aperture, sqrt(a) p.
inline double pixel_aperture_mm(double pixel_pitch_um, double fill_factor) {
    return std::sqrt(fill_factor) * (pixel_pitch_um * um_to_mm);
}

// 1: |sinc(sqrt(a) p f)|.
inline double mtf_pixel(double f_cyc_per_mm, double aperture_mm) {
    return std::fabs(sinc(aperture_mm * f_cyc_per_mm));
}

// 1: |sinc(b f)| for a linear motion of length b mm.
inline double mtf_motion(double f_cyc_per_mm, double blur_mm) {
    return std::fabs(sinc(blur_mm * f_cyc_per_mm));
}

// 1: exp(-2 pi^2 (sigma_j f)^2), sigma_j in mm; sigma_j f is formed first so that no huge
// sigma_j squares to infinity.
inline double mtf_jitter(double f_cyc_per_mm, double jitter_mm) {
    const double t = jitter_mm * f_cyc_per_mm;
    return std::exp(-2.0 * pi * pi * (t * t));
}

// cycles/mm: f_hi, the smallest first zero of the factors (diffraction 1/(lambda_min F),
// pixel 1/(sqrt(a) p), motion 1/b) and, with jitter, jitter's own threshold crossing.
// MTF_sys decreases strictly on [0, f_hi] and is <= threshold at f_hi (MODEL.md section 6).
inline double f50_bracket(double f_number, double shortest_wavelength_nm, double aperture_mm,
                          double blur_mm, double jitter_um, double mtf_threshold) {
    double f_hi = std::fmin(1.0 / (shortest_wavelength_nm * nm_to_mm * f_number), 1.0 / aperture_mm);
    if (blur_mm > 0.0) f_hi = std::fmin(f_hi, 1.0 / blur_mm);
    if (jitter_um > 0.0)
        f_hi = std::fmin(f_hi, std::sqrt(std::log(1.0 / mtf_threshold) / (2.0 * pi * pi)) /
                                   (jitter_um * um_to_mm));
    return f_hi;
}

}  // namespace epc_fast
