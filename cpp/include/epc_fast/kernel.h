// The per-point model, evaluated a block of points at a time.
//
// Layout: each block gathers its points' parameters into contiguous arrays (structure of
// arrays) and runs the model stage by stage, each stage a loop over the block's lanes with no
// branch a vectoriser cannot turn into a select. The f50 bisection advances every lane of the
// block together; a lane stops moving once its own bracket meets the tolerance, so a point's
// result never depends on its neighbours, the block size or the thread count.
//
// The transcendental functions of the MTF are inlined polynomials (polynomials.h), so the lane
// loops vectorise to the width the build targets.
//
// A block pays only for the terms it uses: the motion and jitter factors are compiled out of
// the bisection when no lane of the block has them, and a monochromatic call never loops over
// a spectrum.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "exposure.h"
#include "mtf.h"
#include "parallel.h"
#include "params.h"
#include "status.h"

namespace epc_fast {

constexpr std::size_t block_size = 64;
// Enough halvings to take any finite bracket down to adjacent floats.
constexpr int max_bisection_steps = 2200;

namespace detail {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

// Per-lane state of one block. Every stage runs over all block_size lanes, whatever the
// number n of real points: lanes past n hold stand-ins and are never written out. A constant,
// aligned trip count leaves the vectoriser no scalar prologue or epilogue, so every lane runs
// the same instructions and a point's result does not depend on its place in the block.
struct alignas(64) Block {
    std::size_t n;
    double x[n_params][block_size];  // parameters; invalid lanes hold harmless stand-ins
    bool valid[block_size];
    double rate[block_size], electrons[block_size], t_mpe[block_size], blur[block_size];
    bool capped[block_size], no_light[block_size], full_well[block_size];
    bool unbounded[block_size];
    unsigned char solve[block_size];  // bytes, not bool: the lane loops vectorise on them
    // f50 bisection
    double lambda_f_mm[block_size], aperture_mm[block_size], jitter_mm[block_size];
    double lo[block_size], hi[block_size], mid[block_size], diffraction[block_size];
    unsigned char active[block_size];
};

// Reads points [begin, begin + n); `illuminance_lux`, when given, replaces that column with
// n values of its own (the inverse solvers' trial illuminances).
inline void gather(const Inputs& in, std::size_t begin, const double* illuminance, Block& b) {
    for (int j = 0; j < n_params; ++j) {
        const Column& col = in.columns[j];
        for (std::size_t i = 0; i < b.n; ++i) b.x[j][i] = col[begin + i];
    }
    if (illuminance != nullptr)
        for (std::size_t i = 0; i < b.n; ++i) b.x[illuminance_lux][i] = illuminance[i];
    for (std::size_t i = 0; i < block_size; ++i) b.valid[i] = i < b.n;
    for (int j = 0; j < n_params; ++j)
        for (std::size_t i = 0; i < b.n; ++i) b.valid[i] &= in.domains[j].contains(b.x[j][i]);
    // Invalid and padding lanes compute on stand-ins: no lane sees NaN or loops on garbage.
    for (int j = 0; j < n_params; ++j) {
        const double stand_in = j == mtf_threshold ? 0.5 : 1.0;
        for (std::size_t i = 0; i < block_size; ++i) b.x[j][i] = b.valid[i] ? b.x[j][i] : stand_in;
    }
}

inline void exposure(const Options& opt, Block& b) {
    const auto& x = b.x;
    for (std::size_t i = 0; i < block_size; ++i) {
        b.rate[i] = electron_rate(x[illuminance_lux][i], x[reflectance][i],
                                  x[lens_transmittance][i], x[field_angle_deg][i], x[f_number][i],
                                  x[electrons_per_lux_s_m2][i], x[fill_factor][i],
                                  x[pixel_pitch_um][i]);
        b.capped[i] = b.rate[i] > 0.0 && SnrTarget(x[snr_db][i]).capped_by(x[prnu][i]);
    }
    if (opt.t_mpe_solver == TMpeSolver::closed_form) {
        for (std::size_t i = 0; i < block_size; ++i)
            b.electrons[i] = signal_electrons(b.rate[i], SnrTarget(x[snr_db][i]), x[read_noise_e][i],
                                              x[dark_current_e_per_s][i], x[prnu][i]);
    } else {
        for (std::size_t i = 0; i < block_size; ++i)
            b.electrons[i] = b.rate[i] > 0.0 && !b.capped[i]
                                 ? signal_electrons_brent(b.rate[i], SnrTarget(x[snr_db][i]),
                                                          x[read_noise_e][i],
                                                          x[dark_current_e_per_s][i], x[prnu][i],
                                                          opt.t_mpe_rtol)
                                 : nan;
    }
    for (std::size_t i = 0; i < block_size; ++i) {
        const double t = b.electrons[i] / b.rate[i];
        // A rate so small that T_MPE overflows counts as no light.
        b.no_light[i] = !b.capped[i] && !std::isfinite(t);
        b.full_well[i] = !b.no_light[i] && !b.capped[i] && b.electrons[i] > x[full_well_e][i];
        const bool unreachable = b.capped[i] || b.no_light[i] || b.full_well[i];
        b.t_mpe[i] = unreachable ? inf : t;
        b.blur[i] = unreachable ? 0.0
                                : blur_length_mm(x[focal_length_mm][i], x[shake_deg_per_s][i],
                                                 x[stabilization][i], t);
        b.unbounded[i] = !unreachable && std::isinf(b.blur[i]);
        b.solve[i] = b.valid[i] && !unreachable && !b.unbounded[i];
        if (!b.solve[i]) b.blur[i] = 0.0;
    }
}

// One bisection step on every active lane: MTF_sys(mid) > threshold moves lo, else hi.
// Local __restrict pointers and bitwise logic keep each lane loop a straight line.
template <bool Motion, bool Jitter, bool Poly>
void bisection_step(const Spectrum& spectrum, Block& b) {
    constexpr std::size_t n = block_size;
    const double* __restrict mid = b.mid;
    const double* __restrict f_num = b.x[f_number];
    double* __restrict diffraction = b.diffraction;
    if (Poly) {
        for (std::size_t i = 0; i < n; ++i) diffraction[i] = 0.0;
        for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k) {
            const double lambda_mm = spectrum.wavelengths_nm[k] * nm_to_mm;
            const double w = spectrum.weights[k];
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i)
                diffraction[i] += w * mtf_diffraction(mid[i] * lambda_mm * f_num[i]);
        }
    } else {
        const double* __restrict lambda_f = b.lambda_f_mm;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) diffraction[i] = mtf_diffraction(mid[i] * lambda_f[i]);
    }
    const double* __restrict aperture = b.aperture_mm;
    const double* __restrict blur = b.blur;
    const double* __restrict jitter = b.jitter_mm;
    // Two loops: GCC does not if-convert a select that depends on a vector-maths call.
    double* __restrict mtf = b.diffraction;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double f = mid[i];
        double m = diffraction[i] * mtf_pixel(f, aperture[i]);
        if (Motion) m *= mtf_motion(f, blur[i]);
        if (Jitter) m *= mtf_jitter(f, jitter[i]);
        mtf[i] = m;
    }
    const double* __restrict threshold = b.x[mtf_threshold];
    const unsigned char* __restrict active = b.active;
    double* __restrict lo = b.lo;
    double* __restrict hi = b.hi;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const bool above = mtf[i] > threshold[i];
        const bool act = active[i] != 0;
        lo[i] = (act & above) ? mid[i] : lo[i];
        hi[i] = (act & !above) ? mid[i] : hi[i];
    }
}

template <bool Motion, bool Jitter, bool Poly>
void bisect(const Spectrum& spectrum, double rtol, Block& b) {
    constexpr std::size_t n = block_size;
    const unsigned char* __restrict solve = b.solve;
    const double* __restrict lo = b.lo;
    const double* __restrict hi = b.hi;
    double* __restrict mid = b.mid;
    unsigned char* __restrict active = b.active;
    for (int step = 0; step < max_bisection_steps; ++step) {
        int n_active = 0;
        EPC_FAST_SIMD_REDUCTION(+ : n_active)
        for (std::size_t i = 0; i < n; ++i) {
            const double m = lo[i] + 0.5 * (hi[i] - lo[i]);
            mid[i] = m;
            const bool a = (solve[i] != 0) & (hi[i] - lo[i] > rtol * lo[i]) & (m > lo[i]) &
                           (m < hi[i]);
            active[i] = a;
            n_active += a;
        }
        if (n_active == 0) return;
        bisection_step<Motion, Jitter, Poly>(spectrum, b);
    }
}

inline void f50(const Inputs& in, const Options& opt, Block& b) {
    const auto& x = b.x;
    const Spectrum& spectrum = in.spectrum;
    const bool poly = spectrum.polychromatic();
    double shortest_nm = inf;
    for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k)
        if (spectrum.weights[k] > 0.0) shortest_nm = std::fmin(shortest_nm, spectrum.wavelengths_nm[k]);
    bool motion = false, jitter = false;
    for (std::size_t i = 0; i < block_size; ++i) {
        b.lambda_f_mm[i] = x[wavelength_nm][i] * nm_to_mm * x[f_number][i];
        b.aperture_mm[i] = pixel_aperture_mm(x[pixel_pitch_um][i], x[fill_factor][i]);
        b.jitter_mm[i] = x[jitter_um][i] * um_to_mm;
        b.lo[i] = 0.0;
        b.hi[i] = f50_bracket(x[f_number][i], poly ? shortest_nm : x[wavelength_nm][i],
                              b.aperture_mm[i], b.blur[i], x[jitter_um][i], x[mtf_threshold][i]);
        motion |= b.solve[i] != 0 && b.blur[i] > 0.0;
        jitter |= b.solve[i] != 0 && x[jitter_um][i] > 0.0;
    }
    const double rtol = opt.f50_rtol;
    // One instantiation per combination of the terms a block uses.
    if (poly) {
        if (motion && jitter) bisect<true, true, true>(spectrum, rtol, b);
        else if (motion) bisect<true, false, true>(spectrum, rtol, b);
        else if (jitter) bisect<false, true, true>(spectrum, rtol, b);
        else bisect<false, false, true>(spectrum, rtol, b);
    } else {
        if (motion && jitter) bisect<true, true, false>(spectrum, rtol, b);
        else if (motion) bisect<true, false, false>(spectrum, rtol, b);
        else if (jitter) bisect<false, true, false>(spectrum, rtol, b);
        else bisect<false, false, false>(spectrum, rtol, b);
    }
}

inline void scatter(const Inputs& in, const Block& b, const Outputs& out) {
    const auto& x = b.x;
    for (std::size_t i = 0; i < b.n; ++i) {
        const bool valid = b.valid[i];
        const bool unreachable = b.capped[i] || b.no_light[i] || b.full_well[i];
        const bool solved = valid && !unreachable;  // ok or blur unbounded
        const double f50 = b.unbounded[i] ? 0.0 : b.lo[i] + 0.5 * (b.hi[i] - b.lo[i]);
        const double pitch_mm = x[pixel_pitch_um][i] * um_to_mm;
        const double area_mm2 = in.size_is_pixel_count ? x[size][i] * (pitch_mm * pitch_mm) : x[size][i];
        out.electron_rate_e_per_s[i] = valid ? b.rate[i] : nan;
        out.electrons[i] = valid && !b.no_light[i] && !b.capped[i] ? b.electrons[i] : nan;
        out.t_mpe_s[i] = valid ? b.t_mpe[i] : nan;
        out.blur_mm[i] = !solved ? nan : b.unbounded[i] ? inf : b.blur[i];
        out.f50_cyc_per_mm[i] = solved ? f50 : nan;
        out.epc[i] = solved ? 4.0 * area_mm2 * (f50 * f50) : nan;
        const Status status = !valid ? Status::invalid
                              : unreachable ? Status::unreachable
                              : b.unbounded[i] ? Status::blur_unbounded
                                               : Status::ok;
        const Cause cause = !valid ? Cause::none
                            : b.no_light[i] ? Cause::no_light
                            : b.capped[i] ? Cause::prnu
                            : b.full_well[i] ? Cause::full_well
                                             : Cause::none;
        out.status[i] = static_cast<unsigned char>(status);
        out.cause[i] = static_cast<unsigned char>(cause);
    }
}

}  // namespace detail

// Evaluates points [begin, begin + n), n <= block_size, writing point begin + i to index i of
// `out`. `illuminance_lux`, when not null, holds n illuminances that replace the input column.
// Never throws: every per-point problem is a status in `out`.
inline void evaluate_block(const Inputs& in, const Options& opt, const Outputs& out,
                           std::size_t begin, std::size_t n,
                           const double* illuminance_lux = nullptr) noexcept {
    detail::Block b;
    b.n = n;
    detail::gather(in, begin, illuminance_lux, b);
    detail::exposure(opt, b);
    detail::f50(in, opt, b);
    detail::scatter(in, b, out);
}

// Evaluates points [begin, end) on `threads` threads (static schedule over blocks), writing
// point i to index i of `out`.
inline void evaluate(const Inputs& in, const Options& opt, const Outputs& out, std::size_t begin,
                     std::size_t end, int threads) noexcept {
    for_each_block(begin, end, block_size, threads, [&](std::size_t first, std::size_t n) {
        evaluate_block(in, opt, out.at(first), first, n);
    });
}

}  // namespace epc_fast
