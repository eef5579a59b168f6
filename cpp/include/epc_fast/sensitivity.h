// What limits a design and how sensitive it is: each MTF factor's share of the loss at f50, and
// the elasticity d ln EPC / d ln theta of every parameter, for the lanes of a block whose f50
// is solved, from the formulas of log_slopes.h (python/epc_fast/reference/sensitivity.py derives
// them and carries the same function names): a vector path over the block's lanes, and the
// scalar formulas for the lanes it cannot vouch for and the blocks with the terms beyond the
// paper's camera.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "aberration.h"
#include "block.h"
#include "constants.h"
#include "denoise.h"
#include "exposure/point.h"
#include "exposure/sensor.h"
#include "lens.h"
#include "log_slopes.h"
#include "mtf.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"
#include "status.h"

namespace epc_fast {
namespace detail {

// Above this a sinc's argument, or below this the diffraction MTF, is near the factor's zero:
// the vector path leaves such lanes (thresholds of 1e-6 and less) to sensitivity_lane.
constexpr double near_zero_argument = 1.0 - 0x1p-20;
constexpr double near_zero_diffraction = 0x1p-30;

// One OK lane's shares and elasticities by the scalar formulas (mtf_log_factors,
// t_mpe_log_slopes, blur_angle_log_slope): for the lanes whose shared divisions in
// `sensitivity` could leave the normal range, and those near a factor's zero.
//
// With a threshold c so small that f50 is a factor's zero to within rounding, that factor's
// log and log-slope at the computed f50 are not the root's (or not finite): the factors' logs
// then do not add up to ln c. That factor (the one with the least log, "pinned") takes ln c
// less the others' logs, the shares divide by ln c, and the elasticities take their limit as
// its log-slope goes to -infinity where it is not finite: f50 follows the factor's zero.
template <class T>
void sensitivity_lane(const Inputs& in, const Block<T>& b, std::size_t i, double field_slope,
                      double (&share_out)[n_shares][block_size],
                      double (&elasticity_out)[n_params][block_size]) {
    const auto& x = b.x;
    // binning and bursts (a block with them: b.sensor): the binned pixel's lengths, the
    // alignment residual, and the exposure's inputs as the output pixel of the burst sees them
    // (exposure/sensor.h sensor_terms)
    const double k = x[binning][i], n = x[frames][i];
    const double residual_um = x[alignment_error_um][i] * std::sqrt(1.0 - 1.0 / n);
    auto input = [&](int param, int row) { return b.sensor ? b.sensor_store[row][i] : x[param][i]; };
    MtfLogFactors m = mtf_log_factors(
        static_cast<double>(b.f50[i]), x[f_number][i], x[wavelength_nm][i],
        pixel_aperture_mm(x[pixel_pitch_um][i], x[fill_factor][i]), b.blur[i],
        x[jitter_um][i] * um_to_mm, in.spectrum, x[pixel_pitch_um][i] * um_to_mm, k,
        residual_um * um_to_mm, aberration_depth(x[wavefront_rms_waves][i]), x[denoise_sigma_px][i],
        b.lens_tables != nullptr ? &lens_table(b, i) : nullptr, b.demosaic_table);
    const double ln_c = std::log(x[mtf_threshold][i]);
    double total = (((m.log[0] + m.log[1]) + (m.log[2] + m.log[3])) + m.log[4]) +
                   ((m.log[share_aberration] + m.log[share_denoise]) +
                    (m.log[share_lens] + m.log[share_demosaic]));
    const bool pinned = !(std::fabs(total - ln_c) <= 1e-3 * std::fabs(ln_c));
    if (pinned) {
        auto least = [&m](int s) {  // a NaN log (a sinc past its zero) counts as -inf
            return std::isnan(m.log[s]) ? -std::numeric_limits<double>::infinity() : m.log[s];
        };
        int j = 0;
        for (int s = 1; s < n_shares; ++s)
            if (least(s) < least(j)) j = s;
        double others = 0.0;
        for (int s = 0; s < n_shares; ++s) others += s == j ? 0.0 : m.log[s];
        m.log[j] = ln_c - others;
        total = ln_c;
    }
    for (int s = 0; s < n_shares; ++s) share_out[s][i] = m.log[s] / total;
    const TMpeLogSlopes t = t_mpe_log_slopes(b.electrons[i], b.t_mpe[i],
                                             input(read_noise_e, sensor_read),
                                             input(dark_current_e_per_s, sensor_dark),
                                             input(prnu, sensor_prnu));
    const double beta = blur_angle_log_slope(b.blur[i], x[focal_length_mm][i], x[shake_deg_per_s][i],
                                             input(stabilization, sensor_stab), b.t_mpe[i]);
    double slopes[4] = {m.slope_diffraction, m.slope_pixel, m.slope_motion, m.slope_fill};
    double log_jitter = m.log[share_jitter], log_alignment = m.log[share_alignment];
    double threshold_term = 1.0;
    const double sigma_px = x[denoise_sigma_px][i];
    OpticsSlopes optics{m.slope_aberration, m.wave_aberration, m.slope_denoise + m.slope_demosaic,
                        m.sigma_denoise,
                        sigma_px > 0.0 ? noise_gain_log_slope(sigma_px) : 0.0};
    int infinite = -1;
    for (int s = 0; s < 3; ++s)
        if (!(std::fabs(slopes[s]) <= std::numeric_limits<double>::max())) infinite = s;
    if (infinite >= 0) {  // the limit: every slope over |slope_k|, which goes to infinity
        for (int s = 0; s < 3; ++s) slopes[s] = s == infinite ? -1.0 : 0.0;
        slopes[3] = infinite == 1 && !(std::fabs(m.slope_fill) <= std::numeric_limits<double>::max()) ? -1.0 : 0.0;
        log_jitter = 0.0;
        log_alignment = 0.0;
        threshold_term = 0.0;
        optics = {0.0, 0.0, 0.0, 0.0, optics.gain};  // finite slopes: 0 in that limit
    }
    const double mu = slopes[2] * beta;
    optics.gain *= mu * t.target;  // the noise gain's path through T_MPE and the blur
    // a lens table's L does not move with the f-number or the wavelength: its slope is the
    // optics' in the area slope, and theirs 0
    const double diffraction_slope = b.lens_tables != nullptr ? 0.0 : slopes[0];
    elasticities_of_lane(diffraction_slope, slopes[1], slopes[3], slopes[2], log_jitter, log_alignment, t,
                         mu, field_slope, x[snr_db][i] * (ln10 / 10.0),
                         in.size_is_pixel_count, elasticity_out, i,
                         2.0 / area_slope(slopes[0] + optics.aberration, slopes[1] + optics.denoise,
                                          slopes[2], log_jitter + log_alignment),
                         threshold_term, 1.0, optics);
}

// The shares and elasticities of the block's lanes into share_out and elasticity_out (rows of
// block_size): OK lanes from their f50, NaN on the others, but where the blur is unbounded
// (f50 = 0, EPC = 0: motion takes all of the loss) the shares 0, 0, 1, 0. Each stage is a loop
// over the lanes that vectorises, with the divisions of a lane shared where one product serves
// them (the slowest vector instructions here); the other lanes compute on f = 0 (every factor
// 1) and are masked at the end. A lane whose shared products leave the normal range is redone
// by sensitivity_lane. `Exposure` = false when the block has no read noise, dark current or
// PRNU (broadcast 0): T_MPE's log-slopes are then -1 for the rate, 1 for the target, 0 else.
// `Shares` and `Elasticities` say which are asked for: the logs are formed only for the
// shares, the slopes only for the elasticities.
template <bool Exposure, bool Shares, bool Elasticities, class T>
void sensitivity_as(const Inputs& in, const Block<T>& b, double (&share_out)[n_shares][block_size],
                    double (&elasticity_out)[n_params][block_size]) {
    constexpr bool shares = Shares, elasticities = Elasticities;
    constexpr std::size_t n = block_size;
    const auto& x = b.x;
    alignas(64) double f[n], loss[n], slope_numerator[n], value[n];
    alignas(64) double logs[n_shares][n], slope_pixel[n], slope_motion[n];
    LaneFlag<double> ok[n], slow[n];
    const unsigned char* __restrict status = b.status;
    for (std::size_t i = 0; i < n; ++i) {
        ok[i] = status[i] == static_cast<unsigned char>(Status::ok);
        f[i] = ok[i] ? static_cast<double>(b.f50[i]) : 0.0;
    }
    // diffraction's loss, log-slope numerator and value, over the spectrum's lines
    const double* __restrict f_num = x[f_number];
    alignas(64) double nu[n];
    if (in.spectrum.polychromatic()) {
        for (std::size_t i = 0; i < n; ++i) loss[i] = slope_numerator[i] = value[i] = 0.0;
        for (std::size_t k = 0; k < in.spectrum.wavelengths_nm.size(); ++k) {
            const double lambda_mm = in.spectrum.wavelengths_nm[k] * nm_to_mm;
            unsigned char high = 0;
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) {
                nu[i] = f[i] * lambda_mm * f_num[i];
                high |= !(nu[i] <= 0.5);
            }
            diffraction_of_lanes<Shares, true>(nu, in.spectrum.weights[k], high, loss, slope_numerator, value);
        }
    } else {
        const double* __restrict lambda = x[wavelength_nm];
        unsigned char high = 0;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            nu[i] = f[i] * (lambda[i] * nm_to_mm) * f_num[i];
            high |= !(nu[i] <= 0.5);
        }
        diffraction_of_lanes<Shares, false>(nu, 1.0, high, loss, slope_numerator, value);
    }
    // every factor's log and log-slope (mtf_log_factors), the sincs' and diffraction's
    // divisions in one
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict fill = x[fill_factor];
    const double* __restrict jitter = x[jitter_um];
    const double* __restrict blur = b.blur;
    alignas(64) double aperture[n];
    if (b.is_broadcast(fill_factor)) {  // pixel_aperture_mm, one sqrt
        const double root_fill = std::sqrt(b.broadcast[fill_factor]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) aperture[i] = root_fill * (pitch[i] * um_to_mm);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) aperture[i] = pixel_aperture_mm(pitch[i], fill[i]);
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double y_pixel = aperture[i] * f[i];
        const double y_motion = blur[i] * f[i];
        const double sigma_f = (jitter[i] * um_to_mm) * f[i];
        const double sin_pixel = sinpi_unit(y_pixel), sin_motion = sinpi_unit(y_motion);
        const double d_pixel = y_pixel < detail::series_below ? 1.0 : y_pixel * sin_pixel;
        const double d_motion = y_motion < detail::series_below ? 1.0 : y_motion * sin_motion;
        const double d_sincs = d_pixel * d_motion, product = d_sincs * value[i];
        const double inverse = 1.0 / product;
        slow[i] = ok[i] & (!((product >= 0x1p-900) & (product <= 0x1p900)) |
                           (y_pixel > near_zero_argument) | (y_motion > near_zero_argument) |
                           (value[i] < near_zero_diffraction));
        const LogSinc pixel = log_sinc_given(y_pixel, sin_pixel, d_motion * value[i] * inverse);
        const LogSinc motion = log_sinc_given(y_motion, sin_motion, d_pixel * value[i] * inverse);
        if (Shares) {
            logs[share_diffraction][i] = log_mtf_diffraction(value[i], loss[i]);
            logs[share_pixel][i] = pixel.log;
            logs[share_motion][i] = motion.log;
        }
        logs[share_jitter][i] = -2.0 * pi * pi * sigma_f * sigma_f;
        logs[share_alignment][i] = 0.0;  // a block with bursts takes sensitivity_lane
        logs[share_aberration][i] = 0.0;  // neither term is in the core yet
        logs[share_denoise][i] = 0.0;
        logs[share_lens][i] = 0.0;
        logs[share_demosaic][i] = 0.0;
        if (Elasticities) {
            slope_numerator[i] *= d_sincs * inverse;  // now nu dD/dnu / D
            slope_pixel[i] = pixel.slope;
            slope_motion[i] = motion.slope;
        }
    }
    if (shares) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double inverse_total =
                1.0 / (((logs[0][i] + logs[1][i]) + (logs[2][i] + logs[3][i])) + logs[4][i]);
            const bool unbounded = status[i] == static_cast<unsigned char>(Status::blur_unbounded);
            for (int s = 0; s < n_shares; ++s) {
                const double other = unbounded ? (s == share_motion ? 1.0 : 0.0) : nan;
                share_out[s][i] = ok[i] ? logs[s][i] * inverse_total : other;
            }
        }
    }
    alignas(64) double field_slope[n];
    if (elasticities) {
        if (b.is_broadcast(field_angle_deg)) {
            // the last broadcast angle's slope, kept per thread: two sin calls per block else
            thread_local double memo_angle = nan, memo_slope = 0.0;
            const double angle = b.broadcast[field_angle_deg];
            if (!(angle == memo_angle)) {
                memo_slope = field_angle_rate_log_slope(angle);
                memo_angle = angle;
            }
            const double v = memo_slope;
            for (std::size_t i = 0; i < n; ++i) field_slope[i] = v;
        } else {
            for (std::size_t i = 0; i < n; ++i)
                field_slope[i] = field_angle_rate_log_slope(x[field_angle_deg][i]);
        }
        const double* __restrict focal = x[focal_length_mm];
        const double* __restrict shake = x[shake_deg_per_s];
        const double* __restrict stab = x[stabilization];
        const double* __restrict snr = x[snr_db];
        const double* __restrict read = x[read_noise_e];
        const double* __restrict dark = x[dark_current_e_per_s];
        const double* __restrict u = x[prnu];
        const double* __restrict electrons = b.electrons;
        const double* __restrict t_mpe = b.t_mpe;
        const bool count = in.size_is_pixel_count;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            // OK lanes' exposure; the others compute on 1 e- over 1 s and are masked below
            const double t_s = ok[i] ? t_mpe[i] : 1.0;
            TMpeLogSlopes t{-1.0, 0.0, 0.0, 1.0, 0.0};
            bool exposure_ok = true;
            if (Exposure) {
                // t_mpe_log_slopes with one division by e and one by 1 + q + v
                const double inverse_e = 1.0 / (ok[i] ? electrons[i] : 1.0);
                const double e = ok[i] ? electrons[i] : 1.0;
                const double q = dark[i] * t_s * inverse_e;
                const double v = 2.0 * read[i] * read[i] * inverse_e;
                const double ue = u[i] * u[i] * e;
                const double inverse = 1.0 / (1.0 + q + v);
                const double dark_part = q * inverse;
                t = {-1.0 - dark_part, dark_part, v * inverse, 1.0 - 0.5 * v * inverse + ue * inverse,
                     2.0 * ue * inverse};
                exposure_ok = (q <= 0x1p900) & (v <= 0x1p900) & (ue <= 0x1p900);
            }
            // blur_angle_log_slope as one quotient: alpha (f_L^2 + b^2) / (b f_L), alpha =
            // omega T / k
            const double numerator = shake[i] * deg_to_rad * t_s * (focal[i] * focal[i] + blur[i] * blur[i]);
            const double denominator = stab[i] * blur[i] * focal[i];
            const double beta = blur[i] > 0.0 ? numerator / denominator : 1.0;
            slow[i] |= ok[i] & ((blur[i] > 0.0) & !((numerator >= 0x1p-900) & (numerator <= 0x1p900) &
                                                    (denominator >= 0x1p-900) & (denominator <= 0x1p900)));
            slow[i] |= ok[i] & !exposure_ok;
            const double mask = ok[i] ? 1.0 : nan;
            const double two_over_a =
                (2.0 / area_slope(slope_numerator[i], slope_pixel[i], slope_motion[i], logs[share_jitter][i])) * mask;
            elasticities_of_lane(slope_numerator[i], slope_pixel[i], slope_pixel[i], slope_motion[i],
                                 logs[share_jitter][i], 0.0, t, slope_motion[i] * beta, field_slope[i],
                                 snr[i] * (ln10 / 10.0), count, elasticity_out, i, two_over_a, 1.0,
                                 mask);
        }
    }
    // a block with binning, bursts, the wavefront error or denoising: every OK lane by
    // sensitivity_lane, which has their terms
    if (b.sensor || !b.broadcast_is(wavefront_rms_waves, 0.0) || !b.broadcast_is(denoise_sigma_px, 0.0) ||
        b.lens_tables != nullptr || b.demosaic_table != nullptr)
        for (std::size_t i = 0; i < n; ++i) slow[i] |= ok[i];
    // the slow lanes (most blocks have none)
    int n_slow = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_slow)
    for (std::size_t i = 0; i < n; ++i) n_slow += slow[i] != 0;
    if (n_slow == 0) return;
    for (std::size_t i = 0; i < n; ++i) {
        if (!slow[i]) continue;
        double lane_shares[n_shares][block_size];
        sensitivity_lane(in, b, i, elasticities ? field_slope[i] : 0.0,
                         shares ? share_out : lane_shares, elasticity_out);
    }
}

template <class T>
void sensitivity(const Inputs& in, const Block<T>& b, bool shares, bool elasticities,
                 double (&share_out)[n_shares][block_size],
                 double (&elasticity_out)[n_params][block_size]) {
    const bool exposure = !(b.broadcast_is(read_noise_e, 0.0) && b.broadcast_is(dark_current_e_per_s, 0.0) &&
                            b.broadcast_is(prnu, 0.0));
    auto run = [&](auto exposure_terms) {
        constexpr bool E = decltype(exposure_terms)::value;
        if (shares && elasticities) sensitivity_as<E, true, true>(in, b, share_out, elasticity_out);
        else if (shares) sensitivity_as<E, true, false>(in, b, share_out, elasticity_out);
        else if (elasticities) sensitivity_as<E, false, true>(in, b, share_out, elasticity_out);
    };
    if (exposure) run(std::true_type{});
    else run(std::false_type{});
}

}  // namespace detail
}  // namespace epc_fast
