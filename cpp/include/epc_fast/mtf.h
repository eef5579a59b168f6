// The MTF factors (docs/model.md, "System MTF"), each 1 at f = 0. Same names as in
// python/epc_fast/reference/mtf.py; here each takes the lengths it multiplies f by, precomputed
// per point, because the bisection calls them many times for the same point.
#pragma once

#include <cmath>
#include <limits>

#include "constants.h"
#include "polynomials.h"

namespace epc_fast {

// Every formula is a template over the lanes' type T: float64, or float32 for f50's solve in the
// float32 precision mode (f50/solvers.h). Constants are rounded to T, so a float32 lane loop
// stays in float32 throughout.

// 1: sin(pi x) / (pi x), 1 at x = 0. Written as a select, not a branch, so that lane loops
// vectorise; sinpi's exact argument reduction keeps its digits near the zeros at integers.
template <class T>
EPC_FAST_INLINE T sinc(T x) {
    const T s = sinpi(x) / (T(pi) * x);
    return x == T(0) ? T(1) : s;
}

// 1: circular-pupil diffraction at nu = f lambda F (clamped to 1, where it is 0):
// (2/pi) (acos nu - nu sqrt((1 - nu)(1 + nu))) up to nu = 1/2; above, where those two terms
// cancel, the same function written in z = sqrt((1 - nu)/2) (diffraction_from_half_angle_sine),
// which keeps its relative precision down to the cut-off. Both are computed and one is
// selected, so the lane loops have no branch.
template <class T>
EPC_FAST_INLINE T mtf_diffraction(T nu) {
    const T v = nu < T(1) ? nu : T(1);
    const T acos_v = T(half_pi) - asin_small(v);
    const T low = T(2.0 / pi) * (acos_v - v * std::sqrt((T(1) - v) * (T(1) + v)));
    const T high = diffraction_from_half_angle_sine(std::sqrt(T(0.5) * (T(1) - v)));
    return v <= T(0.5) ? low : high;
}

// mm: side of the square light-collecting aperture, sqrt(a) p.
template <class T>
EPC_FAST_INLINE T pixel_aperture_mm(T pixel_pitch_um, T fill_factor) {
    return std::sqrt(fill_factor) * (pixel_pitch_um * T(um_to_mm));
}

// 1: |sinc(sqrt(a) p f)|.
template <class T>
EPC_FAST_INLINE T mtf_pixel(T f_cyc_per_mm, T aperture_mm) {
    return std::fabs(sinc(aperture_mm * f_cyc_per_mm));
}

// 1: the binned pixel, k x k pixels of pitch p read as one: |sinc(sqrt(a) p f) sin(k pi p f) /
// (k sin(pi p f))|, the second factor written as sinc(k p f) / sinc(p f) (which tends to +-1
// where sin(pi p f) -> 0 at k p f integer too). Takes the aperture sqrt(a) p and the pitch p in
// mm: a pitch of 0 leaves the pixel alone (sinc(0) / sinc(0) = 1), as at k = 1, and as the
// kernel passes it where a = 1 (binned_aperture_mm). For f below the first zero
// min(1/(sqrt(a) p), 1/(k p)) both sincs of p are positive.
template <class T>
EPC_FAST_INLINE T mtf_binned_pixel(T f_cyc_per_mm, T aperture_mm, T pitch_mm, T binning) {
    const T array = sinc(binning * pitch_mm * f_cyc_per_mm) / sinc(pitch_mm * f_cyc_per_mm);
    return std::fabs(sinc(aperture_mm * f_cyc_per_mm) * array);
}

// mm: the binned pixel's lengths as the kernel's f50 takes them. At a = 1, P_k(f) is
// sinc(k p f): one sinc of aperture k p and no pitch factor (pitch_mm 0); else the aperture
// sqrt(a) p and the pitch p of the array factor (k = 1: no array factor, pitch_mm 0).
template <class T>
struct BinnedLengths {
    T aperture_mm, pitch_mm;
};

EPC_FAST_INLINE BinnedLengths<double> binned_lengths_mm(double aperture_mm, double pixel_pitch_um,
                                                        double fill_factor, double binning) {
    const bool whole = fill_factor == 1.0, binned = binning > 1.0;
    const double pitch_mm = pixel_pitch_um * um_to_mm;
    return {binned & whole ? binning * pitch_mm : aperture_mm, binned & !whole ? pitch_mm : 0.0};
}

// mm: the Gaussians of jitter and of a burst's alignment residual as one, of rms
// sqrt(sigma_j^2 + sigma_a^2 (1 - 1/n)) (J(f) A(f), docs/model.md "System MTF"); sigma_j itself
// where there is no residual (n = 1 or sigma_a = 0). The root is the larger times
// sqrt(1 + (smaller / larger)^2), which neither overflows nor calls the C library's hypot (a
// lane loop vectorises it), within an ulp or two of hypot.
EPC_FAST_INLINE double gaussian_blur_mm(double jitter_um, double alignment_error_um, double frames) {
    const double residual_um = alignment_error_um * std::sqrt(1.0 - 1.0 / frames);
    const bool jitter_larger = jitter_um > residual_um;
    const double larger = jitter_larger ? jitter_um : residual_um;
    const double ratio = (jitter_larger ? residual_um : jitter_um) / larger;
    const double rms_um = larger * std::sqrt(1.0 + ratio * ratio);
    return (residual_um > 0.0 ? rms_um : jitter_um) * um_to_mm;
}

// 1: the alignment residual of a burst of n frames, each aligned to within sigma_a rms: the
// frames' offsets about their mean, of variance sigma_a^2 (1 - 1/n):
// exp(-2 pi^2 sigma_a^2 (1 - 1/n) f^2), sigma_a in mm (1 for one frame).
template <class T>
EPC_FAST_INLINE T mtf_alignment(T f_cyc_per_mm, T alignment_error_mm, T frames) {
    const T t = alignment_error_mm * f_cyc_per_mm;
    return exp_poly(T(-2.0 * pi * pi) * (T(1) - T(1) / frames) * (t * t));
}

// 1: |sinc(b f)| for a linear motion of length b mm.
template <class T>
EPC_FAST_INLINE T mtf_motion(T f_cyc_per_mm, T blur_mm) {
    return std::fabs(sinc(blur_mm * f_cyc_per_mm));
}

// 1: exp(-2 pi^2 (sigma_j f)^2), sigma_j in mm; sigma_j f is formed first so that no huge
// sigma_j squares to infinity.
template <class T>
EPC_FAST_INLINE T mtf_jitter(T f_cyc_per_mm, T jitter_mm) {
    const T t = jitter_mm * f_cyc_per_mm;
    return exp_poly(T(-2.0 * pi * pi) * (t * t));
}

// The Newton and Halley f50 solvers need each factor's slope and curvature. A factor M enters
// the system MTF as a product, so what they add up are its log-derivatives: r = M'/M and
// r' = M''/M - (M'/M)^2, per unit of the factor's own argument (the caller applies the chain
// rule). The slopes only steer the solver: their rounding moves its path, never the root it
// converges to. Few divisions: they are the slowest vector instructions here.
template <class T>
struct Slopes {
    T value, r, dr;
};

// Below this y, sinc_slopes_given uses the series of ln sinc: float64 1e-3, float32 3e-2. There the
// truncated series is within 1e-12 (float32: 1e-9) of the function, and above it the direct
// r = pi cot(pi y) - 1/y loses at most 1/(pi^2 y^2 / 3) ~ 3e5 (float32: 3e2) of its ulps to
// cancellation, which only slows the solver down a little where this factor is nearly flat.
template <class T>
constexpr T sinc_series_below = sizeof(T) == sizeof(double) ? T(1e-3) : T(3e-2);

// sinc(y), r = pi cot(pi y) - 1/y and r' = 1/y^2 - pi^2 / sin^2(pi y), for 0 <= y < 1 (inside
// f50's bracket), given sin(pi y) and 1/(y sin(pi y)): 1/y and 1/sin(pi y) are sin(pi y) and y
// times it, so a factor costs one division, and several factors one between them (sinc_slopes).
// Below sinc_series_below, where those cancel, the series of ln sinc(y) =
// -(pi y)^2/6 - (pi y)^4/180 - ...: r = -pi^2 y/3 - pi^4 y^3/45, r' = -pi^2/3 - pi^4 y^2/15
// and sinc = 1 - (pi y)^2/6 + (pi y)^4/120 (the caller passes any finite inv_y_sin there).
template <class T>
EPC_FAST_INLINE Slopes<T> sinc_slopes_given(T y, T sin_py, T inv_y_sin) {
    constexpr double pi2 = pi * pi, pi4 = pi2 * pi2;
    const T inv_y = sin_py * inv_y_sin;
    const T inv_sin = y * inv_y_sin;
    const T value = sin_py * inv_y * T(1.0 / pi);
    const T r = T(pi) * cospi_small(y) * inv_sin - inv_y;
    const T dr = inv_y * inv_y - T(pi2) * (inv_sin * inv_sin);
    const T y2 = y * y;
    const bool small = y < sinc_series_below<T>;
    // sinc by its series too where small: 1/y overflows for a subnormal y
    const T series = T(1) - T(pi2 / 6.0) * y2 + T(pi4 / 120.0) * (y2 * y2);
    return {small ? series : value, small ? -y * (T(pi2 / 3.0) + T(pi4 / 45.0) * y2) : r,
            small ? T(-(pi2 / 3.0)) - T(pi4 / 15.0) * y2 : dr};
}

// y sin(pi y), or 1 where the series is used (so that it never underflows into a product).
template <class T>
EPC_FAST_INLINE T sinc_denominator(T y, T sin_py) {
    return y < sinc_series_below<T> ? T(1) : y * sin_py;
}

// The pixel sinc at y1 and, with Motion, the motion sinc at y2, with their log-slopes, for one
// division shared with a third factor's denominator `other` (monochromatic diffraction's, from
// diffraction_log_slope_parts; 1 where there is none: a product by 1 is exact), whose inverse
// comes back in `inverse_other`: 1/D1 = D2 other / (D1 D2 other) and so on. D = y sin(pi y) lies
// in [sinc_series_below sin(pi sinc_series_below), 1) or is 1, and other in [3e-15, 1] in
// float32 (float64: [1e-40, 1]) below diffraction's cut-off, so the product neither overflows
// nor underflows while both y < 1 - 1e-15 or so. At a factor's zero (y = 1, or nu = 1 for
// other, which only an end of the bracket reaches) the slopes come out NaN instead of 0, which
// the solvers treat the same: not above the threshold (they take a bisection step).
template <class T>
struct SlopesPair {
    Slopes<T> first, second;
};

template <class T>
struct SlopesShared {
    SlopesPair<T> sincs;
    T inverse_other;
};

template <bool Motion, class T>
EPC_FAST_INLINE SlopesShared<T> sinc_slopes(T y1, T y2, T other) {
    const T sin1 = sinpi_unit(y1);
    const T d1 = sinc_denominator(y1, sin1);
    if (!Motion) {
        // the second factor's slopes as the first's, unused: GCC vectorises no lane loop that
        // copies a zeroed Slopes in
        const T inv = T(1) / (d1 * other);
        const Slopes<T> first = sinc_slopes_given(y1, sin1, other * inv);
        return {{first, first}, d1 * inv};
    }
    const T sin2 = sinpi_unit(y2);
    const T d2 = sinc_denominator(y2, sin2);
    const T d12 = d1 * d2;
    const T inv = T(1) / (d12 * other);
    const T inv_d1 = (d2 * other) * inv, inv_d2 = (d1 * other) * inv;
    return {{sinc_slopes_given(y1, sin1, inv_d1), sinc_slopes_given(y2, sin2, inv_d2)}, d12 * inv};
}

// The diffraction MTF at nu with its first and second derivatives in nu (not divided by it:
// a spectrum adds them up first): D' = -(4/pi) sqrt(1 - nu^2), D'' = (4/pi) nu / sqrt(1 - nu^2)
// below the cut-off, and D = D' = D'' = 0 past it (nu >= 1). A spectrum's longer wavelengths
// pass their cut-off inside f50's bracket (set by the shortest): there D'' is 0, not the
// 1/0 = inf of the formula at nu = 1, which made Halley's step vanish (f50/solvers.h).
template <class T>
struct DiffractionSlopes {
    T value, d1, d2;
};

template <class T>
EPC_FAST_INLINE DiffractionSlopes<T> diffraction_slopes(T nu) {
    const bool below = nu < T(1);
    const T v = below ? nu : T(1);
    const T root = std::sqrt((T(1) - v) * (T(1) + v));
    const T d2 = T(4.0 / pi) * v / root;
    return {mtf_diffraction(v), T(-(4.0 / pi)) * root, below ? d2 : T(0)};
}

// The diffraction MTF at nu with its log-slopes in nu, but for one division the caller
// shares (sinc_slopes): r = D'/D = slope_numerator / denominator and r' = D''/D - r^2 =
// curvature_numerator / denominator - r^2, denominator = sqrt(1 - nu^2) D. `High` = false when
// the caller knows nu <= 1/2, which skips the near-cut-off form (mtf_diffraction).
template <class T>
struct DiffractionParts {
    T value, slope_numerator, curvature_numerator, denominator;
};

template <bool High, class T>
EPC_FAST_INLINE DiffractionParts<T> diffraction_log_slope_parts(T nu) {
    const T v = nu < T(1) ? nu : T(1);
    const T root_squared = (T(1) - v) * (T(1) + v);
    const T root = std::sqrt(root_squared);
    const T acos_v = T(half_pi) - asin_small(v);
    T value = T(2.0 / pi) * (acos_v - v * root);
    if (High) {
        const T high = diffraction_from_half_angle_sine(std::sqrt(T(0.5) * (T(1) - v)));
        value = v <= T(0.5) ? value : high;
    }
    return {value, T(-(4.0 / pi)) * root_squared, T(4.0 / pi) * v, root * value};
}

// 1: nu dD/dnu = -(4/pi) nu sqrt(1 - nu^2) below the cut-off, 0 past it.
EPC_FAST_INLINE double diffraction_log_slope_numerator(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    return -(4.0 / pi) * v * std::sqrt((1.0 - v) * (1.0 + v));
}

// cycles/mm: f_hi, the smallest first zero of the factors (diffraction 1/(lambda_min F),
// pixel 1/(sqrt(a) p), motion 1/b) and, with jitter, jitter's own threshold crossing
// sqrt(ln(1/c) / (2 pi^2)) / sigma_j (ln(1/c) is the caller's: the C library's log has no
// place in a lane loop). MTF_sys decreases strictly on [0, f_hi] and is <= threshold at f_hi
// (docs/model.md, "The cut-off frequency f50"). Selects, not branches, so that lane loops
// vectorise. Takes the lengths (mm) the frequency multiplies, as the solvers do.
//
// The first zeros are one division: min(1/x, 1/y) is 1/max(x, y) bit for bit, as division
// rounds monotonically. `Jitter` = false, when the caller knows that no lane has jitter, skips
// the crossing's square root and division.
template <bool Jitter = true, class T>
EPC_FAST_INLINE T f50_bracket(T shortest_lambda_f_mm, T aperture_mm, T blur_mm, T jitter_mm,
                              T ln_inv_threshold) {
    constexpr T infinity = std::numeric_limits<T>::infinity();
    const T optics = shortest_lambda_f_mm > aperture_mm ? shortest_lambda_f_mm : aperture_mm;
    const T longest = optics > blur_mm ? optics : blur_mm;  // blur 0: no motion zero
    const T zero = T(1) / longest;
    if (!Jitter) return zero;
    const T jitter_cross = jitter_mm > T(0)
                               ? std::sqrt(ln_inv_threshold * T(1.0 / (2.0 * pi * pi))) / jitter_mm
                               : infinity;
    return zero < jitter_cross ? zero : jitter_cross;
}

}  // namespace epc_fast
