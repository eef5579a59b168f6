// The lens's wavefront error and denoising (docs/model.md, "System MTF" and "Exposure: T_MPE"):
// Shannon's aberration transfer function on the diffraction MTF, and a Gaussian filter on the
// output image, its noise gain and its transfer. Same names as python/epc_fast/reference/optics.py.
#pragma once

#include <cmath>
#include <cstddef>

#include "constants.h"
#include "polynomials.h"

namespace epc_fast {

// waves: the rms wavefront error at which Shannon's ATF reaches 0 at nu = 1/2.
constexpr double shannon_w0 = 0.18;

// 1: a = (W / 0.18)^2, the ATF's depth at nu = 1/2.
inline double aberration_depth(double wavefront_rms_waves) {
    const double r = wavefront_rms_waves / shannon_w0;
    return r * r;
}

// 1: Shannon's ATF at nu (held at 1 past the cut-off, where the diffraction MTF is 0):
// 1 - a (1 - 4 (nu - 1/2)^2) (R. R. Shannon, "The Art and Science of Optical Design", 1997).
template <class T>
EPC_FAST_INLINE T mtf_aberration(T nu, T depth) {
    const T v = nu < T(1) ? nu : T(1);
    const T c = v - T(0.5);
    return T(1) - depth * (T(1) - T(4) * (c * c));
}

// The ATF's derivatives in nu: -4 a (1 - 2 nu)... written as 8 a (nu - 1/2), and 8 a; 0 past
// the cut-off, where nu is held.
template <class T>
struct AberrationSlopes {
    T value, d1, d2;
};

template <class T>
EPC_FAST_INLINE AberrationSlopes<T> aberration_slopes(T nu, T depth) {
    const bool below = nu < T(1);
    const T v = below ? nu : T(1);
    const T c = v - T(0.5);
    return {T(1) - depth * (T(1) - T(4) * (c * c)), below ? T(8) * depth * c : T(0),
            below ? T(8) * depth : T(0)};
}

// Denoising: a separable Gaussian of sigma output pixels, sampled on the integers
// |i| <= R = ceil(4 sigma), e_i = exp(-i^2 / (2 sigma^2)), normalised to sum 1 (h_i = e_i / Z,
// Z = 1 + 2 sum_{i>=1} e_i). e_0 = 1 exactly, so a subnormal sigma (whose e_i underflow to 0)
// is the identity.

// The taps on one side, R = ceil(4 sigma) (0 at sigma = 0).
inline double denoise_reach(double denoise_sigma_px) { return std::ceil(4.0 * denoise_sigma_px); }

// 1 / (2 sigma^2): the exponent's scale (inf where sigma^2 underflows: e_i = 0 for i >= 1).
inline double denoise_exponent_scale(double denoise_sigma_px) {
    return 1.0 / (2.0 * denoise_sigma_px * denoise_sigma_px);
}

// e_i for i >= 1 (exp_poly: 0 below its range, as exp underflows there).
inline double denoise_tap(double i, double exponent_scale) { return exp_poly(-(i * i) * exponent_scale); }

// 1: Z = 1 + 2 sum_{i=1..R} e_i.
inline double denoise_norm(double denoise_sigma_px) {
    const double reach = denoise_reach(denoise_sigma_px), scale = denoise_exponent_scale(denoise_sigma_px);
    double sum = 0.0;
    for (double i = 1.0; i <= reach; i += 1.0) sum += denoise_tap(i, scale);
    return 1.0 + 2.0 * sum;
}

// 1: g = (sum_i h_i^2)^2, the factor by which the filter, in x and in y, multiplies the variance
// of white pixel noise; 1 at sigma = 0.
inline double noise_gain_denoise(double denoise_sigma_px) {
    if (!(denoise_sigma_px > 0.0)) return 1.0;
    const double reach = denoise_reach(denoise_sigma_px), scale = denoise_exponent_scale(denoise_sigma_px);
    const double inverse_norm = 1.0 / denoise_norm(denoise_sigma_px);
    double sum = 0.0;
    for (double i = 1.0; i <= reach; i += 1.0) {
        const double h = denoise_tap(i, scale) * inverse_norm;
        sum += h * h;
    }
    const double one_d = inverse_norm * inverse_norm + 2.0 * sum;
    return one_d * one_d;
}

// 1: d ln g / d ln sigma = 4 sum_i h_i^2 ((i/sigma)^2 - m) / sum_i h_i^2, m = sum_j h_j (j/sigma)^2
// (over both signs of i); 0 at sigma = 0.
inline double noise_gain_log_slope(double denoise_sigma_px) {
    if (!(denoise_sigma_px > 0.0)) return 0.0;
    const double sigma = denoise_sigma_px;
    const double reach = denoise_reach(sigma), scale = denoise_exponent_scale(sigma);
    const double inverse_norm = 1.0 / denoise_norm(sigma);
    double mean = 0.0, gain = inverse_norm * inverse_norm, weighted = 0.0;
    for (double i = 1.0; i <= reach; i += 1.0) {
        const double h = denoise_tap(i, scale) * inverse_norm;
        const double w = h > 0.0 ? (i / sigma) * (i / sigma) : 0.0;
        mean += 2.0 * h * w;
        gain += 2.0 * h * h;
        weighted += 2.0 * h * h * w;
    }
    // sum_i h_i^2 (w_i - m) with w_0 = 0
    const double centred = weighted - gain * mean;
    return 4.0 * centred / gain;
}

// cos(pi x) and sin(pi x) for any finite x: x - round(x) is exact, and (-1)^round(x) the sign.
template <class T>
struct SinCos {
    T s, c;
};

template <class T>
EPC_FAST_INLINE SinCos<T> sincospi(T x) {
    const T k = round_to_integer(x);
    const T r = x - k;
    const bool odd = k != T(2) * round_to_integer(T(0.5) * k);
    const T s = sinpi_reduced(r), c = cospi_small(r);
    return {odd ? -s : s, odd ? -c : c};
}

// The filter's transfer along the rows at f, H(f) = h_0 + 2 sum_{i>=1} h_i cos(2 pi x i),
// x = min(f p, 1/2) (held at the output's Nyquist value past it), with its first and second
// derivatives in f: H' = -2 sum h_i (2 pi i p) sin(2 pi x i) and H'' = -2 sum h_i (2 pi i p)^2
// cos(2 pi x i), both 0 past the Nyquist frequency. For one lane; `taps` its R.
struct DenoiseTransfer {
    double value, d1, d2;
};

inline DenoiseTransfer denoise_transfer(double f_cyc_per_mm, double denoise_sigma_px,
                                        double output_pitch_mm) {
    if (!(denoise_sigma_px > 0.0)) return {1.0, 0.0, 0.0};
    const double fp = f_cyc_per_mm * output_pitch_mm;
    const bool held = fp >= 0.5;
    const double x = held ? 0.5 : fp;
    const double reach = denoise_reach(denoise_sigma_px), scale = denoise_exponent_scale(denoise_sigma_px);
    const double inverse_norm = 1.0 / denoise_norm(denoise_sigma_px);
    double value = inverse_norm, d1 = 0.0, d2 = 0.0;
    for (double i = 1.0; i <= reach; i += 1.0) {
        const double h = denoise_tap(i, scale) * inverse_norm;
        const SinCos<double> sc = sincospi(2.0 * x * i);
        const double w = 2.0 * pi * i * output_pitch_mm;
        value += 2.0 * h * sc.c;
        d1 -= 2.0 * h * w * sc.s;
        d2 -= 2.0 * h * (w * w) * sc.c;
    }
    return {value, held ? 0.0 : d1, held ? 0.0 : d2};
}

// (ln H, f d ln H / df, sigma d ln H / d sigma) at f: sigma dh_i/dsigma = h_i ((i/sigma)^2 - m),
// m = sum_j h_j (j/sigma)^2, so sigma dH/dsigma = sum_i h_i (i/sigma)^2 (cos(2 pi x i) - H).
struct DenoiseLogFactor {
    double log, f_slope, sigma_slope;
};

inline DenoiseLogFactor denoise_log_factor(double f_cyc_per_mm, double denoise_sigma_px,
                                           double output_pitch_mm) {
    if (!(denoise_sigma_px > 0.0)) return {0.0, 0.0, 0.0};
    const double sigma = denoise_sigma_px;
    const DenoiseTransfer t = denoise_transfer(f_cyc_per_mm, sigma, output_pitch_mm);
    const double fp = f_cyc_per_mm * output_pitch_mm;
    const double x = fp >= 0.5 ? 0.5 : fp;
    const double reach = denoise_reach(sigma), scale = denoise_exponent_scale(sigma);
    const double inverse_norm = 1.0 / denoise_norm(sigma);
    double sigma_slope = 0.0;
    for (double i = 1.0; i <= reach; i += 1.0) {
        const double h = denoise_tap(i, scale) * inverse_norm;
        const double w = h > 0.0 ? (i / sigma) * (i / sigma) : 0.0;
        sigma_slope += 2.0 * h * w * (sincospi(2.0 * x * i).c - t.value);
    }
    return {std::log(t.value), f_cyc_per_mm * t.d1 / t.value, sigma_slope / t.value};
}

}  // namespace epc_fast
