// The fused scan pass: for each block of points, form their parameters (space.h), evaluate the
// model (kernel.h), find their groups (groups.h) and fold the outputs into the reductions
// (reductions.h), all while the block is in cache. Nothing per point is stored.
//
// Threads share a chunk's scan blocks (scan_block_points each); a scan block is folded by one
// thread in point order, and each thread keeps its own reduction states, added together after
// the pass (counts, min, max and the k best do not depend on the order). So the results are
// the same bits for any thread count and any chunking into whole scan blocks.
#pragma once

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "../kernel.h"
#include "../modes.h"
#include "../parallel.h"
#include "groups.h"
#include "reductions.h"
#include "space.h"

namespace epc_fast {

// What a chunk's pass gives back: each reduction's state over the chunk (its threads'
// states combined), and each summary's moments per scan block, (blocks, groups) row-major.
struct ChunkResult {
    std::vector<ReductionState> states;
    struct Moments {
        std::vector<std::int64_t> count;
        std::vector<double> mean, m2;
    };
    std::vector<Moments> moments;  // per reduction (empty but for summaries)
};

namespace detail {

// A thread's workspace for the pass: its points, the kernel's, the outputs and groups of a
// block, and its reduction states. Allocated before the threads start (nothing in the
// parallel region allocates).
struct ScanThread {
    ScanLanes lanes;
    Inputs inputs;
    Workspace workspace;
    alignas(64) double outputs[n_scan_outputs][block_size];
    alignas(64) double log10_outputs[n_scan_outputs][block_size];
    alignas(64) unsigned char status[block_size];
    std::vector<std::vector<std::int32_t>> groups;  // per key, block_size each
    std::vector<std::int32_t> scratch;
    std::vector<ReductionState> states;
    FoldLanes fold;  // views of the arrays above
    // readout modes (modes.h): each mode's inputs (the block's columns, the mode's values
    // over them), the modes' workspace with a Workspace per mode, each lane's mode
    std::vector<Inputs> mode_inputs;
    std::unique_ptr<ModesWorkspace> modes;
    alignas(64) std::int16_t pick[block_size];

    ScanThread(const ScanSpace& space, const std::vector<GroupKey>& keys,
               const std::vector<Reduction>& reductions, const std::vector<ReadoutMode>& readout)
        : lanes(space), inputs(space.inputs), groups(keys.size(), std::vector<std::int32_t>(block_size)),
          scratch(block_size) {
        if (!readout.empty()) {
            mode_inputs = epc_fast::mode_inputs(space.inputs, readout);
            modes = std::make_unique<ModesWorkspace>();
            for (std::size_t k = 1; k < readout.size(); ++k) modes->more.push_back(std::make_unique<Workspace>());
        }
        states.reserve(reductions.size());
        for (const Reduction& r : reductions) states.emplace_back(r);
        fold.index = lanes.index;
        fold.status = status;
        fold.mode = readout.empty() ? nullptr : pick;
        for (int o = 0; o < n_scan_outputs; ++o) {
            fold.outputs[o] = outputs[o];
            fold.log10_outputs[o] = log10_outputs[o];
        }
        for (const auto& g : groups) fold.groups.push_back(g.data());
    }
    ScanThread(const ScanThread&) = delete;
    ScanThread& operator=(const ScanThread&) = delete;
};

}  // namespace detail

// The outputs (Outputs order) that the reductions read, and which of them they read as log10.
struct ScanNeeds {
    bool output[n_scan_outputs] = {};
    bool log10[n_scan_outputs] = {};

    explicit ScanNeeds(const std::vector<Reduction>& reductions) {
        for (const Reduction& r : reductions) {
            output[r.of] = true;
            if (r.kind == ReductionKind::histogram && r.log)
                log10[r.of] = true;
        }
    }
};

// Draws, evaluates and reduces points [start, stop) of the scan (start a multiple of
// scan_block_points) on `threads` threads; with readout `modes`, each point in the mode of
// the largest EPC (modes.h evaluate_modes_block). Never throws inside the threads: every
// allocation is made before they start; per-point problems are statuses.
inline ChunkResult scan_chunk(const ScanSpace& space, const Options& opt,
                              const std::vector<GroupKey>& keys,
                              const std::vector<Reduction>& reductions, std::uint64_t start,
                              std::uint64_t stop, int threads, bool epc_both = false,
                              const std::vector<ReadoutMode>& modes = {}) {
    const std::uint64_t n_points = stop > start ? stop - start : 0;
    const auto n_blocks = static_cast<std::ptrdiff_t>((n_points + scan_block_points - 1) / scan_block_points);
    const ScanNeeds needs(reductions);
    ChunkResult result;
    result.moments.resize(reductions.size());
    for (std::size_t r = 0; r < reductions.size(); ++r) {
        if (reductions[r].kind != ReductionKind::summary) continue;
        const auto cells = static_cast<std::size_t>(n_blocks) * static_cast<std::size_t>(reductions[r].groups);
        result.moments[r].count.assign(cells, 0);
        result.moments[r].mean.assign(cells, 0.0);
        result.moments[r].m2.assign(cells, 0.0);
    }
    int team = threads;
#ifdef _OPENMP
    if (n_blocks < team) team = static_cast<int>(n_blocks > 0 ? n_blocks : 1);
#else
    team = 1;
#endif
    std::vector<std::unique_ptr<detail::ScanThread>> workers;
    for (int t = 0; t < team; ++t)
        workers.push_back(std::make_unique<detail::ScanThread>(space, keys, reductions, modes));

    auto run_block = [&](std::ptrdiff_t b, detail::ScanThread& w) {
        const std::uint64_t block_first = start + static_cast<std::uint64_t>(b) * scan_block_points;
        const std::uint64_t block_end = std::min<std::uint64_t>(stop, block_first + scan_block_points);
        for (std::size_t r = 0; r < reductions.size(); ++r) {
            if (reductions[r].kind != ReductionKind::summary) continue;
            ReductionState& s = w.states[r];
            std::fill(s.block_count.begin(), s.block_count.end(), 0);
            std::fill(s.block_mean.begin(), s.block_mean.end(), 0.0);
            std::fill(s.block_m2.begin(), s.block_m2.end(), 0.0);
        }
        Outputs out{needs.output[0] ? w.outputs[0] : nullptr, needs.output[1] ? w.outputs[1] : nullptr,
                    needs.output[2] ? w.outputs[2] : nullptr, needs.output[3] ? w.outputs[3] : nullptr,
                    needs.output[4] ? w.outputs[4] : nullptr, needs.output[5] ? w.outputs[5] : nullptr,
                    w.status, nullptr};
        for (int s = 0; s < n_shares; ++s)
            out.sensitivity.share[s] = needs.output[6 + s] ? w.outputs[6 + s] : nullptr;
        out.epc_both = epc_both;  // EPC and the status in both directions (kernel.h)
        for (std::uint64_t first = block_first; first < block_end; first += block_size) {
            const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(block_size, block_end - first));
            w.lanes.n = n;
            for (std::size_t i = 0; i < n; ++i) w.lanes.index[i] = first + i;
            form_points(space, true, w.lanes, w.inputs);
            if (modes.empty()) {
                evaluate_block(w.inputs, opt, out, 0, n, nullptr, w.workspace);
            } else {
                for (std::size_t k = 0; k < modes.size(); ++k)
                    set_mode_columns(w.inputs, modes[k], w.mode_inputs[k]);
                evaluate_modes_block(w.mode_inputs, opt, out, w.pick, 0, n, *w.modes);
            }
            for (int o = 0; o < n_scan_outputs; ++o) {
                if (!needs.log10[o]) continue;
                const double* __restrict v = w.outputs[o];
                double* __restrict t = w.log10_outputs[o];
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) t[i] = log10_any(v[i] > 0.0 ? v[i] : 0.0);
            }
            for (std::size_t k = 0; k < keys.size(); ++k) {
                const std::vector<std::int32_t>& cycle = keys[k].cycle;
                if (cycle.empty()) {
                    group_indices(keys[k], space, w.lanes, w.groups[k].data(), w.scratch.data());
                    continue;
                }
                // a block of the key's cycle (first is a multiple of block_size, as the
                // cycle's length is)
                const std::int32_t* __restrict from = cycle.data() + first % cycle.size();
                std::int32_t* __restrict to = w.groups[k].data();
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) to[i] = from[i];
            }
            w.fold.n = n;
            w.fold.first = first;
            for (std::size_t r = 0; r < reductions.size(); ++r) fold(reductions[r], w.fold, w.states[r]);
        }
        for (std::size_t r = 0; r < reductions.size(); ++r)
            if (reductions[r].cycle > 0)
                flush_cycle(reductions[r], keys[static_cast<std::size_t>(reductions[r].key)], w.states[r]);
        for (std::size_t r = 0; r < reductions.size(); ++r) {
            if (reductions[r].kind != ReductionKind::summary) continue;
            const ReductionState& s = w.states[r];
            const auto groups = static_cast<std::size_t>(reductions[r].groups);
            ChunkResult::Moments& m = result.moments[r];
            const std::size_t row = static_cast<std::size_t>(b) * groups;
            std::copy(s.block_count.begin(), s.block_count.end(), m.count.begin() + static_cast<std::ptrdiff_t>(row));
            std::copy(s.block_mean.begin(), s.block_mean.end(), m.mean.begin() + static_cast<std::ptrdiff_t>(row));
            std::copy(s.block_m2.begin(), s.block_m2.end(), m.m2.begin() + static_cast<std::ptrdiff_t>(row));
        }
    };

#ifdef _OPENMP
#pragma omp parallel num_threads(team)
    {
        detail::ScanThread& w = *workers[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(dynamic, 1)
        for (std::ptrdiff_t b = 0; b < n_blocks; ++b) run_block(b, w);
    }
#else
    for (std::ptrdiff_t b = 0; b < n_blocks; ++b) run_block(b, *workers[0]);
#endif
    result.states = std::move(workers[0]->states);
    for (std::size_t t = 1; t < workers.size(); ++t)
        for (std::size_t r = 0; r < reductions.size(); ++r)
            combine(reductions[r], result.states[r], workers[t]->states[r]);
    return result;
}

// The parameters and discrete axes' indices of the points `index[0 .. n - 1]`, as the fused
// pass forms them: values[j] (n each) for each parameter that is not fixed (others left
// untouched), axis_index[a] (n each) for each discrete axis.
inline void scan_points(const ScanSpace& space, const std::uint64_t* index, std::size_t n,
                        double* const* values, std::int32_t* const* axis_index) {
    ScanLanes lanes(space);
    Inputs in = space.inputs;
    for (std::size_t first = 0; first < n; first += block_size) {
        const std::size_t m = std::min(block_size, n - first);
        lanes.n = m;
        bool consecutive = true;
        for (std::size_t i = 0; i < m; ++i) {
            lanes.index[i] = index[first + i];
            consecutive &= i == 0 || lanes.index[i] == lanes.index[i - 1] + 1;
        }
        form_points(space, consecutive, lanes, in);
        for (int j = 0; j < n_params; ++j)
            if (values[j] != nullptr)
                for (std::size_t i = 0; i < m; ++i) values[j][first + i] = lanes.values[j][i];
        for (std::size_t a = 0; a < space.axes.size(); ++a)
            for (std::size_t i = 0; i < m; ++i) axis_index[a][first + i] = lanes.axis_index[a][i];
    }
}

}  // namespace epc_fast
