// The wavefront error's and denoising's part of f50's solve (optics.h's formulas over a block's
// lanes): their per-lane inputs, set once a block (optics_lanes, from start_f50), and their
// factors of the system MTF with the log-slopes Newton and Halley need (f50.h). A block whose
// wavefront error and sigma are a broadcast 0 never comes here: its solve is the one without
// either term, bit for bit.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "block.h"
#include "constants.h"
#include "optics.h"
#include "parallel.h"
#include "params.h"

namespace epc_fast {
namespace detail {

// The ATF's depth and the filter's inputs in T for the lanes to solve; `aberration` and
// `denoise` say whether any of them has the term. A lane not solved, or without denoising, gets
// R = 0 (no tap), so that the block's largest R is its lanes to solve's.
//
// A denoised lane's start (b.at) is moved towards the filter's: H is near the Gaussian
// exp(-2 pi^2 (sigma p)^2 f^2), whose threshold crossing f_c = sqrt(ln(1/c) / (2 pi^2)) / (sigma p)
// joins the start f0 of the other factors as Gaussians' widths add, f = (f0^-2 + f_c^-2)^-1/2
// (a start only: the solvers keep to the bracket, which the filter does not narrow).
template <class T>
void optics_lanes(Block<T>& b, bool any_aberration, bool any_denoise, const T* ln_inverse_c) {
    const auto& x = b.x;
    const LaneFlag<T>* __restrict solve = b.solve;
    if (any_aberration) {
        const double* __restrict wavefront = x[wavefront_rms_waves];
        int count = 0;
        for (std::size_t i = 0; i < block_size; ++i) {
            b.atf_depth[i] = static_cast<T>(aberration_depth(wavefront[i]));
            count += (solve[i] != 0) & (wavefront[i] > 0.0);
        }
        b.aberration = count > 0;
    }
    if (!any_denoise) return;
    const double* __restrict sigma = x[denoise_sigma_px];
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict k = x[binning];
    // a broadcast sigma's norm once for the block (a sum over its taps)
    const bool same = b.is_broadcast(denoise_sigma_px);
    const double same_norm = same ? denoise_norm(b.broadcast[denoise_sigma_px]) : 1.0;
    int taps = 0;
    for (std::size_t i = 0; i < block_size; ++i) {
        const bool on = (solve[i] != 0) & (sigma[i] > 0.0);
        const double reach = on ? denoise_reach(sigma[i]) : 0.0;
        b.denoise_reach[i] = static_cast<T>(reach);
        b.denoise_scale[i] = static_cast<T>(on ? denoise_exponent_scale(sigma[i]) : 0.0);
        b.denoise_inverse_norm[i] = static_cast<T>(on ? 1.0 / (same ? same_norm : denoise_norm(sigma[i])) : 1.0);
        b.output_pitch_mm[i] = static_cast<T>(pitch[i] * k[i] * um_to_mm);
        taps = reach > taps ? static_cast<int>(reach) : taps;
    }
    b.denoise_taps = taps;
    b.denoise = taps > 0;
    if (!b.denoise) return;
    T* __restrict at = b.at;
    const T* __restrict hi = b.hi;
    for (std::size_t i = 0; i < block_size; ++i) {
        if (!(b.denoise_reach[i] > T(0))) continue;  // (a denoised lane is never settled)
        const double width_mm = sigma[i] * static_cast<double>(b.output_pitch_mm[i]);
        const double f_c = std::sqrt(static_cast<double>(ln_inverse_c[i]) / (2.0 * pi * pi)) / width_mm;
        const double f0 = static_cast<double>(at[i]);
        const double joined = 1.0 / std::sqrt(1.0 / (f0 * f0) + 1.0 / (f_c * f_c));
        const T start = static_cast<T>(joined);
        at[i] = (start > T(0)) & (start < hi[i]) ? start : at[i];
    }
}

// The filter's transfer H at b.at into b.denoise_value and, with Slopes, its first and second
// derivatives in f into b.denoise_d1, b.denoise_d2 (optics.h denoise_transfer, lane by lane):
// a pass over the lanes per tap, up to the block's largest R; a lane past its own R adds 0.
template <bool Slopes, class T>
void denoise_factor(Block<T>& b) {
    constexpr std::size_t n = block_size;
    const T* __restrict at = b.at;
    const T* __restrict pitch = b.output_pitch_mm;
    const T* __restrict scale = b.denoise_scale;
    const T* __restrict inverse_norm = b.denoise_inverse_norm;
    const T* __restrict reach = b.denoise_reach;
    T* __restrict xs = b.denoise_x;
    T* __restrict value = b.denoise_value;
    T* __restrict d1 = b.denoise_d1;
    T* __restrict d2 = b.denoise_d2;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const T fp = at[i] * pitch[i];
        xs[i] = fp < T(0.5) ? fp : T(0.5);
        value[i] = inverse_norm[i];
        d1[i] = T(0);
        d2[i] = T(0);
    }
    for (int tap = 1; tap <= b.denoise_taps; ++tap) {
        const T t = static_cast<T>(tap);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const T e = exp_poly(-(t * t) * scale[i]);
            const T h = t <= reach[i] ? e * inverse_norm[i] : T(0);
            const SinCos<T> sc = sincospi(T(2) * xs[i] * t);
            value[i] += T(2) * h * sc.c;
            if (Slopes) {
                const T w = T(2.0 * pi) * t * pitch[i];
                d1[i] -= T(2) * h * w * sc.s;
                d2[i] -= T(2) * h * (w * w) * sc.c;
            }
        }
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
    // solver take a bisection step (f50.h, `usable`) instead of a step it cannot trust.
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

// Monochromatic diffraction's ATF at nu = f lambda F (a spectrum's is in its sum, f50.h):
// b.mtf times it (values only).
template <class T>
void apply_aberration(Block<T>& b) {
    const T* __restrict at = b.at;
    const T* __restrict lambda_f = b.lambda_f_mm;
    const T* __restrict depth = b.atf_depth;
    T* __restrict mtf = b.mtf;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) mtf[i] *= mtf_aberration(at[i] * lambda_f[i], depth[i]);
}

// The same with its log-slopes in f: R + lambda F A'/A, S + (lambda F)^2 (A''/A - (A'/A)^2).
template <bool Curvature, class T>
void apply_aberration_slopes(Block<T>& b) {
    const T* __restrict at = b.at;
    const T* __restrict lambda_f = b.lambda_f_mm;
    const T* __restrict depth = b.atf_depth;
    T* __restrict mtf = b.mtf;
    T* __restrict slope = b.slope;
    T* __restrict curvature = b.curvature;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const T lf = lambda_f[i];
        const AberrationSlopes<T> a = aberration_slopes(at[i] * lf, depth[i]);
        const T inverse = T(1) / a.value;
        const T r = a.d1 * inverse;
        mtf[i] *= a.value;
        slope[i] += lf * r;
        if (Curvature) curvature[i] += (lf * lf) * (a.d2 * inverse - r * r);
    }
}

// A lane's lens table: its index in x[lens], clamped to the tables (a stand-in lane's is 0).
template <class T>
EPC_FAST_INLINE const MtfTable& lens_table(const Block<T>& b, std::size_t i) {
    const std::vector<MtfTable>& tables = *b.lens_tables;
    const double index = b.x[lens][i];
    const std::size_t k = index >= 1.0 ? static_cast<std::size_t>(index) : 0;
    return tables[k < tables.size() ? k : tables.size() - 1];
}

// b.mtf = each lane's lens table at b.at, in place of diffraction (values only).
template <class T>
void lens_values(Block<T>& b) {
    for (std::size_t i = 0; i < block_size; ++i)
        b.mtf[i] = static_cast<T>(tabulated(lens_table(b, i), static_cast<double>(b.at[i])).value);
}

// The lens table in place of monochromatic diffraction's factor (f50.h diffraction_factor):
// L into b.mtf, L' and L'' into b.slope and b.curvature, and L as their denominator.
template <bool Curvature, class T>
void lens_factor(Block<T>& b) {
    for (std::size_t i = 0; i < block_size; ++i) {
        const TableValue v = tabulated(lens_table(b, i), static_cast<double>(b.at[i]));
        b.mtf[i] = static_cast<T>(v.value);
        b.slope[i] = static_cast<T>(v.d1);
        if (Curvature) b.curvature[i] = static_cast<T>(v.d2);
        b.denominator[i] = static_cast<T>(v.value);
    }
}

// A colour sensor's demosaicker (Inputs::demosaic): every lane's output pitch p_out = k p in
// mm, in T, for its M_dem(f p_out).
template <class T>
void demosaic_lanes(Block<T>& b) {
    const double* __restrict pitch = b.x[pixel_pitch_um];
    const double* __restrict k = b.x[binning];
    for (std::size_t i = 0; i < block_size; ++i)
        b.output_pitch_mm[i] = static_cast<T>(pitch[i] * k[i] * um_to_mm);
}

// b.mtf times M_dem(f p_out) at b.at (values only).
template <class T>
void apply_demosaic(Block<T>& b) {
    const MtfTable& table = *b.demosaic_table;
    for (std::size_t i = 0; i < block_size; ++i) {
        const double x = static_cast<double>(b.at[i]) * static_cast<double>(b.output_pitch_mm[i]);
        b.mtf[i] *= static_cast<T>(tabulated(table, x).value);
    }
}

// The same with its log-slopes in f: R + p M'/M, S + p^2 (M''/M - (M'/M)^2), M' in x = f p.
template <bool Curvature, class T>
void apply_demosaic_slopes(Block<T>& b) {
    const MtfTable& table = *b.demosaic_table;
    for (std::size_t i = 0; i < block_size; ++i) {
        const double p = static_cast<double>(b.output_pitch_mm[i]);
        const TableValue v = tabulated(table, static_cast<double>(b.at[i]) * p);
        const double r = p * v.d1 / v.value;
        b.mtf[i] *= static_cast<T>(v.value);
        b.slope[i] += static_cast<T>(r);
        if (Curvature) b.curvature[i] += static_cast<T>(p * p * v.d2 / v.value - r * r);
    }
}

}  // namespace detail
}  // namespace epc_fast
