// A colour sensor's colour filter array (docs/model.md, "The colour filter array"; the names of
// python/epc_fast/reference/cfa.py). The term's pieces: the filters' mean transmittance on the
// electron rate (cfa_rate, exposure/stage.h), the colour correction's noise gain on every
// variance (color_noise_gain, with denoising's: exposure/sensor.h noise_gain_roots), the
// demosaicker's luminance MTF M_dem(f p_out) as a factor of the system MTF with the log-slopes
// Newton and Halley need (demosaic_lanes, mtf_demosaic, f50/system_mtf.h), whether a start can
// be certified with it, and its share's log and log-slope (demosaic_log_factor,
// sensitivity.h). A monochrome call (transmittance and gain a broadcast 1, no demosaicker's
// table) never comes here.
#pragma once

#include <cmath>
#include <cstddef>

#include "block.h"
#include "constants.h"
#include "exposure/exact.h"
#include "parallel.h"
#include "params.h"
#include "tabulated.h"

namespace epc_fast {

// (ln M_dem, f d ln M_dem / df) at f: the share's numerator and the log-slope (also the output
// pitch's, p d ln M_dem / dp, as M_dem is a function of x = f p_out), from the demosaicker's
// table in cycles per output pixel and the output pitch p_out = k p in mm.
struct DemosaicLogFactor {
    double log, f_slope;
};

EPC_FAST_INLINE DemosaicLogFactor demosaic_log_factor(double f_cyc_per_mm, double output_pitch_mm,
                                                      const MtfTable& table) {
    const double x = f_cyc_per_mm * output_pitch_mm;
    const TableValue v = tabulated(table, x);
    return {std::log(v.value), x * v.d1 / v.value};
}

namespace detail {

// The filters on every lane's electron rate, t r, in a block whose transmittance is not a
// broadcast 1; a lane whose rate leaves the moderate range is redone (exposure_lane).
template <class T>
EPC_FAST_INLINE void cfa_rate(Block<T>& b) {
    if (b.broadcast_is(cfa_transmittance, 1.0)) return;
    const double* __restrict t = b.x[cfa_transmittance];
    double* __restrict rate = b.rate;
    LaneFlag<double>* __restrict rate_normal = b.rate_normal;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double rt = rate[i] * t[i];
        rate[i] = rt;
        rate_normal[i] &= moderate(rt);
    }
}

// Whether a block's starts can be certified (f50/start.h): only without a demosaicker's table,
// which the starts do not know.
template <class T>
EPC_FAST_INLINE bool demosaic_certifiable(const Block<T>& b) {
    return b.demosaic_table == nullptr;
}

// The demosaicker's per-lane input (Inputs::demosaic): every lane's output pitch p_out = k p
// in mm, in T, for its M_dem(f p_out).
template <class T>
void demosaic_lanes(Block<T>& b) {
    const double* __restrict pitch = b.x[pixel_pitch_um];
    const double* __restrict k = b.x[binning];
    for (std::size_t i = 0; i < block_size; ++i)
        b.output_pitch_mm[i] = static_cast<T>(pitch[i] * k[i] * um_to_mm);
}

// M_dem (and with Slopes M', M'') at x = f p_out for every lane, f = b.at, into value, d1, d2;
// x into xs.
template <bool Slopes, class T>
EPC_FAST_INLINE void demosaic_values(const Block<T>& b, double* __restrict xs,
                                     double* __restrict value, double* __restrict d1,
                                     double* __restrict d2) {
    const T* __restrict at = b.at;
    const T* __restrict pitch = b.output_pitch_mm;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i)
        xs[i] = static_cast<double>(at[i]) * static_cast<double>(pitch[i]);
    table_lanes<block_size, Slopes>(*b.demosaic_table, xs, block_size, value, d1, d2);
}

// b.mtf times M_dem(f p_out) at b.at (values only).
template <class T>
void mtf_demosaic(Block<T>& b) {
    alignas(64) double xs[block_size], value[block_size];
    demosaic_values<false>(b, xs, value, nullptr, nullptr);
    T* __restrict mtf = b.mtf;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) mtf[i] *= static_cast<T>(value[i]);
}

// The same with its log-slopes in f: R + p M'/M, S + p^2 (M''/M - (M'/M)^2), M' in x = f p.
template <bool Curvature, class T>
void mtf_demosaic_slopes(Block<T>& b) {
    alignas(64) double xs[block_size], value[block_size], d1[block_size], d2[block_size];
    demosaic_values<true>(b, xs, value, d1, d2);
    const T* __restrict pitch_out = b.output_pitch_mm;
    T* __restrict mtf = b.mtf;
    T* __restrict slope = b.slope;
    T* __restrict curvature = b.curvature;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double p = static_cast<double>(pitch_out[i]);
        const double r = p * d1[i] / value[i];
        mtf[i] *= static_cast<T>(value[i]);
        slope[i] += static_cast<T>(r);
        if (Curvature) curvature[i] += static_cast<T>(p * p * d2[i] / value[i] - r * r);
    }
}

}  // namespace detail
}  // namespace epc_fast
