// The lens's wavefront error (docs/model.md, "System MTF"): Shannon's aberration transfer
// function (ATF) on the diffraction MTF. The term's pieces: its formulas (the names of
// python/epc_fast/reference/optics.py), its per-lane input (aberration_lanes, from start_f50),
// its factor of the system MTF with the log-slopes Newton and Halley need (apply_aberration,
// f50/system_mtf.h), whether a start can be certified with it, and its share's log and
// log-slopes (aberration_log_factor, sensitivity.h). A block whose wavefront error is a
// broadcast 0 never comes here: its solve is the one without the term, bit for bit.
#pragma once

#include <cmath>
#include <cstddef>

#include "block.h"
#include "constants.h"
#include "mtf.h"
#include "parallel.h"
#include "params.h"

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

// Whether a lane's start can be certified (f50/start.h): only without the term, which the
// starts do not know.
EPC_FAST_INLINE bool aberration_certifiable(double wavefront_rms_waves) {
    return wavefront_rms_waves == 0.0;
}

// (ln(D_W / D), f d ln(D_W / D) / df, W d ln D_W / dW) at f: the wavefront error's factor of the
// diffraction MTF, D_W = sum_i w_i D_i ATF_i against D = sum_i w_i D_i (`value`, with
// `slope_numerator` = sum_i w_i nu_i dD_i/dnu). D - D_W = sum_i w_i D_i a (1 - 4 (nu_i - 1/2)^2),
// a = (W/0.18)^2, is formed without cancellation, and so its log1p.
struct AberrationLogFactor {
    double log, f_slope, w_slope;
};

inline AberrationLogFactor aberration_log_factor(double f, double f_number, double wavelength_nm,
                                                 const Spectrum& spectrum, double depth,
                                                 double value, double slope_numerator) {
    double deficit = 0.0, aberrated_numerator = 0.0;
    auto line = [&](double lambda_nm, double w) {
        const double raw = f * (lambda_nm * nm_to_mm) * f_number;
        const double nu = raw < 1.0 ? raw : 1.0;
        const double d = mtf_diffraction(nu), c = nu - 0.5;
        const double bowl = 1.0 - 4.0 * (c * c);
        deficit += w * d * depth * bowl;
        aberrated_numerator += w * (diffraction_log_slope_numerator(nu) * (1.0 - depth * bowl) +
                                    d * 8.0 * depth * nu * c);
    };
    if (spectrum.polychromatic()) {
        for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k)
            line(spectrum.wavelengths_nm[k], spectrum.weights[k]);
    } else {
        line(wavelength_nm, 1.0);
    }
    const double aberrated = value - deficit;
    return {std::log1p(-deficit / value), aberrated_numerator / aberrated - slope_numerator / value,
            -2.0 * deficit / aberrated};
}

namespace detail {

// The ATF's depth a = (W / 0.18)^2 in T for every lane, and `aberration`: whether a lane to
// solve has the term.
template <class T>
void aberration_lanes(Block<T>& b) {
    const LaneFlag<T>* __restrict solve = b.solve;
    const double* __restrict wavefront = b.x[wavefront_rms_waves];
    int count = 0;
    for (std::size_t i = 0; i < block_size; ++i) {
        b.atf_depth[i] = static_cast<T>(aberration_depth(wavefront[i]));
        count += (solve[i] != 0) & (wavefront[i] > 0.0);
    }
    b.aberration = count > 0;
}

// Monochromatic diffraction's ATF at nu = f lambda F (a spectrum's is in its sum,
// f50/system_mtf.h): b.mtf times it (values only).
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

}  // namespace detail
}  // namespace epc_fast
