// Readout modes (python/epc_fast/modes.py): each point takes the mode with the highest EPC.
// evaluate_modes runs every mode of a block of points in turn and keeps each lane's best, in
// one pass over the points; best_modes picks the mode from every mode's EPC and take_modes
// gathers any output of the modes by that pick (for calls whose modes are separate calls:
// night mode, a frame cap). All run in blocks on the call's threads (for_each_block), each point
// on its own: the results do not depend on the thread count.
#pragma once

#include <array>
#include <memory>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "kernel.h"
#include "parallel.h"
#include "params.h"

namespace epc_fast {

// The mode index of a point where no mode has a finite EPC (every mode INVALID or UNREACHABLE).
constexpr std::int16_t no_mode = -1;

// Points a block of best_modes and take_modes covers: enough work to be worth a grab.
constexpr std::size_t mode_block_points = 4096;

// Whether a mode of EPC `epc` is better than the best so far (of EPC `best`, mode `pick`): its
// EPC finite (v - v is 0; NaN for NaN and +-inf), and the first finite one or a larger one (a
// tie keeps the earlier mode).
EPC_FAST_INLINE bool better_mode(double epc, double best, std::int16_t pick) {
    return (epc - epc == 0.0) & ((pick == no_mode) | (epc > best));
}

// mode[i] for i < n: the first mode with the largest finite EPC among epc[k][i] (NaN and +-inf
// are not finite), no_mode where none is. Never throws.
inline void best_modes(const std::vector<const double*>& epc, std::int16_t* mode, std::size_t n,
                       int threads) noexcept {
    struct None {};
    for_each_block<None>(0, n, mode_block_points, threads,
                         [&](std::size_t first, std::size_t count, None&) {
        alignas(64) double best[mode_block_points];
        std::int16_t* __restrict pick = mode + first;
        for (std::size_t i = 0; i < count; ++i) {
            best[i] = 0.0;
            pick[i] = no_mode;
        }
        for (std::size_t k = 0; k < epc.size(); ++k) {
            const double* __restrict v = epc[k] + first;
            const auto index = static_cast<std::int16_t>(k);
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < count; ++i) {
                const bool better = better_mode(v[i], best[i], pick[i]);
                best[i] = better ? v[i] : best[i];
                pick[i] = better ? index : pick[i];
            }
        }
    });
}

// out[i] = values[mode[i]][i] for i < n, elements of `item_bytes` bytes (1, 2, 4 or 8); a point
// of no_mode takes the first mode's. Never throws.
inline void take_modes(const std::int16_t* mode, const std::vector<const void*>& values,
                       std::size_t item_bytes, void* out, std::size_t n, int threads) noexcept {
    struct None {};
    auto take = [&](auto item) {
        using Item = decltype(item);
        Item* to = static_cast<Item*>(out);
        for_each_block<None>(0, n, mode_block_points, threads,
                             [&](std::size_t first, std::size_t count, None&) {
            for (std::size_t i = first; i < first + count; ++i) {
                const std::size_t k = mode[i] > 0 ? static_cast<std::size_t>(mode[i]) : 0;
                to[i] = static_cast<const Item*>(values[k])[i];
            }
        });
    };
    switch (item_bytes) {
        case 1: take(std::uint8_t{}); break;
        case 2: take(std::uint16_t{}); break;
        case 4: take(std::uint32_t{}); break;
        default: take(std::uint64_t{}); break;
    }
}

// `to`'s columns: `in`'s, with the columns `mode` sets broadcast from its values (`mode` must
// outlive them). A mode's value outside its domain makes every point INVALID in that mode
// (gather.h), as it would in a call of its own.
inline void set_mode_columns(const Inputs& in, const ReadoutMode& mode, Inputs& to) {
    to.columns = in.columns;
    for (int p = 0; p < 4; ++p)
        if (mode.sets[static_cast<std::size_t>(p)])
            to.columns[mode_params[p]] = Column{&mode.values[static_cast<std::size_t>(p)], 0};
}

// Each mode's inputs: `in` with its columns set by the mode (set_mode_columns; `modes` must
// outlive them).
inline std::vector<Inputs> mode_inputs(const Inputs& in, const std::vector<ReadoutMode>& modes) {
    std::vector<Inputs> each(modes.size(), in);
    for (std::size_t k = 0; k < modes.size(); ++k) set_mode_columns(in, modes[k], each[k]);
    return each;
}

namespace detail {

// One block's outputs, a row of block_size lanes each: a mode's as evaluate_block writes them,
// or the best so far. `epc` is always kept (the pick reads it).
struct ModeRows {
    alignas(64) double values[7][block_size];  // rate, electrons, T_MPE, blur, f50, EPC, across
    alignas(64) unsigned char codes[2][block_size];  // status, cause
    alignas(64) double shares[n_shares][block_size];
    alignas(64) double elasticities[n_params][block_size];

    // Outputs writing the rows `out` asks for (and EPC) into these rows.
    Outputs rows_for(const Outputs& out) {
        auto row = [](const void* asked, auto* r) { return asked != nullptr ? r : nullptr; };
        Outputs o{row(out.electron_rate_e_per_s, values[0]), row(out.electrons, values[1]),
                  row(out.t_mpe_s, values[2]), row(out.blur_mm, values[3]),
                  row(out.f50_cyc_per_mm, values[4]), values[5], row(out.status, codes[0]),
                  row(out.cause, codes[1])};
        o.f50_across_cyc_per_mm = row(out.f50_across_cyc_per_mm, values[6]);
        o.epc_both = out.epc_both;
        for (int s = 0; s < n_shares; ++s) o.sensitivity.share[s] = row(out.sensitivity.share[s], shares[s]);
        for (int j = 0; j < n_params; ++j)
            o.sensitivity.elasticity[j] = row(out.sensitivity.elasticity[j], elasticities[j]);
        return o;
    }
};

// A thread's state for evaluate_modes: a kernel Workspace for each mode (each keeps its own
// mode's broadcast rows and layout from block to block: gather.h), the best rows (the first
// mode's written there directly) and a later mode's.
// A mode past the first whose Workspace cannot be allocated shares the first's: a Workspace
// holds only caches keyed by value, so the results are the same.
struct ModesWorkspace {
    Workspace first;
    std::vector<std::unique_ptr<Workspace>> more;
    ModeRows mode, best;

    Workspace& of(std::size_t k) noexcept {
        if (k == 0) return first;
        try {
            while (more.size() < k) more.push_back(std::make_unique<Workspace>());
            return *more[k - 1];
        } catch (...) {  // no memory for another: the first's caches serve this mode too
            return first;
        }
    }
};

// best's lanes of n where `take` (a row of flags) from `from`, for every row `rows` writes.
inline void take_lanes(const Outputs& rows, const ModeRows& from, ModeRows& best,
                       const unsigned char* __restrict take, std::size_t n) {
    auto select = [&](const auto* asked, const auto* src, auto* dst) {
        if (asked == nullptr) return;
        for (std::size_t i = 0; i < n; ++i) dst[i] = take[i] ? src[i] : dst[i];
    };
    const double* value_rows[] = {rows.electron_rate_e_per_s, rows.electrons, rows.t_mpe_s,
                                  rows.blur_mm, rows.f50_cyc_per_mm, rows.epc,
                                  rows.f50_across_cyc_per_mm};
    for (int r = 0; r < 7; ++r) select(value_rows[r], from.values[r], best.values[r]);
    select(rows.status, from.codes[0], best.codes[0]);
    select(rows.cause, from.codes[1], best.codes[1]);
    for (int s = 0; s < n_shares; ++s) select(rows.sensitivity.share[s], from.shares[s], best.shares[s]);
    for (int j = 0; j < n_params; ++j)
        select(rows.sensitivity.elasticity[j], from.elasticities[j], best.elasticities[j]);
}

// `best`'s first n lanes into `out` from point `begin` on, for every output `out` asks for.
inline void write_best(const ModeRows& best, const Outputs& out, std::size_t begin, std::size_t n) {
    auto write = [&](auto* to, const auto* from) {
        if (to != nullptr) std::memcpy(to + begin, from, n * sizeof *from);
    };
    double* value_outputs[] = {out.electron_rate_e_per_s, out.electrons, out.t_mpe_s,
                               out.blur_mm, out.f50_cyc_per_mm, out.epc,
                               out.f50_across_cyc_per_mm};
    for (int r = 0; r < 7; ++r) write(value_outputs[r], best.values[r]);
    write(out.status, best.codes[0]);
    write(out.cause, best.codes[1]);
    for (int s = 0; s < n_shares; ++s) write(out.sensitivity.share[s], best.shares[s]);
    for (int j = 0; j < n_params; ++j) write(out.sensitivity.elasticity[j], best.elasticities[j]);
}

}  // namespace detail

// Points [first, first + n) of every mode (inputs: mode_inputs), n <= block_size, each point
// the outputs of its mode with the largest finite EPC (the first of equal ones; the first
// mode's where none is finite) written to `out` and that mode's index to pick[0 .. n - 1]
// (no_mode where none): the block evaluated in every mode in turn (kernel.h evaluate_block)
// and its lanes' best kept, so that only the best is written out. Never throws.
inline void evaluate_modes_block(const std::vector<Inputs>& inputs, const Options& opt,
                                 const Outputs& out, std::int16_t* pick, std::size_t first,
                                 std::size_t n, detail::ModesWorkspace& ws) noexcept {
    detail::ModeRows& current = ws.mode;
    detail::ModeRows& best = ws.best;
    const Outputs rows = current.rows_for(out);
    const double* __restrict best_epc = best.values[5];
    const double* __restrict epc = current.values[5];
    // the first mode straight into the best rows: every lane's best so far
    evaluate_block(inputs[0], opt, best.rows_for(out), first, n, nullptr, ws.of(0));
    for (std::size_t i = 0; i < n; ++i)
        pick[i] = better_mode(best_epc[i], 0.0, no_mode) ? std::int16_t{0} : no_mode;
    alignas(64) unsigned char take[block_size];
    for (std::size_t k = 1; k < inputs.size(); ++k) {
        evaluate_block(inputs[k], opt, rows, first, n, nullptr, ws.of(k));
        const auto index = static_cast<std::int16_t>(k);
        for (std::size_t i = 0; i < n; ++i) {
            const bool better = better_mode(epc[i], best_epc[i], pick[i]);
            take[i] = better;
            pick[i] = better ? index : pick[i];
        }
        detail::take_lanes(rows, current, best, take, n);
    }
    detail::write_best(best, out, first, n);
}

// Points [begin, end) of every mode (evaluate_modes_block), in one pass over the points on
// `threads` threads, each point's mode index in mode[begin .. end - 1]. Never throws.
inline void evaluate_modes(const std::vector<Inputs>& inputs, const Options& opt,
                           const Outputs& out, std::int16_t* mode, std::size_t begin,
                           std::size_t end, int threads) noexcept {
    for_each_block<detail::ModesWorkspace>(
        begin, end, block_size, threads,
        [&](std::size_t first, std::size_t n, detail::ModesWorkspace& ws) {
            evaluate_modes_block(inputs, opt, out, mode + first, first, n, ws);
        });
}

}  // namespace epc_fast
