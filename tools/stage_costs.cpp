// Where the kernel's time goes, stage by stage (kernel.h, exposure/stage.h, f50/stage.h): one
// thread runs the blocks of `points` random phone designs (phone_designs.h) through the stages
// cumulatively (gather; then the exposure; then f50's start and bracket; then its solve; then
// the scatter into the outputs, which is evaluate_block) and prints each stage's share, from
// the best of `rounds` passes of each (taken in turn). The stages run in their real order on
// real data, so each one's cost is that of its place in the kernel. 8192 points stay in the
// caches.
//
//   g++ -std=c++17 -O3 -march=x86-64-v4 -mprefer-vector-width=512 -ffp-contract=fast
//       -fno-math-errno -fno-trapping-math -fopenmp -I cpp/include tools/stage_costs.cpp
//       -o /tmp/stage_costs      (one command, from the repository's root)
//   /tmp/stage_costs [points=8192] [rounds=200] [float64|float32]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "epc_fast/kernel.h"
#include "phone_designs.h"

using namespace epc_fast;

namespace {

// Seconds for one pass of the first `stages` stages over all n points.
template <class T>
double pass_s(const Inputs& in, const Options& opt, const Outputs& out, std::size_t n,
              int stages, detail::Block<T>& block) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t first = 0; first < n; first += block_size) {
        block.n = std::min(block_size, n - first);
        detail::gather(in, first, nullptr, block);
        if (stages >= 2) detail::exposure(opt, block, out.exposure_values_read());
        if (stages == 3) detail::start_f50(in.spectrum, detail::settle_rtol<T>(opt), block);
        if (stages >= 4) detail::f50(in.spectrum, opt, block);
        if (stages >= 5) detail::scatter(in, block, out.at(first));
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The best ns a point of each cumulative pass (1..5 stages), the passes taken in turn in
// every round so that a drift in the machine's speed falls on all of them alike.
template <class T>
void best_ns_per_point(const Inputs& in, const Options& opt, const Outputs& out, std::size_t n,
                       int rounds, double (&best)[6]) {
    auto block = std::make_unique<detail::Block<T>>();
    for (int s = 1; s <= 5; ++s) best[s] = 1e300;
    for (int r = 0; r < rounds; ++r)
        for (int s = 1; s <= 5; ++s) best[s] = std::min(best[s], pass_s(in, opt, out, n, s, *block));
    for (int s = 1; s <= 5; ++s) best[s] *= 1e9 / static_cast<double>(n);
}

}  // namespace

int main(int argc, char** argv) {
    const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 8192;
    const int rounds = argc > 2 ? std::atoi(argv[2]) : 200;
    const bool float32 = argc > 3 && std::string(argv[3]) == "float32";
    if (n == 0 || rounds <= 0) {
        std::fprintf(stderr, "usage: stage_costs [points] [rounds] [float64|float32]\n");
        return 2;
    }
    const tools::PhoneDesigns designs(n, 0.0);
    const Inputs in = designs.inputs();
    Options opt;
    opt.precision = float32 ? Precision::float32 : Precision::float64;
    tools::OutputArrays arrays(n);
    const Outputs out = arrays.outputs();
    const char* names[] = {"gather", "exposure", "f50 start", "f50 solve", "scatter"};
    double cumulative[6] = {0.0};
    if (float32) best_ns_per_point<float>(in, opt, out, n, rounds, cumulative);
    else best_ns_per_point<double>(in, opt, out, n, rounds, cumulative);
    std::printf("%zu points, %s, 1 thread: %.2f ns a point in all (%.1f M points/s)\n", n,
                float32 ? "float32" : "float64", cumulative[5], 1e3 / cumulative[5]);
    for (int s = 1; s <= 5; ++s) {
        const double own = cumulative[s] - cumulative[s - 1];
        std::printf("  %-10s %6.2f ns  %5.1f%%\n", names[s - 1], own, 100.0 * own / cumulative[5]);
    }
    return 0;
}
