// T_MPE and blur of every lane of a block (stage.h): the vector path of the closed form, which
// drops the terms a block does not use (ExposureTerms) with the same bits, and the general
// formulas of point.h for the lanes it cannot vouch for (exposure_lane).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "../block.h"
#include "../constants.h"
#include "../parallel.h"
#include "../params.h"
#include "exact.h"
#include "point.h"
#include "sensor.h"

namespace epc_fast {
namespace detail {

// T_MPE, blur and the unreachable causes of one lane by the general formulas of point.h
// (scaled products, the C library's pow, sin and tan, Brent when asked): for the lanes the
// vector path below cannot vouch for.
template <class T>
void exposure_lane(const Options& opt, Block<T>& b, std::size_t i) {
    const auto& x = b.x;
    b.rate[i] = electron_rate(x[illuminance_lux][i], x[reflectance][i], x[lens_transmittance][i],
                              x[field_angle_deg][i], x[f_number][i],
                              x[electrons_per_lux_s_m2][i], x[fill_factor][i],
                              x[pixel_pitch_um][i]);
    b.rate[i] *= x[cfa_transmittance][i];  // a colour sensor's filters (1: monochrome)
    if (b.sensor) b.rate[i] *= b.sensor_store[sensor_pixels][i];  // the output pixel's rate
    SnrTarget target(x[snr_db][i]);
    if (b.gained) target.root_s *= b.root_gain[i];  // denoising: the target s g
    b.capped[i] = b.rate[i] > 0.0 && target.capped_by(x[prnu][i]);
    if (opt.t_mpe_solver == TMpeSolver::closed_form)
        b.electrons[i] = signal_electrons(b.rate[i], target, x[read_noise_e][i],
                                          x[dark_current_e_per_s][i], x[prnu][i]);
    else
        b.electrons[i] = b.rate[i] > 0.0 && !b.capped[i]
                             ? signal_electrons_brent(b.rate[i], target, x[read_noise_e][i],
                                                      x[dark_current_e_per_s][i], x[prnu][i],
                                                      opt.t_mpe_rtol)
                             : nan;
    const double t = b.electrons[i] / b.rate[i];
    b.t_mpe[i] = t;
    const bool unreachable = b.capped[i] || !std::isfinite(t) || b.electrons[i] > x[full_well_e][i];
    b.blur[i] = unreachable ? 0.0
                            : blur_length_mm(x[focal_length_mm][i], x[shake_deg_per_s][i],
                                             x[stabilization][i], t);
}

// The terms of T_MPE and blur a block uses: a broadcast dark current, read noise or PRNU of 0
// drops that term, and so does a broadcast shake of 0 (motion 0); motion 1 is shake with a
// broadcast stabilisation of 1, 2 any other.
struct ExposureTerms {
    bool dark, read, prnu;
    int motion;
};

template <class T>
ExposureTerms exposure_terms(const Block<T>& b) {
    // a burst divides the shake by n too (sensor_terms): stabilisation 1 is not the whole of it
    const bool shake = !b.broadcast_is(shake_deg_per_s, 0.0);
    const bool unstabilised = b.broadcast_is(stabilization, 1.0) && b.broadcast_is(frames, 1.0);
    return {!b.broadcast_is(dark_current_e_per_s, 0.0), !b.broadcast_is(read_noise_e, 0.0),
            !b.broadcast_is(prnu, 0.0), !shake ? 0 : unstabilised ? 1 : 2};
}

// signal_electrons and blur_length_mm for every lane, from the rate, sqrt(s) and the PRNU margin
// w; `slow` marks the lanes whose products leave the normal range (exposure_lane redoes
// them). The template drops the terms the block does not use: Dark (q = 1), Read (hypot(x, 0) =
// x), Prnu (w = 1), Motion 0 (no blur), 1 (stabilisation 1) or 2.
template <bool Dark, bool Read, bool Prnu, int Motion, class T>
void electrons_and_blur(Block<T>& b, const double* __restrict root_s,
                        const double* __restrict w_margin) {
    const auto& x = b.x;
    const double* __restrict read = x[read_noise_e];
    const double* __restrict dark = x[dark_current_e_per_s];
    const double* __restrict well = x[full_well_e];
    const double* __restrict focal = x[focal_length_mm];
    const double* __restrict shake = x[shake_deg_per_s];
    const double* __restrict stab = x[stabilization];
    const double* __restrict rate = b.rate;
    // moderate rates only (the rate's stage): the divisions by the rate share one reciprocal
    const LaneFlag<double>* __restrict rate_normal = b.rate_normal;
    const LaneFlag<double>* __restrict capped = b.capped;
    double* __restrict electrons = b.electrons;
    double* __restrict t_mpe = b.t_mpe;
    double* __restrict blur = b.blur;
    LaneFlag<double>* __restrict slow = b.slow;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double rs = root_s[i], rv = rate[i], inverse_rv = 1.0 / rv;
        // signal_electrons
        double a = 0.0, el = 0.0;
        bool electrons_normal = true;
        {
            const double w = Prnu ? w_margin[i] : 1.0;
            // dark / rate: a lane where it is above 2^900 is redone (divide_by's range); below
            // 2^-900 it does not move q = 1 + dark / rate from 1
            const double dark_per_rate = Dark ? divide_by(dark[i], rv, inverse_rv) : 0.0;
            const double q = 1.0 + dark_per_rate;
            const double read_term = Read ? 2.0 * read[i] * (Prnu ? std::sqrt(w) : 1.0) / q : 0.0;
            a = (Prnu ? rs / (2.0 * w) : 0.5 * rs) * (rs + (Read ? hypot_moderate(rs, read_term) : rs));
            if (Read) electrons_normal &= read_term <= hypot_moderate_max;
            if (Dark) {
                const double ad = a * dark[i];
                const double extra = divide_by(ad, rv, inverse_rv);
                const bool no_dark = dark[i] == 0.0;
                electrons_normal &= no_dark | ((dark_per_rate <= 0x1p900) & normal(a) & moderate(ad) &
                                               moderate(extra));
                el = a + (no_dark ? 0.0 : extra);
            } else {
                el = a;
            }
        }
        // T_MPE: a lane where it leaves 2^-900..2^900 (a rate so small that T_MPE is 1e270 s,
        // or overflows) is redone, unless PRNU caps it (its T_MPE is then infinite, whatever t)
        const double t = divide_by(el, rv, inverse_rv);
        electrons_normal &= moderate(t) | (capped[i] != 0);
        electrons[i] = el;
        t_mpe[i] = t;
        const bool unreachable = (capped[i] != 0) | !(t <= std::numeric_limits<double>::max()) | (el > well[i]);
        bool motion_ok = true;
        if (Motion == 0) {
            blur[i] = 0.0;
        } else {
            // blur_length_mm
            const double angle1 = shake[i] * deg_to_rad;
            const double angle2 = angle1 * t;
            const double angle = Motion == 2 ? angle2 / stab[i] : angle2;
            const bool angle_normal = normal(shake[i]) & normal(angle1) & normal(angle2) & normal(angle);
            const bool still = shake[i] == 0.0;
            const double tan_angle = tan_of_angle(angle);
            blur[i] = still ? 0.0 : angle < half_pi ? focal[i] * tan_angle : inf;
            motion_ok = unreachable | still | angle_normal;
        }
        slow[i] = !((rate_normal[i] != 0) & electrons_normal & motion_ok);
    }
}

}  // namespace detail
}  // namespace epc_fast
