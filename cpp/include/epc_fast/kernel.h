// The per-point model, evaluated a block of points at a time.
//
// Layout: each block gathers its points' parameters into contiguous arrays (structure of
// arrays, block.h) and runs the model stage by stage, each stage a loop over the block's lanes
// with no branch a vectoriser cannot turn into a select: gather (gather.h), exposure (T_MPE and
// blur: exposure/stage.h), f50 (f50/stage.h), the shares and elasticities when asked for
// (sensitivity.h), scatter (here).
//
// The transcendental functions of the MTF are inlined polynomials (polynomials.h), so the lane
// loops vectorise to the width the build targets.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "block.h"
#include "exposure/stage.h"
#include "f50/stage.h"
#include "gather.h"
#include "parallel.h"
#include "params.h"
#include "sensitivity.h"
#include "status.h"
#include "stream.h"
#include "test_slowdown.h"

namespace epc_fast {

namespace detail {

// f_out[i]: f50 where solved, 0 where the blur is unbounded, NaN elsewhere, for every lane.
template <class T>
EPC_FAST_INLINE void f50_lanes(const Block<T>& b, double* __restrict f_out) {
    const unsigned char* __restrict status = b.status;
    const T* __restrict f50 = b.f50;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) {
        const unsigned char st = status[i];
        f_out[i] = st == static_cast<unsigned char>(Status::ok)               ? double{f50[i]}
                   : st == static_cast<unsigned char>(Status::blur_unbounded) ? 0.0
                                                                              : nan;
    }
}

// epc[i] = 4 S f^2 for the first n lanes, from their f50 f (f50_lanes) and sensor size.
template <class T>
EPC_FAST_INLINE void epc_lanes(const Inputs& in, const Block<T>& b, const double* __restrict f,
                               double* __restrict epc, std::size_t n) {
    const double* __restrict sz = b.x[size];
    const double* __restrict pitch = b.x[pixel_pitch_um];
    const bool count = in.size_is_pixel_count;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double pitch_mm = pitch[i] * um_to_mm;
        const double area_mm2 = count ? sz[i] * (pitch_mm * pitch_mm) : sz[i];
        epc[i] = 4.0 * area_mm2 * (f[i] * f[i]);
    }
}

// EPC counted in both directions for the first n lanes, as python/epc_fast/axes.py epc_both
// forms it from the paper's EPC (epc, in place) and the two f50s: EPC f50_across / f50, 0
// where the blur is unbounded (f50 = 0), NaN where the status is BEYOND_TABLE (the f50 across
// passed a table's end: combined_status).
template <class T>
EPC_FAST_INLINE void epc_both_lanes(const Block<T>& b, const double* __restrict f,
                                    const unsigned char* __restrict status,
                                    double* __restrict epc, std::size_t n) {
    const double* __restrict across = b.across_out;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double value = f[i] == 0.0 ? 0.0 * across[i] : epc[i] * (across[i] / f[i]);
        epc[i] = status[i] == static_cast<unsigned char>(Status::beyond_table) ? nan : value;
    }
}

// The status counted in both directions into `status`: BEYOND_TABLE where the lane is OK along
// the motion and its f50 across passed a table's end.
template <class T>
EPC_FAST_INLINE void combined_status(const Block<T>& b, unsigned char* __restrict status) {
    const unsigned char* __restrict along = b.status;
    const unsigned char* __restrict beyond = b.across_beyond;
    constexpr auto ok = static_cast<unsigned char>(Status::ok);
    constexpr auto past = static_cast<unsigned char>(Status::beyond_table);
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i)
        status[i] = (along[i] == ok) & (beyond[i] != 0) ? past : along[i];
}

// to[i] = from[i] for the block's lanes, unless `to` is null (an output not asked for).
template <class V>
EPC_FAST_INLINE void copy_lanes(V* __restrict to, const V* __restrict from) {
    if (to == nullptr) return;
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) to[i] = from[i];
}

// Writes the block's n points; an output pointer that is null is not computed. The exposure
// stage left the rate, electrons, T_MPE, blur, status and cause as they are written out.
// A full block that is not streamed is written by fixed-length lane loops straight into the
// outputs. Other blocks are staged: a partial one is copied n points, a full block of a
// streaming call writes its whole cache lines with streaming stores (stream.h stream_copy;
// the thread's fence is in ~Workspace).
template <class T>
void scatter(const Inputs& in, const Block<T>& b, const Outputs& out) {
    const std::size_t n = b.n;
    const bool stream = out.stream && n == block_size;
    const bool asked = out.f50_cyc_per_mm != nullptr || out.epc != nullptr;
    // the status as written: counted in both directions with epc_both
    alignas(64) unsigned char both_status[block_size];
    if (out.epc_both) combined_status(b, both_status);
    const unsigned char* status = out.epc_both ? both_status : b.status;
    // the exposure's outputs, and the f50 across, each by `copy`
    auto exposure_outputs = [&](auto&& copy) {
        copy(out.electron_rate_e_per_s, b.rate);
        copy(out.electrons, b.electrons);
        copy(out.t_mpe_s, b.t_mpe);
        copy(out.blur_mm, b.blur_out);
        copy(out.status, status);
        copy(out.cause, b.cause);
        copy(out.f50_across_cyc_per_mm, b.across_out);
    };
    if (n == block_size && !stream) {
        exposure_outputs([](auto* to, const auto* from) { copy_lanes(to, from); });
        if (!asked) return;
        alignas(64) double f_own[block_size];
        double* f_out = out.f50_cyc_per_mm != nullptr ? out.f50_cyc_per_mm : f_own;
        f50_lanes(b, f_out);
        if (out.epc != nullptr) {
            epc_lanes(in, b, f_out, out.epc, block_size);
            if (out.epc_both) epc_both_lanes(b, f_out, status, out.epc, block_size);
        }
        return;
    }
    auto copy = [n, stream](auto* to, const auto* from) {
        if (to == nullptr) return;
        if (stream) stream_copy(to, from, n * sizeof *from);
        else std::memcpy(to, from, n * sizeof *from);
    };
    exposure_outputs(copy);
    if (!asked) return;
    alignas(64) double f_out[block_size];
    f50_lanes(b, f_out);
    copy(out.f50_cyc_per_mm, f_out);
    if (out.epc != nullptr) {
        alignas(64) double epc[block_size];
        epc_lanes(in, b, f_out, epc, n);
        if (out.epc_both) epc_both_lanes(b, f_out, status, epc, n);
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

// The f50 across the motion (docs/model.md, "Resolution in both directions") into
// b.across_out (NaN unless solved) and b.across_beyond, after the f50 along it: the same
// block solved again with the motion blur 0, as the exposure left it otherwise (a lane whose
// blur was unbounded is solved too), exactly as a call with the shake rate 0 would solve it.
// The f50 along, the status and the lanes float32 could not solve (`wide`, from either pass)
// are as the first pass left them.
template <class T>
void across_f50(const Spectrum& spectrum, const Options& opt, Block<T>& b) {
    alignas(64) T f50_along[block_size];
    alignas(64) unsigned char status_along[block_size], wide_along[block_size];
    constexpr auto ok = static_cast<unsigned char>(Status::ok);
    constexpr auto past = static_cast<unsigned char>(Status::beyond_table);
    constexpr auto unbounded = static_cast<unsigned char>(Status::blur_unbounded);
    for (std::size_t i = 0; i < block_size; ++i) {
        const unsigned char st = b.status[i];
        f50_along[i] = b.f50[i];
        status_along[i] = st;
        wide_along[i] = b.wide[i];
        const bool timed = (st == ok) | (st == past) | (st == unbounded);
        b.status[i] = timed ? ok : st;
        b.solve[i] = timed;
        b.blur[i] = 0.0;
    }
    f50(spectrum, opt, b);
    for (std::size_t i = 0; i < block_size; ++i) {
        const unsigned char st = b.status[i];
        b.across_out[i] = st == ok ? static_cast<double>(b.f50[i]) : nan;
        b.across_beyond[i] = st == past;
        b.f50[i] = f50_along[i];
        b.status[i] = status_along[i];
        b.wide[i] = static_cast<unsigned char>(b.wide[i] | wide_along[i]);
    }
}

// Evaluates points [begin, begin + n) with f50 solved in T (block.h).
template <class T>
void evaluate_block_as(const Inputs& in, const Options& opt, const Outputs& out, std::size_t begin,
                       std::size_t n, const double* illuminance_lux, Block<T>& b) {
    b.n = n;
    gather(in, begin, illuminance_lux, b);
    exposure(opt, b, out.exposure_values_read());
    // a lens table replaces diffraction and with it the spectrum: f50 is solved as for one
    // wavelength (the shares' aberration-free D keeps the call's spectrum: sensitivity.h)
    static const Spectrum no_spectrum{};
    const Spectrum& spectrum = in.lens_tables.empty() ? in.spectrum : no_spectrum;
    b.lens_tables = in.lens_tables.empty() ? nullptr : &in.lens_tables;
    b.demosaic_table = in.demosaic.knots.empty() ? nullptr : &in.demosaic;
    if (out.f50_cyc_per_mm != nullptr || out.epc != nullptr || out.sensitivity.any() ||
        out.across()) {
        f50(spectrum, opt, b);
        if (out.across()) across_f50(spectrum, opt, b);
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
// T_MPE are those of float64). A lane whose lengths float32 cannot hold (f50/settle.h) is redone
// with the whole block in float64 and takes that result: each point's result still depends only
// on its own inputs.
inline void evaluate_block(const Inputs& in, const Options& opt, const Outputs& out,
                           std::size_t begin, std::size_t n, const double* illuminance_lux,
                           Workspace& ws) noexcept {
    [[maybe_unused]] TestSlowdown slowdown;  // nothing unless EPC_FAST_TEST_SLOWDOWN
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
    double across[block_size];
    Outputs wide_out{values[0], values[1], values[2], values[3], values[4], values[5],
                     codes[0], codes[1]};
    wide_out.f50_across_cyc_per_mm = out.f50_across_cyc_per_mm != nullptr ? across : nullptr;
    wide_out.epc_both = out.epc_both;
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
    take(out.f50_across_cyc_per_mm, across);
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
                              of(out.status), of(out.cause), of(out.f50_across_cyc_per_mm)};
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
