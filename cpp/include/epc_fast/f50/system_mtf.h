// The system MTF of every lane of a block at its abscissa b.at, for f50's solvers (solvers.h):
// its value (bisection, Brent, the lens tables' end) or its value with the log-slopes and
// curvatures of every factor (Newton, Halley). The factors are mtf.h's; a lens table (lens.h)
// takes diffraction's place, and the wavefront error (aberration.h), denoising (denoise.h)
// and a colour sensor's demosaicker (cfa.h) multiply in where a block has them.
//
// The functions are templates over the terms a block uses: motion and jitter are compiled
// out of blocks that have none, and a monochromatic call never loops over a spectrum.
#pragma once

#include <cstddef>

#include "../aberration.h"
#include "../block.h"
#include "../cfa.h"
#include "../denoise.h"
#include "../lens.h"
#include "../mtf.h"
#include "../parallel.h"
#include "../params.h"

namespace epc_fast {
namespace detail {

// b.mtf = MTF_sys(b.at) for every lane (threshold and solve masks are the caller's).
template <bool Motion, bool Jitter, bool Binning, bool Poly, class T>
void system_mtf(const Spectrum& spectrum, Block<T>& b) {
    constexpr std::size_t n = block_size;
    const T* __restrict at = b.at;
    const T* __restrict f_num = b.f_number;
    T* __restrict mtf = b.mtf;
    if (Poly) {
        for (std::size_t i = 0; i < n; ++i) mtf[i] = T(0);
        for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k) {
            const T lambda_mm = static_cast<T>(spectrum.wavelengths_nm[k] * nm_to_mm);
            const T w = static_cast<T>(spectrum.weights[k]);
            if (b.aberration) {  // each wavelength's D times its ATF
                const T* __restrict depth = b.atf_depth;
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < n; ++i) {
                    const T nu = at[i] * lambda_mm * f_num[i];
                    mtf[i] += w * (mtf_diffraction(nu) * mtf_aberration(nu, depth[i]));
                }
                continue;
            }
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) mtf[i] += w * mtf_diffraction(at[i] * lambda_mm * f_num[i]);
        }
    } else if (b.lens_tables != nullptr) {
        mtf_lens(b);
    } else {
        const T* __restrict lambda_f = b.lambda_f_mm;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) mtf[i] = mtf_diffraction(at[i] * lambda_f[i]);
    }
    const T* __restrict aperture = b.aperture_mm;
    const T* __restrict blur = b.blur_mm;
    const T* __restrict jitter = b.jitter_mm;
    const T* __restrict bin_pitch = b.bin_pitch_mm;
    const T* __restrict bin_k = b.bin_k;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const T f = at[i];
        T m = mtf[i] * (Binning ? mtf_binned_pixel(f, aperture[i], bin_pitch[i], bin_k[i])
                                : mtf_pixel(f, aperture[i]));
        if (Motion) m *= mtf_motion(f, blur[i]);
        if (Jitter) m *= mtf_jitter(f, jitter[i]);
        mtf[i] = m;
    }
    if (b.aberration && !Poly) apply_aberration(b);
    if (b.denoise) apply_denoise(b);
    if (b.demosaic_table != nullptr) mtf_demosaic(b);
}

// Monochromatic diffraction at b.at: its value into b.mtf, its log-slopes' numerators, in f,
// into b.slope and b.curvature and their denominator into b.denominator
// (diffraction_log_slope_parts; system_mtf_slopes divides).
template <bool High, bool Curvature, class T>
void diffraction_factor(Block<T>& b) {
    const T* __restrict at = b.at;
    const T* __restrict lambda_f = b.lambda_f_mm;
    T* __restrict mtf = b.mtf;
    T* __restrict slope = b.slope;
    T* __restrict curvature = b.curvature;
    T* __restrict denominator = b.denominator;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const T lf = lambda_f[i];
        const DiffractionParts<T> d = diffraction_log_slope_parts<High>(at[i] * lf);
        mtf[i] = d.value;
        slope[i] = lf * d.slope_numerator;
        if (Curvature) curvature[i] = (lf * lf) * d.curvature_numerator;
        denominator[i] = d.denominator;
    }
}

// b.mtf, b.slope = M'/M and b.curvature = sum_i (M_i''/M_i - (M_i'/M_i)^2) at b.at, so that
// M''/M = slope^2 + curvature (M the product of the factors M_i). Newton skips the curvature.
template <bool Motion, bool Jitter, bool Binning, bool Poly, bool Curvature, class T>
void system_mtf_slopes(const Spectrum& spectrum, Block<T>& b) {
    constexpr std::size_t n = block_size;
    const T* __restrict at = b.at;
    const T* __restrict f_num = b.f_number;
    T* __restrict mtf = b.mtf;
    T* __restrict slope = b.slope;
    T* __restrict curvature = b.curvature;
    if (Poly) {  // D = sum_k w_k D_k, D' and D'' likewise; divided by D afterwards
        for (std::size_t i = 0; i < n; ++i) mtf[i] = slope[i] = curvature[i] = T(0);
        for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k) {
            const T lambda_mm = static_cast<T>(spectrum.wavelengths_nm[k] * nm_to_mm);
            const T w = static_cast<T>(spectrum.weights[k]);
            if (b.aberration) {  // (D A)' = D'A + D A', (D A)'' = D''A + 2 D'A' + D A''
                const T* __restrict depth = b.atf_depth;
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < n; ++i) {
                    const T lf = lambda_mm * f_num[i];
                    const T nu = at[i] * lf;
                    const DiffractionSlopes<T> d = diffraction_slopes(nu);
                    const AberrationSlopes<T> a = aberration_slopes(nu, depth[i]);
                    mtf[i] += w * (d.value * a.value);
                    slope[i] += (w * lf) * (d.d1 * a.value + d.value * a.d1);
                    if (Curvature)
                        curvature[i] += (w * (lf * lf)) *
                                        (d.d2 * a.value + T(2) * (d.d1 * a.d1) + d.value * a.d2);
                }
                continue;
            }
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) {
                const T lf = lambda_mm * f_num[i];
                const DiffractionSlopes<T> d = diffraction_slopes(at[i] * lf);
                mtf[i] += w * d.value;
                slope[i] += (w * lf) * d.d1;
                if (Curvature) curvature[i] += (w * (lf * lf)) * d.d2;
            }
        }
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const T r = slope[i] / mtf[i];
            slope[i] = r;
            if (Curvature) curvature[i] = curvature[i] / mtf[i] - r * r;
        }
    } else if (b.lens_tables != nullptr) {
        lens_factor<Curvature>(b);
    } else {
        const T* __restrict lambda_f = b.lambda_f_mm;
        T nu_max = T(0);
        EPC_FAST_SIMD_REDUCTION(max : nu_max)
        for (std::size_t i = 0; i < n; ++i) {
            const T nu = at[i] * lambda_f[i];
            nu_max = nu > nu_max ? nu : nu_max;
        }
        if (nu_max > T(0.5)) diffraction_factor<true, Curvature>(b);
        else diffraction_factor<false, Curvature>(b);
    }
    const T* __restrict aperture = b.aperture_mm;
    const T* __restrict blur = b.blur_mm;
    const T* __restrict jitter = b.jitter_mm;
    const T* __restrict bin_pitch = b.bin_pitch_mm;
    const T* __restrict bin_k = b.bin_k;
    const T* __restrict denominator = b.denominator;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const T f = at[i];
        T m = mtf[i], r = slope[i], s = Curvature ? curvature[i] : T(0);
        // pixel aperture and motion: one division between them, and monochromatic
        // diffraction's too (its slopes are still to be divided: diffraction_factor; a
        // spectrum's were divided above)
        const T a = aperture[i], l = Motion ? blur[i] : T(0);
        const SlopesShared<T> shared = sinc_slopes<Motion>(a * f, l * f, Poly ? T(1) : denominator[i]);
        if (!Poly) {
            r *= shared.inverse_other;
            if (Curvature) s = s * shared.inverse_other - r * r;
        }
        const Slopes<T> p = shared.sincs.first, q = shared.sincs.second;
        m *= p.value;
        r += a * p.r;
        if (Curvature) s += (a * a) * p.dr;
        if (Motion) {
            m *= q.value;
            r += l * q.r;
            if (Curvature) s += (l * l) * q.dr;
        }
        if (Binning) {  // the array factor sinc(k p f) / sinc(p f): its log-slopes subtract
            const T lp = bin_pitch[i], lk = bin_k[i] * lp;
            const SlopesShared<T> g = sinc_slopes<true>(lk * f, lp * f, T(1));
            const Slopes<T> whole = g.sincs.first, one = g.sincs.second;
            m *= whole.value / one.value;
            r += lk * whole.r - lp * one.r;
            if (Curvature) s += (lk * lk) * whole.dr - (lp * lp) * one.dr;
        }
        if (Jitter) {  // J = exp(-k f^2), k = 2 pi^2 sigma^2: J'/J = -2 k f, (J''/J - (J'/J)^2) = -2 k
            const T sigma = jitter[i];
            const T two_k = T(4.0 * pi * pi) * (sigma * sigma);
            m *= mtf_jitter(f, sigma);
            r += -two_k * f;
            if (Curvature) s += -two_k;
        }
        mtf[i] = m;
        slope[i] = r;
        if (Curvature) curvature[i] = s;
    }
    if (b.aberration && !Poly) apply_aberration_slopes<Curvature>(b);
    if (b.denoise) apply_denoise_slopes<Curvature>(b);
    if (b.demosaic_table != nullptr) mtf_demosaic_slopes<Curvature>(b);
}

}  // namespace detail
}  // namespace epc_fast
