// The exposure's inputs as the sensor's output pixel sees them: binning and bursts (the
// read noise, dark current, PRNU, full well and stabilisation of the burst's output pixel, and
// the rate times k^2: sensor_terms) and the noise gains that multiply every variance, of
// denoising (denoise.h) and of a colour sensor's colour correction (cfa.h): noise_gain_roots.
#pragma once

#include <cmath>
#include <cstddef>

#include "../block.h"
#include "../denoise.h"
#include "../parallel.h"
#include "../params.h"
#include "point.h"

namespace epc_fast {
namespace detail {

// The rows of Block::sensor_store (sensor_terms, below).
enum SensorRow : int { sensor_read, sensor_dark, sensor_prnu, sensor_well, sensor_stab, sensor_pixels };

// Denoising (denoise.h): every noise variance times the filter's noise gain g, met after the
// filter, so the target sqrt(s) becomes sqrt(s g). A block whose sigma is a broadcast 0 has no
// gain (`gained` false: sqrt(s) as it is, bit for bit); else b.root_gain holds sqrt(g) per lane,
// a broadcast sigma's computed once for the call.
//
// A colour sensor's colour correction and demosaicking (color_noise_gain, g_c) multiply every
// variance too: g = g_denoise(sigma) g_c.
template <class T>
void noise_gain_roots(Block<T>& b) {
    b.gained = !(b.broadcast_is(denoise_sigma_px, 0.0) && b.broadcast_is(color_noise_gain, 1.0));
    if (!b.gained) return;
    double* __restrict root_gain = b.root_gain;
    if (b.is_broadcast(denoise_sigma_px) && b.is_broadcast(color_noise_gain)) {
        const double sigma = b.broadcast[denoise_sigma_px], color = b.broadcast[color_noise_gain];
        if (!(sigma == b.memo_sigma && color == b.memo_color_gain)) {
            b.memo_root_gain = std::sqrt(noise_gain_denoise(sigma) * color);
            b.memo_sigma = sigma;
            b.memo_color_gain = color;
        }
        for (std::size_t i = 0; i < block_size; ++i) root_gain[i] = b.memo_root_gain;
        return;
    }
    const double* __restrict sigma = b.x[denoise_sigma_px];
    const double* __restrict color = b.x[color_noise_gain];
    for (std::size_t i = 0; i < block_size; ++i)
        root_gain[i] = std::sqrt(noise_gain_denoise(sigma[i]) * color[i]);
}

// Binning and bursts (point.h): a block whose binning or frames are not a broadcast 1 reads
// the read noise, dark current, PRNU, full well and stabilisation as the output pixel of the
// burst sees them (sensor_store's rows), and multiplies the rate by k^2; every other block
// reads its inputs as they are. With k = n = 1 in a lane, its row values are its inputs.

// The sensor rows of a block that has binning or bursts; x[] points at them for the exposure
// stage (restore_inputs puts the inputs back). Returns whether the block has them.
template <class T>
bool sensor_terms(Block<T>& b, const double* (&saved)[5]) {
    b.sensor = !(b.broadcast_is(binning, 1.0) && b.broadcast_is(frames, 1.0));
    if (!b.sensor) return false;
    constexpr int inputs[5] = {read_noise_e, dark_current_e_per_s, prnu, full_well_e, stabilization};
    for (int r = 0; r < 5; ++r) saved[r] = b.x[inputs[r]];
    const double* __restrict k = b.x[binning];
    const double* __restrict n = b.x[frames];
    const double* __restrict readout = b.x[binning_readout];
    auto& row = b.sensor_store;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double pixels = binned_pixels(k[i]);
        row[sensor_pixels][i] = pixels;
        row[sensor_read][i] = burst_read_noise_e(saved[0][i], k[i], n[i], readout[i]);
        row[sensor_dark][i] = saved[1][i] * pixels;
        row[sensor_prnu][i] = saved[2][i] / k[i];
        row[sensor_well][i] = saved[3][i] * (pixels * n[i]);
        row[sensor_stab][i] = saved[4][i] * n[i];
    }
    for (int r = 0; r < 5; ++r) b.x[inputs[r]] = row[r];
    return true;
}

template <class T>
void restore_inputs(Block<T>& b, const double* (&saved)[5]) {
    constexpr int inputs[5] = {read_noise_e, dark_current_e_per_s, prnu, full_well_e, stabilization};
    for (int r = 0; r < 5; ++r) b.x[inputs[r]] = saved[r];
}

}  // namespace detail
}  // namespace epc_fast
