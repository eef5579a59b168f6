// The kernel's speed without Python: evaluate() on random phone designs (phone_designs.h, those
// of epc_fast.selfcheck.random_designs), outputs preallocated (one thread unless asked for
// more); prints the best points/s of `rounds` calls. For profiling the kernel (perf record) and comparing two
// versions of a header back to back on the same machine; bench/ measures the package.
//
//   g++ -std=c++17 -O3 -march=x86-64-v4 -mprefer-vector-width=512 -ffp-contract=fast
//       -fno-math-errno -fno-trapping-math -fopenmp -I cpp/include tools/kernel_speed.cpp
//       -o /tmp/kernel_speed      (one command, from the repository's root)
//   /tmp/kernel_speed [points=1000000] [rounds=5] [halley|newton|brent|bisection] [float32|float64]
//                     [threads=1] [jitter_um=0] [wavelengths=0] [all|f50_epc]
//
// wavelengths > 0: a spectrum of that many equally weighted wavelengths over 480..580 nm (the
// default QE's band), with its fitted f50 start (f50/spectrum_fit.h); < 0: the same spectrum
// without it (the cubic start), for comparison.
//
// f50_epc: only f50 and EPC written (the others null: not computed), as `outputs=("f50_cyc_per_mm",
// "epc")` asks; all (the default): every output.
//
// 8192 points stay in the caches (the kernel alone); 10^6 and more stream from memory.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "epc_fast/f50/spectrum_fit.h"
#include "epc_fast/kernel.h"
#include "phone_designs.h"

using namespace epc_fast;

int main(int argc, char** argv) {
    const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 1000000;
    const int rounds = argc > 2 ? std::atoi(argv[2]) : 5;
    const std::string solver = argc > 3 ? argv[3] : "halley";
    const bool float32 = argc > 4 && std::string(argv[4]) == "float32";
    const int threads = argc > 5 ? std::atoi(argv[5]) : 1;
    double jitter = argc > 6 ? std::atof(argv[6]) : 0.0;  // um, every point
    const int wavelengths = argc > 7 ? std::atoi(argv[7]) : 0;
    const bool f50_epc_only = argc > 8 && std::string(argv[8]) == "f50_epc";
    if (n == 0 || rounds <= 0 || threads <= 0 || !(jitter >= 0.0)) {
        std::fprintf(stderr, "usage: kernel_speed [points] [rounds] [solver] [float32|float64] [threads] [jitter_um] [wavelengths] [all|f50_epc]\n");
        return 2;
    }
    const tools::PhoneDesigns designs(n, jitter);
    Inputs in = designs.inputs();
    for (int k = 0, count = std::abs(wavelengths); k < count; ++k) {
        in.spectrum.wavelengths_nm.push_back(count == 1 ? 530.0 : 480.0 + 100.0 * k / (count - 1));
        in.spectrum.weights.push_back(1.0 / count);
    }
    if (wavelengths > 0) in.spectrum.start = spectrum_start_of(in.spectrum);
    Options opt;
    opt.precision = float32 ? Precision::float32 : Precision::float64;
    opt.f50_solver = solver == "bisection" ? F50Solver::bisection
                     : solver == "newton"  ? F50Solver::newton
                     : solver == "brent"   ? F50Solver::brent
                                           : F50Solver::halley;
    tools::OutputArrays arrays(n);
    Outputs out = arrays.outputs();
    if (f50_epc_only) {
        out.electron_rate_e_per_s = out.electrons = out.t_mpe_s = out.blur_mm = nullptr;
        out.status = out.cause = nullptr;
        out = streaming_for(out, n);  // streamed or not by these two outputs' bytes, as a call decides
    }
    double best = 0.0, total_s = 0.0;
    for (int r = 0; r < rounds; ++r) {
        const auto start = std::chrono::steady_clock::now();
        evaluate(in, opt, out, 0, n, threads);
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        best = std::max(best, static_cast<double>(n) / s);
        total_s += s;
    }
    if (wavelengths != 0)
        std::printf("%d wavelengths, %s start; ", std::abs(wavelengths), wavelengths > 0 ? "fitted" : "cubic");
    std::printf("%zu points, %s, %s, %d thread(s): best %.2f M points/s, mean %.2f (f50[0] = %.17g)\n",
                n, solver.c_str(), float32 ? "float32" : "float64", threads, best / 1e6,
                static_cast<double>(n) * rounds / total_s / 1e6, arrays.values[4][0]);
    return 0;
}
