// Denoising (docs/model.md, "System MTF" and "Exposure: T_MPE"): a Gaussian filter on the
// output image, its noise gain and its transfer. The term's pieces: its formulas (the names of
// python/epc_fast/reference/optics.py), its per-lane inputs (denoise_lanes, from start_f50), its
// factor of the system MTF with the log-slopes Newton and Halley need (apply_denoise,
// f50/system_mtf.h), whether a start can be certified with it, and its share's log and
// log-slopes (denoise_log_factor, sensitivity.h); its noise gain enters the exposure
// (exposure/sensor.h noise_gain_roots). A block whose sigma is a broadcast 0 never comes here:
// its solve is the one without the term, bit for bit.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "block.h"
#include "constants.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"

namespace epc_fast {

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

// Whether a lane's start can be certified (f50/start.h): only without the term, which the
// starts do not know.
EPC_FAST_INLINE bool denoise_certifiable(double denoise_sigma_px) {
    return denoise_sigma_px == 0.0;
}

namespace detail {

// A lane's weight h_i at tap i (as T), from its 1 / (2 sigma^2), 1 / Z and R: 0 past R.
template <class T>
EPC_FAST_INLINE T denoise_weight(T tap, T exponent_scale, T inverse_norm, T reach) {
    const T e = exp_poly(-(tap * tap) * exponent_scale);
    return tap <= reach ? e * inverse_norm : T(0);
}

// The filter's inputs in T for the lanes to solve, and `denoise`: whether any of them has the
// term. A lane not solved, or without denoising, gets R = 0 (no tap), so that the block's
// largest R is its lanes to solve's.
//
// A denoised lane's start (b.at) is moved towards the filter's: H is near the Gaussian
// exp(-2 pi^2 (sigma p)^2 f^2), whose threshold crossing f_c = sqrt(ln(1/c) / (2 pi^2)) / (sigma p)
// joins the start f0 of the other factors as Gaussians' widths add, f = (f0^-2 + f_c^-2)^-1/2
// (a start only: the solvers keep to the bracket, which the filter does not narrow).
template <class T>
void denoise_lanes(Block<T>& b, const T* ln_inverse_c) {
    const auto& x = b.x;
    const LaneFlag<T>* __restrict solve = b.solve;
    const double* __restrict sigma = x[denoise_sigma_px];
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict k = x[binning];
    // a broadcast sigma's filter once for the block, kept from block to block (its norm a sum
    // over its taps, and its weights where they are cached)
    const bool same = b.is_broadcast(denoise_sigma_px);
    if (same && !(b.memo_denoise_sigma == b.broadcast[denoise_sigma_px])) {
        const double sigma_same = b.broadcast[denoise_sigma_px];
        const bool on = sigma_same > 0.0;
        b.memo_denoise_sigma = sigma_same;
        b.memo_denoise_reach = on ? denoise_reach(sigma_same) : 0.0;
        b.memo_denoise_scale = on ? denoise_exponent_scale(sigma_same) : 0.0;
        b.memo_denoise_inverse_norm = on ? 1.0 / denoise_norm(sigma_same) : 1.0;
        const T reach_t = static_cast<T>(b.memo_denoise_reach);
        const T scale_t = static_cast<T>(b.memo_denoise_scale);
        const T inverse_norm_t = static_cast<T>(b.memo_denoise_inverse_norm);
        for (int tap = 1; tap <= Block<T>::denoise_cached_taps; ++tap)
            b.memo_denoise_h[tap - 1] = denoise_weight(static_cast<T>(tap), scale_t, inverse_norm_t, reach_t);
    }
    int taps = 0;
    if (same) {
        const T reach_same = static_cast<T>(b.memo_denoise_reach);
        const T scale_same = static_cast<T>(b.memo_denoise_scale);
        const T inverse_norm_same = static_cast<T>(b.memo_denoise_inverse_norm);
        int any = 0;
        EPC_FAST_SIMD_REDUCTION(+ : any)
        for (std::size_t i = 0; i < block_size; ++i) {
            const bool on = (solve[i] != 0) & (reach_same > T(0));
            b.denoise_reach[i] = on ? reach_same : T(0);
            b.denoise_scale[i] = on ? scale_same : T(0);
            b.denoise_inverse_norm[i] = on ? inverse_norm_same : T(1);
            b.output_pitch_mm[i] = static_cast<T>(pitch[i] * k[i] * um_to_mm);
            any += on;
        }
        taps = any > 0 ? static_cast<int>(b.memo_denoise_reach) : 0;
    } else {
        for (std::size_t i = 0; i < block_size; ++i) {
            const bool on = (solve[i] != 0) & (sigma[i] > 0.0);
            const double reach = on ? denoise_reach(sigma[i]) : 0.0;
            b.denoise_reach[i] = static_cast<T>(reach);
            b.denoise_scale[i] = static_cast<T>(on ? denoise_exponent_scale(sigma[i]) : 0.0);
            b.denoise_inverse_norm[i] = static_cast<T>(on ? 1.0 / denoise_norm(sigma[i]) : 1.0);
            b.output_pitch_mm[i] = static_cast<T>(pitch[i] * k[i] * um_to_mm);
            taps = reach > taps ? static_cast<int>(reach) : taps;
        }
    }
    b.denoise_taps = taps;
    b.denoise = taps > 0;
    // the weights: a broadcast sigma's the same in every lane to solve (a lane not solved takes
    // them too, harmlessly: its transfer is never read); per-lane ones cached up to 20 taps
    b.denoise_weights = same && taps <= Block<T>::denoise_cached_taps ? DenoiseWeights::same
                        : taps <= Block<T>::denoise_cached_taps      ? DenoiseWeights::cached
                                                                     : DenoiseWeights::formed;
    if (!b.denoise) return;
    if (b.denoise_weights == DenoiseWeights::cached) {
        const T* __restrict scale = b.denoise_scale;
        const T* __restrict inverse_norm = b.denoise_inverse_norm;
        const T* __restrict reach_t = b.denoise_reach;
        for (int tap = 1; tap <= taps; ++tap) {
            const T t = static_cast<T>(tap);
            T* __restrict h = b.denoise_h[tap - 1];
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i)
                h[i] = denoise_weight(t, scale[i], inverse_norm[i], reach_t[i]);
        }
    }
    T* __restrict at = b.at;
    const T* __restrict hi = b.hi;
    const T* __restrict reach_lane = b.denoise_reach;
    const T* __restrict output_pitch = b.output_pitch_mm;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        // (a denoised lane is never settled; a lane without the term keeps its start)
        const double width_mm = sigma[i] * static_cast<double>(output_pitch[i]);
        const double f_c = std::sqrt(static_cast<double>(ln_inverse_c[i]) / (2.0 * pi * pi)) / width_mm;
        const double f0 = static_cast<double>(at[i]);
        const double joined = 1.0 / std::sqrt(1.0 / (f0 * f0) + 1.0 / (f_c * f_c));
        const T start = static_cast<T>(joined);
        at[i] = (reach_lane[i] > T(0)) & (start > T(0)) & (start < hi[i]) ? start : at[i];
    }
}

// The filter's transfer H at b.at into b.denoise_value and, with Slopes, its first and second
// derivatives in f into b.denoise_d1, b.denoise_d2: a pass over the lanes per tap, up to the
// block's largest R; a lane past its own R adds 0. cos(2 pi x i) and sin(2 pi x i) come from
// tap 1's by rotation, (c, s)_{i+1} = (c c_1 - s s_1, s c_1 + c s_1), whose rounding grows by
// an ulp or two a tap (tens of ulp of 1 up to sigma = 5 px, against H >= 2^-20 where its
// slopes are used: apply_denoise_slopes); the weights are a broadcast sigma's or the block's cached
// ones where it has them (denoise_lanes), else formed at each tap.
template <bool Slopes, class T>
void denoise_factor(Block<T>& b) {
    constexpr std::size_t n = block_size;
    const T* __restrict at = b.at;
    const T* __restrict pitch = b.output_pitch_mm;
    const T* __restrict scale = b.denoise_scale;
    const T* __restrict inverse_norm = b.denoise_inverse_norm;
    const T* __restrict reach = b.denoise_reach;
    T* __restrict value = b.denoise_value;
    T* __restrict d1 = b.denoise_d1;
    T* __restrict d2 = b.denoise_d2;
    alignas(64) T c1[n], s1[n], c[n], s[n];
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const T fp = at[i] * pitch[i];
        const T x = fp < T(0.5) ? fp : T(0.5);
        const SinCos<T> one = sincospi(T(2) * x);
        c1[i] = c[i] = one.c;
        s1[i] = s[i] = one.s;
        value[i] = inverse_norm[i];
        d1[i] = T(0);
        d2[i] = T(0);
    }
    auto taps = [&](auto weights) EPC_FAST_LAMBDA_INLINE {
        constexpr DenoiseWeights W = decltype(weights)::value;
        for (int tap = 1; tap <= b.denoise_taps; ++tap) {
            const T t = static_cast<T>(tap);
            const T* __restrict row = b.denoise_h[W == DenoiseWeights::cached ? tap - 1 : 0];
            const T same = b.memo_denoise_h[tap <= Block<T>::denoise_cached_taps ? tap - 1 : 0];
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) {
                const T h = W == DenoiseWeights::same     ? same
                            : W == DenoiseWeights::cached ? row[i]
                                                          : denoise_weight(t, scale[i], inverse_norm[i], reach[i]);
                const T ct = c[i], st = s[i];
                value[i] += T(2) * h * ct;
                if (Slopes) {
                    const T w = T(2.0 * pi) * t * pitch[i];
                    d1[i] -= T(2) * h * w * st;
                    d2[i] -= T(2) * h * (w * w) * ct;
                }
                c[i] = ct * c1[i] - st * s1[i];
                s[i] = st * c1[i] + ct * s1[i];
            }
        }
    };
    using Weights = DenoiseWeights;
    switch (b.denoise_weights) {
        case Weights::same: taps(std::integral_constant<Weights, Weights::same>{}); break;
        case Weights::cached: taps(std::integral_constant<Weights, Weights::cached>{}); break;
        case Weights::formed: taps(std::integral_constant<Weights, Weights::formed>{}); break;
    }
    if (Slopes) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const bool held = at[i] * pitch[i] >= T(0.5);
            d1[i] = held ? T(0) : d1[i];
            d2[i] = held ? T(0) : d2[i];
        }
    }
}

// b.mtf times the filter's H at b.at (values only: bisection and Brent).
template <class T>
void apply_denoise(Block<T>& b) {
    denoise_factor<false>(b);
    T* __restrict mtf = b.mtf;
    const T* __restrict value = b.denoise_value;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) mtf[i] *= value[i];
}

// b.mtf, b.slope and b.curvature with the filter's factor: M H, R + H'/H, S + H''/H - (H'/H)^2.
template <bool Curvature, class T>
void apply_denoise_slopes(Block<T>& b) {
    denoise_factor<true>(b);
    T* __restrict mtf = b.mtf;
    T* __restrict slope = b.slope;
    T* __restrict curvature = b.curvature;
    const T* __restrict value = b.denoise_value;
    const T* __restrict d1 = b.denoise_d1;
    const T* __restrict d2 = b.denoise_d2;
    // Where H is below 2^-20 its sum of cosines has lost the digits its slopes need (a rounding
    // of its largest terms, ~1e-16, against H): the lane's slope is NaN there, which makes the
    // solver take a bisection step (f50/solvers.h, `usable`) instead of a step it cannot trust.
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const T inverse = T(1) / value[i];
        const T r = d1[i] * inverse;
        const bool reliable = value[i] >= T(0x1p-20);
        mtf[i] *= value[i];
        slope[i] = reliable ? slope[i] + r : std::numeric_limits<T>::quiet_NaN();
        if (Curvature) curvature[i] += d2[i] * inverse - r * r;
    }
}

}  // namespace detail
}  // namespace epc_fast
