// The kernel's exposure stage (kernel.h): each lane's electron rate, T_MPE and blur, and from
// them its status and cause, a block at a time.
//
// The formulas are exposure.h's. The vector path computes them with plain products whose
// partial products are checked to stay inside 2^-900..2^900 (then they equal exposure.h's
// scaled products bit for bit), one reciprocal shared by the quotients with the same divisor
// (divide_by: the same bits as dividing), and vectorised hypot and tan. A lane it cannot vouch
// for, or every lane when Brent is asked for, is redone by exposure.h's formulas themselves
// (exposure_lane). A block drops the terms it does not use (ExposureTerms), with the same bits.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "block.h"
#include "constants.h"
#include "exposure.h"
#include "optics.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"
#include "status.h"

namespace epc_fast {

namespace detail {

// Whether a partial product is a normal double. A plain product of positive factors whose every
// partial product is normal equals scaled_product's result bit for bit (the same roundings, no
// scaling needed).
EPC_FAST_INLINE bool normal(double v) {
    return (v >= std::numeric_limits<double>::min()) & (v <= std::numeric_limits<double>::max());
}

// Whether v lies inside 2^-900..2^900, where a quotient formed by divide_by is the correctly
// rounded one (its residual neither underflows nor overflows).
EPC_FAST_INLINE bool moderate(double v) {
    return (v >= 0x1p-900) & (v <= 0x1p900);
}

// a / b, rounded correctly, from inverse_b = 1 / b rounded: one division then serves every
// quotient by b. q = a inverse_b is within an ulp of a / b; the residual a - q b is exact with a
// fused multiply-add, and q + (a - q b) inverse_b, rounded once, is the correctly rounded a / b
// (Markstein, IBM J. Res. Dev. 34(1), 1990) for a, b and a / b inside 2^-900..2^900 (moderate;
// the callers send other lanes to exposure_lane). Checked against the division for 2e8 random
// and adversarial pairs (tests/core/test_exposure.py checks the kernel's results). The
// unfused build divides.
EPC_FAST_INLINE double divide_by(double a, double b, double inverse_b) {
#if EPC_FAST_FMA
    const double q = a * inverse_b;
    return std::fma(std::fma(-q, b, a), inverse_b, q);
#else
    (void)inverse_b;
    return a / b;
#endif
}

#if !EPC_FAST_FMA
// The rounding error a b - fl(a b), exactly (Dekker's product with Veltkamp's split): what
// std::fma(a, b, -a * b) gives, in plain arithmetic that vectorises everywhere. Exact for
// |a|, |b| < 1e300 whose product neither overflows nor underflows. Only in the unfused build:
// under -ffp-contract=fast the compiler could fuse inside the split, and the fused build has
// std::fma at the places that need an exact product.
EPC_FAST_INLINE double product_error(double a, double b) {
    constexpr double split = 134217729.0;  // 2^27 + 1
    const double p = a * b;
    const double ca = split * a, cb = split * b;
    const double a_hi = ca - (ca - a), a_lo = a - a_hi;
    const double b_hi = cb - (cb - b), b_lo = b - b_hi;
    return ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
}
#endif

// tan(angle) for 0 <= angle < pi/2, as sinpi(t) / cospi(t) with t = angle / pi carried in two
// doubles (t_hi + t_lo, Dekker's product): cospi's argument 1/2 - t_hi is exact, and t_lo keeps
// the digits that tan's condition number near pi/2 would otherwise amplify. Within a few ulp
// of the C library's tan of the same angle. Both arguments lie in [0, 1/2], where sinpi
// reduces nothing (round gives 0, 1/2 included: ties to even), so sinpi_reduced gives sinpi's
// bits; for a larger angle the result is meaningless and the caller selects inf instead.
EPC_FAST_INLINE double tan_of_angle(double angle) {
    constexpr double inv_pi_hi = 0.3183098861837907;     // 1/pi rounded
    constexpr double inv_pi_lo = -1.9678676675182486e-17;  // 1/pi - inv_pi_hi
#if EPC_FAST_FMA
    // 1/2 - angle inv_pi_hi exactly, rounded once: no rounding error to carry (and none that a
    // fused t_hi could count twice)
    const double fused_cos_arg = std::fma(-angle, inv_pi_hi, 0.5) - angle * inv_pi_lo;
    return sinpi_reduced(angle * inv_pi_hi + angle * inv_pi_lo) / sinpi_reduced(fused_cos_arg);
#else
    const double t_hi = angle * inv_pi_hi;
    const double t_lo = product_error(angle, inv_pi_hi) + angle * inv_pi_lo;
    const double cos_arg = (0.5 - t_hi) - t_lo;
    return sinpi_reduced(t_hi + t_lo) / sinpi_reduced(cos_arg);
#endif
}

// Above this y, hypot_moderate's y^2 could overflow: the caller redoes the lane.
constexpr double hypot_moderate_max = 0x1p500;

// hypot(x, y) = sqrt(x^2 + y^2) as it reads, with no division, for x in [1e-150, 1e150] (10^(snr/20)
// inside the SNR domain) and 0 <= y <= hypot_moderate_max: x^2 is a normal double, x^2 + y^2
// cannot overflow, and a y^2 that underflows is below 1e-16 of x^2's ulp. x exactly when
// y = 0 (sqrt(fl(x^2)) = x in binary arithmetic), else within 1 ulp.
EPC_FAST_INLINE double hypot_moderate(double x, double y) {
#if EPC_FAST_FMA
    return std::sqrt(std::fma(x, x, y * y));
#else
    return std::sqrt(x * x + y * y);
#endif
}

// The rows of Block::sensor_store (sensor_terms, below).
enum SensorRow : int { sensor_read, sensor_dark, sensor_prnu, sensor_well, sensor_stab, sensor_pixels };

// T_MPE, blur and the unreachable causes of one lane by the general formulas of exposure.h
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

// Denoising (optics.h): every noise variance times the filter's noise gain g, met after the
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

// Binning and bursts (exposure.h): a block whose binning or frames are not a broadcast 1 reads
// the read noise, dark current, PRNU, full well and stabilisation as the output pixel of the
// burst sees them (sensor_store's rows), and multiplies the rate by k^2; every other block
// reads its inputs as they are. With k = n = 1 in a lane, its row values are its inputs.

// The sensor rows of a block that has binning or bursts; x[] points at them for the exposure
// stage (restore_inputs puts the inputs back). Returns whether the block has them.
template <class T>
bool sensor_terms(const Options& opt, Block<T>& b, const double* (&saved)[5]) {
    b.sensor = !(b.broadcast_is(binning, 1.0) && b.broadcast_is(frames, 1.0));
    if (!b.sensor) return false;
    constexpr int inputs[5] = {read_noise_e, dark_current_e_per_s, prnu, full_well_e, stabilization};
    for (int r = 0; r < 5; ++r) saved[r] = b.x[inputs[r]];
    const double* __restrict k = b.x[binning];
    const double* __restrict n = b.x[frames];
    const bool charge = opt.charge_binning;
    auto& row = b.sensor_store;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const double pixels = binned_pixels(k[i]);
        row[sensor_pixels][i] = pixels;
        row[sensor_read][i] = burst_read_noise_e(saved[0][i], k[i], n[i], charge);
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

// T_MPE and blur for every lane. The vector path computes the closed form with plain products
// and vectorised hypot and tan; a lane whose products leave the normal range, or any lane
// when Brent is asked for, is redone by exposure_lane. cos(theta) and 10^(snr/20) are computed once for a
// block when their columns are broadcast.
// T_MPE and blur for every lane, on the inputs as x[] holds them (sensor_terms'); `values`:
// whether the rate, electrons, T_MPE, blur and cause are read (decide_lanes).
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
    const double* __restrict well = x[full_well_e];
    double* __restrict rate = b.rate;
    double* __restrict electrons = b.electrons;
    double* __restrict t_mpe = b.t_mpe;
    double* __restrict blur = b.blur;
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
    if (!b.broadcast_is(cfa_transmittance, 1.0)) {  // a colour sensor's filters: t r
        const double* __restrict t = x[cfa_transmittance];
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double rt = rate[i] * t[i];
            rate[i] = rt;
            rate_normal[i] &= moderate(rt);
        }
    }
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
    const bool sensor = sensor_terms(opt, b, saved);
    exposure_of_inputs(opt, b, values);
    if (sensor) restore_inputs(b, saved);
}

}  // namespace detail

}  // namespace epc_fast
