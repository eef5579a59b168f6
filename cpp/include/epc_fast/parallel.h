// OpenMP, or its absence, behind three small functions. The kernel's results never depend
// on the thread count: every point is computed on its own.
#pragma once

#include <cstddef>
#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

// Marks a lane loop for vectorisation (OpenMP SIMD, enabled by -fopenmp-simd without the
// OpenMP runtime).
#define EPC_FAST_SIMD _Pragma("omp simd")
#define EPC_FAST_PRAGMA(x) _Pragma(#x)
#define EPC_FAST_SIMD_REDUCTION(...) EPC_FAST_PRAGMA(omp simd reduction(__VA_ARGS__))

namespace epc_fast {

inline bool openmp_enabled() {
#ifdef _OPENMP
    return true;
#else
    return false;
#endif
}

// The team size used when the caller does not say: OMP_NUM_THREADS when set, else the cores.
inline int default_threads() {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

// The most threads a region of for_each_block has run with on the calling thread (1: none
// yet). The OpenMP runtime keeps a thread's team for its next regions, so a call from that
// thread on no more threads than this starts none (the Python API then skips counting the
// stacks it would map: epc_fast._validation.threads_of).
inline int& largest_team() {
    static thread_local int threads = 1;
    return threads;
}

// Calls block(first, count, state) for consecutive blocks of at most block_size points covering
// [begin, end), on `threads` threads. Each thread default-constructs one State and hands it to
// every block it runs. Dynamic schedule, 16 blocks (1024 points) a grab: blocks differ in cost
// (lanes that stop early, slow lanes, Brent's T_MPE, the inverse solvers' trials), and a static
// split leaves one thread idle at the end of every chunk while the other finishes its half.
// Which thread runs a block never changes its result: the State holds only caches keyed by
// value (kernel.h Workspace). block must not throw. The team is never larger than the number
// of blocks: a small call does not wake idle threads. Block boundaries depend only on begin,
// never on the thread count.
template <class State, class Block>
void for_each_block(std::size_t begin, std::size_t end, std::size_t block_size, int threads,
                    Block&& block) {
    const std::size_t n = end > begin ? end - begin : 0;
    const auto n_blocks = static_cast<std::ptrdiff_t>((n + block_size - 1) / block_size);
    auto run = [&](std::ptrdiff_t k, State& state) {
        const std::size_t first = begin + static_cast<std::size_t>(k) * block_size;
        block(first, end - first < block_size ? end - first : block_size, state);
    };
#ifdef _OPENMP
    const int team = n_blocks < threads ? static_cast<int>(n_blocks > 0 ? n_blocks : 1) : threads;
    int ran = 1;
#pragma omp parallel num_threads(team)
    {
        State state;
#pragma omp master
        ran = omp_get_num_threads();
#pragma omp for schedule(dynamic, 16)
        for (std::ptrdiff_t k = 0; k < n_blocks; ++k) run(k, state);
    }
    if (ran > largest_team()) largest_team() = ran;
#else
    (void)threads;
    State state;
    for (std::ptrdiff_t k = 0; k < n_blocks; ++k) run(k, state);
#endif
}

// A range of bytes of a caller's array (first_touch).
struct Region {
    unsigned char* data;
    std::size_t bytes;
};

// Writes a 0 into every 4 KiB page of `regions` (null ones skipped), on `threads` threads, each
// a contiguous share of all the pages: for arrays just allocated (never touched), which the
// caller is about to overwrite. Their first write faults each page in and the kernel zeroes
// it, which on a transparent huge page is 2 MiB at once while the other thread waits for it if
// it writes there too. The kernel's blocks (for_each_block) run both threads through the
// same pages; their shares of the pages here are apart, so the two threads zero different
// pages at the same time. For 10^7 points' outputs (500 MB) that makes the default call 5-12%
// faster on two cores.
template <std::size_t N>
void first_touch(const Region (&regions)[N], int threads) {
    constexpr std::size_t page = 4096;  // the smallest x86-64 page; finer strides touch twice
    std::size_t offsets[N + 1] = {};    // page k of the whole list is page k - offsets[r] of r
    for (std::size_t r = 0; r < N; ++r) {
        const std::size_t bytes = regions[r].data != nullptr ? regions[r].bytes : 0;
        offsets[r + 1] = offsets[r] + (bytes + page - 1) / page;
    }
    const auto total = static_cast<std::ptrdiff_t>(offsets[N]);
    auto touch = [&](std::ptrdiff_t k) {
        std::size_t r = 0;
        while (static_cast<std::size_t>(k) >= offsets[r + 1]) ++r;
        const std::size_t at = (static_cast<std::size_t>(k) - offsets[r]) * page;
        // the page of byte `at`, and the last byte's page when the region ends within the next
        regions[r].data[at] = 0;
        if (static_cast<std::size_t>(k) + 1 == offsets[r + 1]) regions[r].data[regions[r].bytes - 1] = 0;
    };
#ifdef _OPENMP
    if (threads > 1 && total > 1) {
#pragma omp parallel for schedule(static) num_threads(threads)
        for (std::ptrdiff_t k = 0; k < total; ++k) touch(k);
        return;
    }
#endif
    (void)threads;
    for (std::ptrdiff_t k = 0; k < total; ++k) touch(k);
}

}  // namespace epc_fast
