// Inverse problems over illuminance, nested over the forward model:
//   lux_for_epc:   the illuminance at which a design reaches a target EPC;
//   crossover_lux: the highest illuminance in a range at which two designs have equal EPC.
// Both run Brent's method on u = ln(illuminance) in lockstep over the lanes of a block: each
// iteration evaluates the forward model once for the whole block (kernel.h) at every lane's
// trial illuminance, so the forward model keeps its vectorised layout.
//
// The forward EPC of a point that is UNREACHABLE counts as 0 (no image; BLUR_UNBOUNDED is 0
// already); an INVALID point makes its inverse INVALID. With a design's f50 across the motion
// (epc_axes="both": a column independent of the illuminance, solved once by the caller), the
// forward EPC is 4 S f50 f50_across = EPC f50_across / f50; without it (data null), the
// paper's 4 S f50^2. python/epc_fast/inverse.py holds the
// NumPy reference of the same definitions.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "brent.h"
#include "kernel.h"
#include "parallel.h"
#include "params.h"
#include "status.h"

namespace epc_fast {

enum class InverseStatus : std::uint8_t { ok = 0, invalid = 1, no_solution = 2 };

struct InverseOptions {
    double lux_lo, lux_hi;  // the search range, 0 < lux_lo < lux_hi < inf
    double rtol;            // on the illuminance (an absolute tolerance on ln L)
    int grid_points = 64;   // crossover_lux: samples of the range that bracket the crossings
    int max_iter = 200;     // Brent iterations per lane
};

struct InverseOutputs {
    double* illuminance_lux;
    double* epc;
    unsigned char* status;
};

namespace detail {

// EPC of points [begin, begin + n) at the given illuminances; invalid[i] when the point's
// inputs are out of their domains. Unreachable points count as EPC 0. `ws` is the calling
// thread's (its broadcast rows and remembered constants serve every trial of the block).
inline void epc_at(const Inputs& in, const Column& across, const Options& opt, std::size_t begin,
                   std::size_t n, const double* lux, double* epc, bool* invalid, Workspace& ws) {
    double rate[block_size], electrons[block_size], t_mpe[block_size], blur[block_size];
    double f50[block_size];
    unsigned char status[block_size], cause[block_size];
    const Outputs out{rate, electrons, t_mpe, blur, f50, epc, status, cause};
    evaluate_block(in, opt, out, begin, n, lux, ws);
    for (std::size_t i = 0; i < n; ++i) {
        invalid[i] = status[i] == static_cast<unsigned char>(Status::invalid);
        if (status[i] == static_cast<unsigned char>(Status::unreachable)) epc[i] = 0.0;
        else if (across.data != nullptr && f50[i] > 0.0) epc[i] *= across[begin + i] / f50[i];
    }
}

// Lockstep Brent over the running lanes of a block: g(u, lane) fills values for trial u's.
// On return, state[i].b is lane i's root for every lane that was running.
template <class G>
void brent_lanes(std::size_t n, BrentState* state, bool* running, int max_iter, G&& g) {
    double u[block_size], value[block_size];
    for (int iter = 0; iter < max_iter; ++iter) {
        bool any = false;
        for (std::size_t i = 0; i < n; ++i) {
            u[i] = state[i].b;  // finished lanes re-evaluate their root: harmless
            if (running[i]) {
                double next;
                running[i] = !state[i].step(next);
                if (running[i]) u[i] = next;
                any |= running[i];
            }
        }
        if (!any) return;
        g(u, value);
        for (std::size_t i = 0; i < n; ++i)
            if (running[i]) state[i].accept(value[i]);
    }
}

// Writes each OK lane's root illuminance e^b and the EPC of `in` there; NaN elsewhere.
inline void write_roots(const Inputs& in, const Column& across, const Options& opt,
                        std::size_t begin, std::size_t n,
                        const BrentState* state, const InverseOutputs& out, Workspace& ws) {
    double lux[block_size], epc[block_size];
    bool invalid[block_size];
    for (std::size_t i = 0; i < n; ++i) lux[i] = std::exp(state[i].b);
    epc_at(in, across, opt, begin, n, lux, epc, invalid, ws);
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < n; ++i) {
        const bool ok = out.status[i] == static_cast<unsigned char>(InverseStatus::ok);
        out.illuminance_lux[i] = ok ? lux[i] : nan;
        out.epc[i] = ok ? epc[i] : nan;
    }
}

inline void lux_for_epc_block(const Inputs& in, const Column& across, const Column& target_epc,
                              const Options& opt,
                              const InverseOptions& inv, std::size_t begin, std::size_t n,
                              const InverseOutputs& out, Workspace& ws) {
    const double u_lo = std::log(inv.lux_lo), u_hi = std::log(inv.lux_hi);
    double lux[block_size], epc_lo[block_size], epc_hi[block_size], target[block_size];
    bool invalid_lo[block_size], invalid_hi[block_size], running[block_size];
    BrentState state[block_size];
    for (std::size_t i = 0; i < n; ++i) lux[i] = inv.lux_lo;
    epc_at(in, across, opt, begin, n, lux, epc_lo, invalid_lo, ws);
    for (std::size_t i = 0; i < n; ++i) lux[i] = inv.lux_hi;
    epc_at(in, across, opt, begin, n, lux, epc_hi, invalid_hi, ws);
    for (std::size_t i = 0; i < n; ++i) {
        target[i] = target_epc[begin + i];
        const bool invalid = invalid_lo[i] || invalid_hi[i] || !(target[i] > 0.0) ||
                             !std::isfinite(target[i]);
        const double g_lo = epc_lo[i] - target[i], g_hi = epc_hi[i] - target[i];
        running[i] = !invalid && g_lo < 0.0 && g_hi >= 0.0;
        out.status[i] = static_cast<unsigned char>(
            invalid ? InverseStatus::invalid
                    : running[i] ? InverseStatus::ok : InverseStatus::no_solution);
        state[i].start(u_lo, g_lo, u_hi, g_hi, 0.0, inv.rtol);
    }
    bool invalid[block_size];
    brent_lanes(n, state, running, inv.max_iter, [&](const double* u, double* g) {
        for (std::size_t i = 0; i < n; ++i) lux[i] = std::exp(u[i]);
        epc_at(in, across, opt, begin, n, lux, g, invalid, ws);
        for (std::size_t i = 0; i < n; ++i) g[i] -= target[i];
    });
    write_roots(in, across, opt, begin, n, state, out, ws);
}

inline void crossover_lux_block(const Inputs& a, const Column& across_a, const Inputs& b,
                                const Column& across_b, const Options& opt,
                                const InverseOptions& inv, std::size_t begin, std::size_t n,
                                const InverseOutputs& out, Workspace& ws) {
    const double u_lo = std::log(inv.lux_lo), u_hi = std::log(inv.lux_hi);
    double lux[block_size], epc_a[block_size], epc_b[block_size];
    bool invalid_a[block_size], invalid_b[block_size], invalid[block_size] = {};
    bool found[block_size] = {}, have_prev[block_size] = {};
    double u_prev[block_size], d_prev[block_size], u_bracket[block_size], d_bracket[block_size];
    auto difference = [&](const double* u, double* d) {
        for (std::size_t i = 0; i < n; ++i) lux[i] = std::exp(u[i]);
        epc_at(a, across_a, opt, begin, n, lux, epc_a, invalid_a, ws);
        epc_at(b, across_b, opt, begin, n, lux, epc_b, invalid_b, ws);
        for (std::size_t i = 0; i < n; ++i) {
            d[i] = epc_a[i] - epc_b[i];
            invalid[i] |= invalid_a[i] || invalid_b[i];
        }
    };
    // Scan the grid from the top: the first pair of neighbouring non-zero differences of
    // opposite sign brackets the highest crossing.
    double u[block_size], d[block_size];
    const int last = inv.grid_points - 1;
    for (int k = last; k >= 0; --k) {
        const double uk = k == last ? u_hi : k == 0 ? u_lo : u_lo + (u_hi - u_lo) * k / last;
        for (std::size_t i = 0; i < n; ++i) u[i] = uk;
        difference(u, d);
        bool all_found = true;
        for (std::size_t i = 0; i < n; ++i) {
            if (!found[i] && d[i] != 0.0 && !std::isnan(d[i])) {
                if (have_prev[i] && (d[i] > 0.0) != (d_prev[i] > 0.0)) {
                    found[i] = true;
                    u_bracket[i] = uk;
                    d_bracket[i] = d[i];
                } else {
                    have_prev[i] = true;
                    u_prev[i] = uk;
                    d_prev[i] = d[i];
                }
            }
            all_found &= found[i] || invalid[i];
        }
        if (all_found) break;
    }
    bool running[block_size];
    BrentState state[block_size];
    for (std::size_t i = 0; i < n; ++i) {
        running[i] = found[i] && !invalid[i];
        out.status[i] = static_cast<unsigned char>(
            invalid[i] ? InverseStatus::invalid
                       : running[i] ? InverseStatus::ok : InverseStatus::no_solution);
        if (running[i]) state[i].start(u_bracket[i], d_bracket[i], u_prev[i], d_prev[i], 0.0, inv.rtol);
        else state[i].start(u_lo, 0.0, u_hi, 0.0, 0.0, inv.rtol);
    }
    brent_lanes(n, state, running, inv.max_iter, difference);
    write_roots(a, across_a, opt, begin, n, state, out, ws);
}

inline InverseOutputs offset(const InverseOutputs& out, std::size_t first) {
    return InverseOutputs{out.illuminance_lux + first, out.epc + first, out.status + first};
}

}  // namespace detail

// Points [begin, end): the illuminance where each design reaches target_epc[i]; `across`, each
// design's f50 across the motion, or a null column for the paper's EPC. Never throws.
inline void lux_for_epc(const Inputs& in, const Column& across, const Column& target_epc,
                        const Options& opt,
                        const InverseOptions& inv, const InverseOutputs& out, std::size_t begin,
                        std::size_t end, int threads) noexcept {
    for_each_block<Workspace>(begin, end, block_size, threads,
                              [&](std::size_t first, std::size_t n, Workspace& ws) {
                                  detail::lux_for_epc_block(in, across, target_epc, opt, inv, first, n,
                                                            detail::offset(out, first), ws);
                              });
}

// Points [begin, end): the highest illuminance in the range where designs a[i] and b[i] have
// equal EPC; `across_a`, `across_b` as for lux_for_epc. Never throws.
inline void crossover_lux(const Inputs& a, const Column& across_a, const Inputs& b,
                          const Column& across_b, const Options& opt,
                          const InverseOptions& inv, const InverseOutputs& out, std::size_t begin,
                          std::size_t end, int threads) noexcept {
    for_each_block<Workspace>(begin, end, block_size, threads,
                              [&](std::size_t first, std::size_t n, Workspace& ws) {
                                  detail::crossover_lux_block(a, across_a, b, across_b, opt, inv, first, n,
                                                              detail::offset(out, first), ws);
                              });
}

}  // namespace epc_fast
