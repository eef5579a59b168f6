// The per-point model, evaluated a block of points at a time.
//
// Layout: each block gathers its points' parameters into contiguous arrays (structure of
// arrays, block.h) and runs the model stage by stage, each stage a loop over the block's lanes
// with no branch a vectoriser cannot turn into a select: gather, exposure (T_MPE and blur),
// f50 (f50.h), scatter.
//
// The transcendental functions of the MTF are inlined polynomials (polynomials.h), so the lane
// loops vectorise to the width the build targets.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "block.h"
#include "exposure.h"
#include "f50.h"
#include "parallel.h"
#include "params.h"
#include "sensitivity.h"
#include "status.h"
#include "stream.h"

namespace epc_fast {

namespace detail {

// The value invalid and padding lanes compute on: no lane sees NaN or loops on garbage.
inline double stand_in(int param) { return param == mtf_threshold ? 0.5 : 1.0; }

// valid[i] &= x[i] in d, for every lane; the domain's open or closed ends are decided once.
inline void check_domain(const Domain& d, const double* __restrict x, unsigned char* __restrict valid) {
    const double lo = d.lo, hi = d.hi;
    if (d.lo_closed && d.hi_closed) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] &= (x[i] >= lo) & (x[i] <= hi);
    } else if (d.lo_closed) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] &= (x[i] >= lo) & (x[i] < hi);
    } else if (d.hi_closed) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] &= (x[i] > lo) & (x[i] <= hi);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) valid[i] &= (x[i] > lo) & (x[i] < hi);
    }
}

inline bool same_bits(double a, double b) {
    std::uint64_t x = 0, y = 0;
    std::memcpy(&x, &a, sizeof x);
    std::memcpy(&y, &b, sizeof y);
    return x == y;
}

// Reads points [begin, begin + n); `illuminance_lux`, when given, replaces that column with
// n values of its own (the inverse solvers' trial illuminances). A broadcast column (stride 0)
// is checked once and copied to every lane; padding lanes past n get stand-ins.
template <class T>
void gather(const Inputs& in, std::size_t begin, const double* illuminance, Block<T>& b) {
    const std::size_t n = b.n;
    unsigned char* __restrict valid = b.valid;
    for (std::size_t i = 0; i < block_size; ++i) valid[i] = i < n;
    b.uniform = 0;
    for (int j = 0; j < n_params; ++j) {
        const bool replaced = j == illuminance_lux && illuminance != nullptr;
        const double* src = replaced ? illuminance : in.columns[j].data;
        const std::ptrdiff_t stride = replaced ? 1 : in.columns[j].stride;
        double* __restrict x = b.x_store[j];
        const std::uint32_t bit = std::uint32_t{1} << j;
        if (stride == 0) {
            // every lane holds the value, or the stand-in if it is invalid, even a lane that is
            // invalid for another parameter (harmless: a value inside the domain)
            const double v = src[0];
            const bool ok = in.domains[j].contains(v);
            const double fill = ok ? v : stand_in(j);
            if (!((b.row_filled & bit) != 0 && same_bits(b.row_value[j], fill))) {
                for (std::size_t i = 0; i < block_size; ++i) x[i] = fill;
                b.row_value[j] = fill;
                b.row_filled |= bit;
            }
            if (!ok)
                for (std::size_t i = 0; i < block_size; ++i) valid[i] = 0;
            b.uniform |= bit;
            b.broadcast[j] = fill;
            b.x[j] = x;
            continue;
        }
        b.row_filled &= ~bit;
        if (!replaced) src += static_cast<std::ptrdiff_t>(begin) * stride;
        if (stride == 1 && n == block_size) {
            b.x[j] = src;  // read in place (copied below if a lane turns out invalid)
            check_domain(in.domains[j], src, valid);
            continue;
        }
        if (stride == 1) {
            for (std::size_t i = 0; i < n; ++i) x[i] = src[i];
        } else {
            for (std::size_t i = 0; i < n; ++i) x[i] = src[static_cast<std::ptrdiff_t>(i) * stride];
        }
        for (std::size_t i = n; i < block_size; ++i) x[i] = stand_in(j);
        check_domain(in.domains[j], x, valid);
        b.x[j] = x;
    }
    int n_valid = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_valid)
    for (std::size_t i = 0; i < block_size; ++i) n_valid += valid[i];
    if (n_valid == static_cast<int>(block_size)) return;
    for (int j = 0; j < n_params; ++j) {
        if (b.is_broadcast(j)) continue;  // already harmless
        double* __restrict x = b.x_store[j];
        if (b.x[j] != x) {  // read in place so far: copy, to hold the stand-ins
            const double* __restrict src = b.x[j];
            for (std::size_t i = 0; i < block_size; ++i) x[i] = src[i];
            b.x[j] = x;
        }
        const double s = stand_in(j);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) x[i] = valid[i] ? x[i] : s;
    }
}

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
// and adversarial pairs (tests/test_exposure.py checks the kernel's results). The
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
    const SnrTarget target(x[snr_db][i]);
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
    const bool shake = !b.broadcast_is(shake_deg_per_s, 0.0);
    return {!b.broadcast_is(dark_current_e_per_s, 0.0), !b.broadcast_is(read_noise_e, 0.0),
            !b.broadcast_is(prnu, 0.0), !shake ? 0 : b.broadcast_is(stabilization, 1.0) ? 1 : 2};
}

// signal_electrons and blur_length_mm for every lane, from the rate, sqrt(s) and the PRNU margin
// w; flag_scratch[0] marks the lanes whose products leave the normal range (exposure_lane redoes
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
    const unsigned char* __restrict rate_normal = b.flag_scratch[1];
    const unsigned char* __restrict capped = b.capped;
    double* __restrict electrons = b.electrons;
    double* __restrict t_mpe = b.t_mpe;
    double* __restrict blur = b.blur;
    unsigned char* __restrict slow = b.flag_scratch[0];
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

// T_MPE and blur for every lane. The vector path computes the closed form with plain products
// and vectorised hypot and tan; a lane whose products leave the normal range, or any lane
// when Brent is asked for, is redone by exposure_lane. cos(theta) and 10^(snr/20) are computed once for a
// block when their columns are broadcast.
template <class T>
void exposure(const Options& opt, Block<T>& b) {
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
    unsigned char* __restrict capped = b.capped;
    // Three stages, each small enough for GCC to vectorise (one loop with all of it does not):
    // the rate, the PRNU margin, then electrons and blur.
    double* __restrict w_margin = b.scratch[2];
    unsigned char* __restrict rate_normal = b.flag_scratch[1];
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
    const unsigned char* __restrict slow = b.flag_scratch[0];
    const bool brent = opt.t_mpe_solver != TMpeSolver::closed_form;
    int n_slow = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_slow)
    for (std::size_t i = 0; i < n; ++i) n_slow += slow[i];
    if (brent || n_slow > 0)
        for (std::size_t i = 0; i < n; ++i)
            if (brent || slow[i]) exposure_lane(opt, b, i);
    // Each lane's status and cause, and its rate, electrons, T_MPE and blur as they are written
    // out (NaN where undefined): decided once here, where the flags are at hand, so that
    // scatter only copies them.
    unsigned char* __restrict status = b.status;
    unsigned char* __restrict cause = b.cause;
    double* __restrict blur_out = b.blur_out;
    unsigned char* __restrict solve = b.solve;
    const unsigned char* __restrict valid = b.valid;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double t = t_mpe[i];  // electrons / rate, from either path
        const bool ok = valid[i] != 0, cap = capped[i] != 0;
        // A rate so small that T_MPE overflows counts as no light.
        const bool dark_lane = !cap & !(t <= std::numeric_limits<double>::max());
        const bool over = !dark_lane & !cap & (electrons[i] > well[i]);
        const bool unreachable = cap | dark_lane | over;
        const bool inf_blur = !unreachable & (blur[i] > std::numeric_limits<double>::max());
        const bool s = ok & !unreachable & !inf_blur;
        status[i] = !ok          ? static_cast<unsigned char>(Status::invalid)
                    : unreachable ? static_cast<unsigned char>(Status::unreachable)
                    : inf_blur    ? static_cast<unsigned char>(Status::blur_unbounded)
                                  : static_cast<unsigned char>(Status::ok);
        cause[i] = !ok        ? static_cast<unsigned char>(Cause::none)
                   : dark_lane ? static_cast<unsigned char>(Cause::no_light)
                   : cap       ? static_cast<unsigned char>(Cause::prnu)
                   : over      ? static_cast<unsigned char>(Cause::full_well)
                               : static_cast<unsigned char>(Cause::none);
        rate[i] = ok ? rate[i] : nan;
        electrons[i] = ok & !dark_lane & !cap ? electrons[i] : nan;
        t_mpe[i] = !ok ? nan : unreachable ? inf : t;
        blur_out[i] = !ok | unreachable ? nan : inf_blur ? inf : blur[i];
        solve[i] = s;
        blur[i] = s ? blur[i] : 0.0;
    }
}

// Writes the block's n points; an output pointer that is null is not computed. The exposure
// stage left the rate, electrons, T_MPE, blur, status and cause as they are written out.
// A full block of a streaming call writes its whole cache lines with streaming stores
// (stream.h stream_copy); the thread's fence is in ~Workspace.
template <class T>
void scatter(const Inputs& in, const Block<T>& b, const Outputs& out) {
    const std::size_t n = b.n;
    const auto& x = b.x;
    const bool stream = out.stream && n == block_size;
    auto copy = [n, stream](auto* to, const auto* from) {
        if (to == nullptr) return;
        if (stream) stream_copy(to, from, n * sizeof *from);
        else std::memcpy(to, from, n * sizeof *from);
    };
    copy(out.electron_rate_e_per_s, b.rate);
    copy(out.electrons, b.electrons);
    copy(out.t_mpe_s, b.t_mpe);
    copy(out.blur_mm, b.blur_out);
    copy(out.status, b.status);
    copy(out.cause, b.cause);
    if (out.f50_cyc_per_mm == nullptr && out.epc == nullptr) return;
    // f50 where solved, 0 where the blur is unbounded, NaN elsewhere; EPC from it
    const unsigned char* __restrict status = b.status;
    const T* __restrict f50 = b.f50;
    alignas(64) double f_out[block_size];
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const unsigned char st = status[i];
        f_out[i] = st == static_cast<unsigned char>(Status::ok)               ? double{f50[i]}
                   : st == static_cast<unsigned char>(Status::blur_unbounded) ? 0.0
                                                                              : nan;
    }
    copy(out.f50_cyc_per_mm, f_out);
    if (out.epc != nullptr) {
        alignas(64) double epc[block_size];
        const double* __restrict sz = x[size];
        const double* __restrict pitch = x[pixel_pitch_um];
        const bool count = in.size_is_pixel_count;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double pitch_mm = pitch[i] * um_to_mm;
            const double area_mm2 = count ? sz[i] * (pitch_mm * pitch_mm) : sz[i];
            const double f = f_out[i];
            epc[i] = 4.0 * area_mm2 * (f * f);
        }
        copy(out.epc, epc);
    }
}

// Writes the block's n points of the shares and elasticities (sensitivity.h), for the outputs
// that ask for them; with streaming stores as scatter writes.
template <class T>
void scatter_sensitivity(const Inputs& in, const Block<T>& b, const Outputs& out) {
    const SensitivityOutputs& to = out.sensitivity;
    alignas(64) double shares[n_shares][block_size];
    alignas(64) double elasticities[n_params][block_size];
    sensitivity(in, b, to.any_share(), to.any_elasticity(), shares, elasticities);
    const std::size_t n = b.n;
    const bool stream = out.stream && n == block_size;
    auto copy = [n, stream](double* dst, const double* from) {
        if (stream) stream_copy(dst, from, n * sizeof *from);
        else std::memcpy(dst, from, n * sizeof *from);
    };
    for (int s = 0; s < n_shares; ++s)
        if (to.share[s] != nullptr) copy(to.share[s], shares[s]);
    for (int j = 0; j < n_params; ++j)
        if (to.elasticity[j] != nullptr) copy(to.elasticity[j], elasticities[j]);
}

// Evaluates points [begin, begin + n) with f50 solved in T (block.h).
template <class T>
void evaluate_block_as(const Inputs& in, const Options& opt, const Outputs& out, std::size_t begin,
                       std::size_t n, const double* illuminance_lux, Block<T>& b) {
    b.n = n;
    gather(in, begin, illuminance_lux, b);
    exposure(opt, b);
    if (out.f50_cyc_per_mm != nullptr || out.epc != nullptr || out.sensitivity.any()) {
        f50(in.spectrum, opt, b);
    } else {  // f50 not asked for: not solved (status and the rest need only the exposure)
        for (std::size_t i = 0; i < block_size; ++i) b.wide[i] = 0;
    }
    scatter(in, b, out);
    if (out.sensitivity.any()) scatter_sensitivity(in, b, out);
}

}  // namespace detail

// The per-thread state of evaluate: one Block per lane type, kept from block to block (its
// broadcast rows and remembered constants carry over; gather, exposure).
struct Workspace {
    detail::Block<double> block64;
    detail::Block<float> block32;
    Workspace() = default;
    Workspace(const Workspace&) = delete;
    Workspace& operator=(const Workspace&) = delete;
    // Each thread keeps its Workspace until its last block is written: its streaming stores
    // (scatter) are fenced here, before the call returns and the results are read.
    ~Workspace() { stream_fence(); }
};

// Evaluates points [begin, begin + n), n <= block_size, writing point begin + i to index i of
// `out`. `illuminance_lux`, when not null, holds n illuminances that replace the input column.
// Never throws: every per-point problem is a status in `out`.
//
// Precision::float32 solves f50 in float32 (everything else stays float64, so statuses and
// T_MPE are those of float64). A lane whose lengths float32 cannot hold (f50.h) is redone with
// the whole block in float64 and takes that result: each point's result still depends only on
// its own inputs.
inline void evaluate_block(const Inputs& in, const Options& opt, const Outputs& out,
                           std::size_t begin, std::size_t n, const double* illuminance_lux,
                           Workspace& ws) noexcept {
    if (opt.precision == Precision::float64) {
        detail::evaluate_block_as(in, opt, out, begin, n, illuminance_lux, ws.block64);
        return;
    }
    detail::Block<float>& b = ws.block32;
    detail::evaluate_block_as(in, opt, out, begin, n, illuminance_lux, b);
    int n_wide = 0;
    for (std::size_t i = 0; i < n; ++i) n_wide += b.wide[i];
    if (n_wide == 0) return;
    double values[6][block_size];
    unsigned char codes[2][block_size];
    Outputs wide_out{values[0], values[1], values[2], values[3], values[4], values[5],
                     codes[0], codes[1]};
    // the sensitivity outputs asked for, as rows of block_size
    double shares[n_shares][block_size];
    double elasticities[n_params][block_size];
    for (int s = 0; s < n_shares; ++s)
        wide_out.sensitivity.share[s] = out.sensitivity.share[s] != nullptr ? shares[s] : nullptr;
    for (int j = 0; j < n_params; ++j)
        wide_out.sensitivity.elasticity[j] =
            out.sensitivity.elasticity[j] != nullptr ? elasticities[j] : nullptr;
    detail::evaluate_block_as(in, opt, wide_out, begin, n, illuminance_lux, ws.block64);
    stream_fence();  // the block's streamed lines land before these lanes overwrite them
    auto take = [&](auto* to, const auto* from) {
        if (to != nullptr)
            for (std::size_t i = 0; i < n; ++i)
                if (b.wide[i]) to[i] = from[i];
    };
    take(out.electron_rate_e_per_s, values[0]);
    take(out.electrons, values[1]);
    take(out.t_mpe_s, values[2]);
    take(out.blur_mm, values[3]);
    take(out.f50_cyc_per_mm, values[4]);
    take(out.epc, values[5]);
    take(out.status, codes[0]);
    take(out.cause, codes[1]);
    for (int s = 0; s < n_shares; ++s) take(out.sensitivity.share[s], shares[s]);
    for (int j = 0; j < n_params; ++j) take(out.sensitivity.elasticity[j], elasticities[j]);
}

// first_touch (parallel.h) over the pages of the outputs' points [begin, end): for output arrays
// just allocated, before evaluate writes them.
inline void first_touch(const Outputs& out, std::size_t begin, std::size_t end,
                        int threads) noexcept {
    const std::size_t n = end > begin ? end - begin : 0;
    auto of = [&](auto* p) {
        return Region{reinterpret_cast<unsigned char*>(p != nullptr ? p + begin : nullptr), n * sizeof *p};
    };
    const Region regions[] = {of(out.electron_rate_e_per_s), of(out.electrons), of(out.t_mpe_s),
                              of(out.blur_mm), of(out.f50_cyc_per_mm), of(out.epc),
                              of(out.status), of(out.cause)};
    first_touch(regions, threads);
    const SensitivityOutputs& s = out.sensitivity;
    if (!s.any()) return;
    Region more[n_shares + n_params];
    for (int k = 0; k < n_shares; ++k) more[k] = of(s.share[k]);
    for (int j = 0; j < n_params; ++j)
        more[n_shares + j] = of(s.elasticity[j]);
    first_touch(more, threads);
}

// `out` for a call of n points: streaming (stream.h) when its outputs total stream_min_bytes
// or more, too many to stay in the caches until the caller reads them.
inline Outputs streaming_for(Outputs out, std::size_t n) noexcept {
    out.stream = streaming_stores && out.bytes_per_point() * n >= stream_min_bytes;
    return out;
}

// Evaluates points [begin, end) on `threads` threads (blocks shared out dynamically), writing
// point i to index i of `out`. Each thread keeps one Workspace for all its blocks.
inline void evaluate(const Inputs& in, const Options& opt, const Outputs& out, std::size_t begin,
                     std::size_t end, int threads) noexcept {
    for_each_block<Workspace>(
        begin, end, block_size, threads, [&](std::size_t first, std::size_t n, Workspace& ws) {
            evaluate_block(in, opt, out.at(first), first, n, nullptr, ws);
        });
}

}  // namespace epc_fast
