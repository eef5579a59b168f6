// The kernel's exposure stage (kernel.h): each lane's electron rate, T_MPE and blur, and from
// them its status and cause, a block at a time.
//
// The formulas are point.h's. The vector path computes them with plain products whose partial
// products are checked to stay inside 2^-900..2^900 (then they equal point.h's scaled products
// bit for bit), one reciprocal shared by the quotients with the same divisor (divide_by: the
// same bits as dividing), and vectorised hypot and tan (exact.h). A lane it cannot vouch for,
// or every lane when Brent is asked for, is redone by point.h's formulas themselves
// (exposure_lane, electrons.h). A block drops the terms it does not use (ExposureTerms), with
// the same bits; a block that bins or bursts reads its output pixel's inputs (sensor.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "../block.h"
#include "../cfa.h"
#include "../constants.h"
#include "../parallel.h"
#include "../params.h"
#include "../status.h"
#include "electrons.h"
#include "exact.h"
#include "point.h"
#include "sensor.h"

namespace epc_fast {
namespace detail {

// Each lane's status, the lanes to solve and their blur; with Values, also its cause, and its
// rate, electrons, T_MPE and blur as they are written out (NaN where undefined): decided once
// here, where the flags are at hand, so that scatter only copies them. A call that writes none
// of those (f50 and EPC alone, say) skips them: they are read only by scatter and sensitivity.
template <bool Values, class T>
void decide_lanes(Block<T>& b) {
    const double* __restrict well = b.x[full_well_e];
    double* __restrict rate = b.rate;
    double* __restrict electrons = b.electrons;
    double* __restrict t_mpe = b.t_mpe;
    double* __restrict blur = b.blur;
    const LaneFlag<double>* __restrict capped = b.capped;
    unsigned char* __restrict status = b.status;
    unsigned char* __restrict cause = b.cause;
    double* __restrict blur_out = b.blur_out;
    LaneFlag<T>* __restrict solve = b.solve;
    const LaneFlag<double>* __restrict valid = b.valid;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double t = t_mpe[i];  // electrons / rate, from either path
        const bool ok = valid[i] != 0, cap = capped[i] != 0;
        // A rate so small that T_MPE overflows counts as no light.
        const bool dark_lane = !cap & !(t <= std::numeric_limits<double>::max());
        const bool over = !dark_lane & !cap & (electrons[i] > well[i]);
        const bool unreachable = cap | dark_lane | over;
        const bool inf_blur = !unreachable & (blur[i] > std::numeric_limits<double>::max());
        const bool s = ok & !unreachable & !inf_blur;
        // Branch-free, so that the loop vectorises: the codes as sums of flags times codes (at
        // most one term of each is set: inf_blur excludes unreachable, and dark_lane, cap and
        // over exclude each other; Status::ok and Cause::none are 0), and every value loaded
        // once and chosen by single selects.
        const unsigned flag_ok = ok;
        status[i] = static_cast<unsigned char>(
            (1u - flag_ok) * static_cast<unsigned>(Status::invalid) +
            flag_ok * (static_cast<unsigned>(unreachable) * static_cast<unsigned>(Status::unreachable) +
                       static_cast<unsigned>(inf_blur) * static_cast<unsigned>(Status::blur_unbounded)));
        const double bl = blur[i];
        if (Values) {
            cause[i] = static_cast<unsigned char>(
                flag_ok * (static_cast<unsigned>(dark_lane) * static_cast<unsigned>(Cause::no_light) +
                           static_cast<unsigned>(cap) * static_cast<unsigned>(Cause::prnu) +
                           static_cast<unsigned>(over) * static_cast<unsigned>(Cause::full_well)));
            const double r = rate[i], e = electrons[i];
            rate[i] = ok ? r : nan;
            electrons[i] = (ok & !dark_lane & !cap) ? e : nan;
            const double t_kept = unreachable ? inf : t;
            t_mpe[i] = ok ? t_kept : nan;
            const double blur_kept = inf_blur ? inf : bl;
            blur_out[i] = (ok & !unreachable) ? blur_kept : nan;
        }
        solve[i] = s;
        blur[i] = s ? bl : 0.0;
    }
}

// T_MPE and blur for every lane, on the inputs as x[] holds them (sensor_terms'). The vector
// path computes the closed form with plain products and vectorised hypot and tan; a lane whose
// products leave the normal range, or any lane when Brent is asked for, is redone by
// exposure_lane. cos(theta) and 10^(snr/20) are computed once for a block when their columns
// are broadcast. `values`: whether the rate, electrons, T_MPE, blur and cause are read
// (decide_lanes).
template <class T>
void exposure_of_inputs(const Options& opt, Block<T>& b, bool values) {
    constexpr std::size_t n = block_size;
    const auto& x = b.x;
    double* __restrict cos2 = b.scratch[0];
    double* __restrict root_s = b.scratch[1];
    // A broadcast column's cos(theta) and 10^(snr/20) are the same for every block of a call:
    // the Block remembers the last ones it computed (pure functions: the same bits).
    if (b.is_broadcast(field_angle_deg)) {
        const double angle = b.broadcast[field_angle_deg];
        if (!(angle == b.memo_angle_deg)) {
            b.memo_cos_theta = std::sin((90.0 - std::fabs(angle)) * deg_to_rad);
            b.memo_angle_deg = angle;
        }
        const double c = b.memo_cos_theta;
        for (std::size_t i = 0; i < n; ++i) cos2[i] = c * c;
    } else {
        for (std::size_t i = 0; i < n; ++i) {
            const double c = std::sin((90.0 - std::fabs(x[field_angle_deg][i])) * deg_to_rad);
            cos2[i] = c * c;
        }
    }
    if (b.is_broadcast(snr_db)) {
        const double snr = b.broadcast[snr_db];
        if (!(snr == b.memo_snr_db)) {
            b.memo_root_s = SnrTarget(snr).root_s;
            b.memo_snr_db = snr;
        }
        const double r = b.memo_root_s;
        for (std::size_t i = 0; i < n; ++i) root_s[i] = r;
    } else {
        for (std::size_t i = 0; i < n; ++i) root_s[i] = SnrTarget(x[snr_db][i]).root_s;
    }
    noise_gain_roots(b);
    if (b.gained) {
        const double* __restrict root_gain = b.root_gain;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) root_s[i] *= root_gain[i];
    }
    const double* __restrict lux = x[illuminance_lux];
    const double* __restrict refl = x[reflectance];
    const double* __restrict tau = x[lens_transmittance];
    const double* __restrict f_num = x[f_number];
    const double* __restrict k_e = x[electrons_per_lux_s_m2];
    const double* __restrict fill = x[fill_factor];
    const double* __restrict pitch = x[pixel_pitch_um];
    double* __restrict rate = b.rate;
    LaneFlag<double>* __restrict capped = b.capped;
    // Three stages, each small enough for GCC to vectorise (one loop with all of it does not):
    // the rate, the PRNU margin, then electrons and blur.
    double* __restrict w_margin = b.scratch[2];
    LaneFlag<double>* __restrict rate_normal = b.rate_normal;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        // electron_rate's product, in its order. The lane is redone (exposure_lane) unless
        // every partial product is moderate: then each is a normal double, so the plain
        // product is scaled_product's bit for bit, and divide_by is the division. Their least
        // and greatest are tracked (two instructions a product, not two comparisons and two
        // mask operations); a NaN product (0 times an overflow) comes after an infinite or
        // zero one, which the bounds have kept.
        double rv = lux[i], least = rv, most = rv;
        auto track = [&](double v) {
            least = v < least ? v : least;
            most = v > most ? v : most;
        };
        rv *= refl[i];
        track(rv);
        rv *= tau[i];
        track(rv);
        rv *= cos2[i];
        track(rv);
        rv *= cos2[i];
        track(rv);
        rv *= k_e[i];
        track(rv);
        rv *= fill[i];
        track(rv);
        rv *= pitch[i];
        track(rv);
        rv *= pitch[i];
        track(rv);
        rv *= um_to_m * um_to_m;
        track(rv);
        rv /= 4.0;
        track(rv);
        // the two divisions by F with one reciprocal (divide_by: the same roundings)
        const double f = f_num[i], inverse_f = 1.0 / f;
        track(f);
        rv = divide_by(rv, f, inverse_f);
        track(rv);
        rv = divide_by(rv, f, inverse_f);
        track(rv);
        const bool ok = moderate(least) & moderate(most);
        rate[i] = rv;
        rate_normal[i] = ok;
    }
    cfa_rate(b);  // a colour sensor's filters: t r
    if (b.sensor) {  // the output pixel's rate, k^2 r (exposure_lane's too)
        const double* __restrict pixels = b.sensor_store[sensor_pixels];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double rk = rate[i] * pixels[i];
            rate[i] = rk;
            rate_normal[i] &= moderate(rk);
        }
    }
    const ExposureTerms terms = exposure_terms(b);
    if (terms.prnu) {
        const double* __restrict u = x[prnu];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            // SnrTarget::capped_by and prnu_margin: capped when u sqrt(s) >= 1 exactly
            const double rs = root_s[i];
#if EPC_FAST_FMA
            // u sqrt(s) - 1 rounded once has the exact difference's sign; 1 -+ u sqrt(s) from
            // the exact product (the compiler must not fuse p into one and not the other). No
            // fma(u, s, -u s) here: GCC 12 does not vectorise a loop with it.
            capped[i] = std::fma(u[i], rs, -1.0) >= 0.0;
            w_margin[i] = std::fma(-u[i], rs, 1.0) * std::fma(u[i], rs, 1.0);
#else
            // the product p and its rounding error e; e is used only where p is near 1, where
            // both factors are far inside product_error's range
            const double p = u[i] * rs;
            const double p_error = product_error(u[i], rs);
            const double e = std::fabs(p - 1.0) < 0.5 ? p_error : 0.0;
            capped[i] = (p > 1.0) | ((p == 1.0) & (e >= 0.0));
            w_margin[i] = ((1.0 - p) - e) * ((1.0 + p) + e);
#endif
        }
    } else {  // u = 0: never capped, w = 1 exactly
        for (std::size_t i = 0; i < n; ++i) capped[i] = 0;
        for (std::size_t i = 0; i < n; ++i) w_margin[i] = 1.0;
    }
    // One instantiation per combination of the terms the block uses (each exact where it
    // drops a term: x / 1, x + 0, hypot(x, 0) and sqrt(1) are x and 1 bit for bit).
    const int code = (terms.dark ? 1 : 0) | (terms.read ? 2 : 0) | (terms.prnu ? 4 : 0);
    auto run = [&](auto dark, auto read, auto prnu) {
        constexpr bool D = decltype(dark)::value, R = decltype(read)::value, P = decltype(prnu)::value;
        if (terms.motion == 0) electrons_and_blur<D, R, P, 0>(b, root_s, w_margin);
        else if (terms.motion == 1) electrons_and_blur<D, R, P, 1>(b, root_s, w_margin);
        else electrons_and_blur<D, R, P, 2>(b, root_s, w_margin);
    };
    using yes = std::true_type;
    using no = std::false_type;
    switch (code) {
        case 0: run(no{}, no{}, no{}); break;
        case 1: run(yes{}, no{}, no{}); break;
        case 2: run(no{}, yes{}, no{}); break;
        case 3: run(yes{}, yes{}, no{}); break;
        case 4: run(no{}, no{}, yes{}); break;
        case 5: run(yes{}, no{}, yes{}); break;
        case 6: run(no{}, yes{}, yes{}); break;
        default: run(yes{}, yes{}, yes{}); break;
    }
    const LaneFlag<double>* __restrict slow = b.slow;
    const bool brent = opt.t_mpe_solver != TMpeSolver::closed_form;
    LaneFlag<double> n_slow = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_slow)
    for (std::size_t i = 0; i < n; ++i) n_slow += slow[i];
    if (brent || n_slow > 0)
        for (std::size_t i = 0; i < n; ++i)
            if (brent || slow[i]) exposure_lane(opt, b, i);
    if (values) decide_lanes<true>(b);
    else decide_lanes<false>(b);
}

// T_MPE and blur for every lane: exposure_of_inputs on the inputs, or on the output pixel of the
// burst where the block bins or bursts (sensor_terms). `values`: whether the lanes' rate,
// electrons, T_MPE, blur and cause are read after it (an output or the sensitivities); else
// only each lane's status, whether to solve it and its blur are left (decide_lanes).
template <class T>
void exposure(const Options& opt, Block<T>& b, bool values) {
    const double* saved[5];
    const bool sensor = sensor_terms(b, saved);
    exposure_of_inputs(opt, b, values);
    if (sensor) restore_inputs(b, saved);
}

}  // namespace detail
}  // namespace epc_fast
