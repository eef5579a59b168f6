// What a block's f50 start reads (start.h): the terms it has as the start sees them, ln(1/c)
// and the cubic start's scale, and every lane's lengths in float64.
#pragma once

#include <cmath>
#include <cstddef>

#include "../block.h"
#include "../constants.h"
#include "../lens.h"
#include "../mtf.h"
#include "../parallel.h"
#include "../params.h"
#include "guesses.h"

namespace epc_fast {
namespace detail {

// The terms of a block as its start sees them.
struct StartTerms {
    bool poly;        // a spectrum
    bool alignment;   // a burst's alignment residual, a Gaussian as jitter is: the two are one
    bool jitter;      // jitter or an alignment residual (gaussian_blur_mm)
    bool binning;     // binning other than a broadcast 1
    // the wavefront error and denoising: a lane with either takes no certified start (the
    // starts know neither factor), and float32 leaves denoising's lanes to float64 (its
    // transfer's phases 2 pi f p i lose float32's digits at large i)
    bool aberration, denoise;
    // a lens table (every lane of the call has one) takes the place of diffraction: the
    // bracket ends at the table's end, the start scales by where it falls to 1/2, no start is
    // certified, and float32 leaves its lanes to float64
    bool lens;
    // any of them or a demosaicker's table (no certified start either: the starts know none)
    bool optics;
};

template <class T>
EPC_FAST_INLINE StartTerms start_terms(const Spectrum& spectrum, const Block<T>& b) {
    StartTerms t;
    t.poly = spectrum.polychromatic();
    t.alignment = !(b.broadcast_is(alignment_error_um, 0.0) || b.broadcast_is(frames, 1.0));
    t.jitter = !b.broadcast_is(jitter_um, 0.0) || t.alignment;
    t.binning = !b.broadcast_is(binning, 1.0);
    t.aberration = !b.broadcast_is(wavefront_rms_waves, 0.0);
    t.denoise = !b.broadcast_is(denoise_sigma_px, 0.0);
    t.lens = b.lens_tables != nullptr;
    t.optics = t.aberration | t.denoise | t.lens | (b.demosaic_table != nullptr);
    return t;
}

// ln(1/c) into b.mtf, for the jitter bracket, and sqrt(ln(1/c) / ln 2) into b.slope, for the
// start's scaling (scratch until the solver runs); the C library's log only for a threshold
// other than 1/2, once for a broadcast threshold.
template <class T>
EPC_FAST_INLINE void threshold_terms(Block<T>& b) {
    constexpr std::size_t n = block_size;
    T* __restrict ln_inv_c = b.mtf;
    T* __restrict start_scale = b.slope;
    if (b.is_broadcast(mtf_threshold)) {
        const T l = ln_inverse_threshold<T>(b.broadcast[mtf_threshold]);
        const T scale = start_scale_of(l);
        for (std::size_t i = 0; i < n; ++i) ln_inv_c[i] = l;
        for (std::size_t i = 0; i < n; ++i) start_scale[i] = scale;
    } else {
        const double* __restrict threshold = b.x[mtf_threshold];
        for (std::size_t i = 0; i < n; ++i) ln_inv_c[i] = ln_inverse_threshold<T>(threshold[i]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) start_scale[i] = start_scale_of(ln_inv_c[i]);
    }
}

// Every lane's lengths in float64, rounded to T later (float32: after checking they fit), in
// b.scratch: lambda F, the shortest wavelength's (the bracket's optics zero), the pixel
// aperture, the jitter (with a burst's alignment residual), and the length of the starts'
// diffraction coordinate (lambda F, the mean wavelength's with a spectrum). Two loops, each of
// one type, as GCC vectorises them.
//
// Binning: the binned pixel's lengths (binned_lengths_mm); the bracket's pixel zero is at
// 1 / (k p) where a < 1 (the array factor's, below sqrt(a) p's), 1 / ap elsewhere
// (zero_length). A lane with an array factor (bin_pitch > 0) takes the start of the pixel
// alone, never certified: not settled.
template <class T>
EPC_FAST_INLINE void start_lengths(Spectrum::Extent extent, StartTerms terms,
                                   Block<T>& b, double* __restrict bin_pitch,
                                   double* __restrict zero_length) {
    constexpr std::size_t n = block_size;
    const auto& x = b.x;
    const bool poly = terms.poly;
    const double shortest_nm = extent.shortest_nm;
    const double* __restrict wavelength = x[wavelength_nm];
    const double* __restrict f_num_in = x[f_number];
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict fill = x[fill_factor];
    const double* __restrict jitter_um_ = x[jitter_um];
    const double mean_mm = extent.mean_nm * nm_to_mm;
    double* __restrict lf = b.scratch[0];
    double* __restrict lf_short = b.scratch[1];
    double* __restrict ap = b.scratch[2];
    double* __restrict jit = b.scratch[3];
    double* __restrict d_length = b.scratch[4];
    if (b.is_broadcast(fill_factor)) {  // pixel_aperture_mm, one sqrt
        const double root_fill = std::sqrt(b.broadcast[fill_factor]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) ap[i] = root_fill * (pitch[i] * um_to_mm);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) ap[i] = pixel_aperture_mm(pitch[i], fill[i]);
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double f_number_i = f_num_in[i];
        lf[i] = wavelength[i] * nm_to_mm * f_number_i;
        lf_short[i] = (poly ? shortest_nm : wavelength[i]) * nm_to_mm * f_number_i;
        jit[i] = jitter_um_[i] * um_to_mm;
        d_length[i] = poly ? mean_mm * f_number_i : lf[i];
    }
    if (terms.lens) lens_start_lengths(b, start_nu50, lf_short, d_length);
    if (terms.alignment) {
        const double* __restrict residual = x[alignment_error_um];
        const double* __restrict frames_in = x[frames];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i)
            jit[i] = gaussian_blur_mm(jitter_um_[i], residual[i], frames_in[i]);
    }
    if (terms.binning) {
        const double* __restrict k = x[binning];
        for (std::size_t i = 0; i < n; ++i) {
            const BinnedLengths<double> l = binned_lengths_mm(ap[i], pitch[i], fill[i], k[i]);
            ap[i] = l.aperture_mm;
            bin_pitch[i] = l.pitch_mm;
            zero_length[i] = l.pitch_mm > 0.0 ? k[i] * l.pitch_mm : l.aperture_mm;
        }
    }
}

}  // namespace detail
}  // namespace epc_fast
