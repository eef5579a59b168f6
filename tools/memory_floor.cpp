// What an evaluate() call's memory traffic alone costs: the bytes of a call over n points of
// random_designs (seven float64 input columns read, the outputs written), moved by the
// package's own scheduler (parallel.h: blocks of block_size points, 16 a grab) with next to no
// arithmetic. No kernel, however fast, runs a call faster than this on the same machine. Prints
// the best and mean points/s of `rounds` calls.
//
//   g++ -std=c++17 -O3 -march=native -fopenmp -I cpp/include tools/memory_floor.cpp
//       -o /tmp/memory_floor      (one command, from the repository's root)
//   /tmp/memory_floor [points=10000000] [default|lean|out|stream] [rounds=5] [threads=2]
//
// default: the eight outputs of a default call (six float64, status and cause uint8: 50 bytes a
//          point) in new allocations, as NumPy makes them (malloc, and madvise(MADV_HUGEPAGE)
//          on the page-aligned part, as NumPy does for allocations of 4 MiB and more), so that
//          every output page is faulted in, and zeroed by the kernel, during the call;
// lean:    the same for outputs=("f50_cyc_per_mm", "epc", "status") (17 bytes a point);
// out:     the eight outputs written into arrays allocated and touched once before (out=),
//          64-byte aligned as the output cache's (output_cache.h), with ordinary stores;
// stream:  the same with streaming stores (stream.h), as a large call writes them.
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "epc_fast/block.h"
#include "epc_fast/parallel.h"
#include "epc_fast/stream.h"

namespace {

void* allocate(std::size_t bytes) {
    void* p = std::malloc(bytes);
    if (p == nullptr) {
        std::fprintf(stderr, "out of memory\n");
        std::exit(1);
    }
    const auto begin = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t aligned = (begin + 4095) & ~std::uintptr_t{4095};
    if (bytes >= (std::size_t{4} << 20) && aligned - begin < bytes)
        madvise(reinterpret_cast<void*>(aligned), (bytes - (aligned - begin)) & ~std::size_t{4095},
                MADV_HUGEPAGE);
    return p;
}

// 2 MiB-aligned memory marked for huge pages, as the output cache's blocks (output_cache.h)
void* aligned(std::size_t bytes) {
    constexpr std::size_t huge = std::size_t{2} << 20;
    void* p = std::aligned_alloc(huge, (bytes + huge - 1) / huge * huge);
    if (p == nullptr) {
        std::fprintf(stderr, "out of memory\n");
        std::exit(1);
    }
    madvise(p, (bytes + huge - 1) / huge * huge, MADV_HUGEPAGE);
    return p;
}

struct Call {
    std::vector<double*> values;           // float64 outputs (null: not asked for)
    std::vector<unsigned char*> codes;      // uint8 outputs
};

}  // namespace

int main(int argc, char** argv) {
    const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 10000000;
    const std::string mode = argc > 2 ? argv[2] : "default";
    const int rounds = argc > 3 ? std::atoi(argv[3]) : 5;
    const int threads = argc > 4 ? std::atoi(argv[4]) : 2;
    if (n == 0 || rounds <= 0 || threads <= 0 ||
        (mode != "default" && mode != "lean" && mode != "out" && mode != "stream")) {
        std::fprintf(stderr, "usage: memory_floor [points] [default|lean|out|stream] [rounds] [threads]\n");
        return 2;
    }
    const int n_values = mode == "lean" ? 2 : 6, n_codes = mode == "lean" ? 1 : 2;
    constexpr int n_inputs = 7;
    std::vector<double*> in(n_inputs);
    for (int k = 0; k < n_inputs; ++k) {
        in[k] = static_cast<double*>(allocate(n * sizeof(double)));
        for (std::size_t i = 0; i < n; ++i) in[k][i] = 1.0 + static_cast<double>((i + k) % 7);
    }
    const bool kept_outputs = mode == "out" || mode == "stream", stream = mode == "stream";
    auto new_call = [&] {
        Call c;
        for (int k = 0; k < n_values; ++k) c.values.push_back(static_cast<double*>(allocate(n * sizeof(double))));
        for (int k = 0; k < n_codes; ++k) c.codes.push_back(static_cast<unsigned char*>(allocate(n)));
        return c;
    };
    auto release = [](Call& c) {
        for (auto* p : c.values) std::free(p);
        for (auto* p : c.codes) std::free(p);
    };
    Call kept;
    if (kept_outputs) {  // allocated (aligned) and faulted in once, before the timed calls
        for (int k = 0; k < n_values; ++k) kept.values.push_back(static_cast<double*>(aligned(n * sizeof(double))));
        for (int k = 0; k < n_codes; ++k) kept.codes.push_back(static_cast<unsigned char*>(aligned(n)));
        for (auto* p : kept.values) std::memset(p, 0, n * sizeof(double));
        for (auto* p : kept.codes) std::memset(p, 0, n);
    }
    double best = 0.0, total_s = 0.0, check = 0.0;
    for (int r = 0; r < rounds; ++r) {
        const auto start = std::chrono::steady_clock::now();
        Call c = kept_outputs ? kept : new_call();
        // each block's outputs computed into the block, then copied out, as kernel.h scatters
        // (streamed only for a full block of m = block_size points, as kernel.h scatter)
        auto put = [stream](void* to, const void* from, std::size_t bytes, std::size_t m) {
            if (stream && m == epc_fast::block_size)
                epc_fast::stream_copy(to, from, bytes);
            else
                std::memcpy(to, from, bytes);
        };
        struct Fence {  // each thread's streamed lines visible before the call returns
            ~Fence() { epc_fast::stream_fence(); }
        };
        epc_fast::for_each_block<Fence>(
            0, n, epc_fast::block_size, threads, [&](std::size_t first, std::size_t m, Fence&) {
                // every output from two inputs, so that all seven columns are read
                for (int k = 0; k < n_values; ++k) {
                    const double* __restrict x = in[k % n_inputs] + first;
                    const double* __restrict y = in[(k + 1) % n_inputs] + first;
                    alignas(64) double o[epc_fast::block_size];
                    EPC_FAST_SIMD
                    for (std::size_t i = 0; i < m; ++i) o[i] = x[i] * y[i];
                    put(c.values[k] + first, o, m * sizeof(double), m);
                }
                for (int k = 0; k < n_codes; ++k) {
                    const double* __restrict x = in[(n_values + k) % n_inputs] + first;
                    alignas(64) unsigned char o[epc_fast::block_size];
                    EPC_FAST_SIMD
                    for (std::size_t i = 0; i < m; ++i) o[i] = x[i] > 3.0;
                    put(c.codes[k] + first, o, m, m);
                }
            });
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        check += c.values[0][n / 2] + c.codes[0][n / 3];
        if (!kept_outputs) release(c);
        best = std::max(best, static_cast<double>(n) / s);
        total_s += s;
    }
    if (kept_outputs) release(kept);
    for (auto* p : in) std::free(p);
    std::printf("%s, %zu points, %d thread(s): best %.1f M points/s, mean %.1f (check %g)\n",
                mode.c_str(), n, threads, best / 1e6, static_cast<double>(n) * rounds / total_s / 1e6,
                check);
    return 0;
}
