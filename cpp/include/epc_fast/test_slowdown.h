// A deliberate slowdown for testing benchmark comparisons (epc-fast bench compare), compiled in
// only by the CMake option EPC_FAST_TEST_SLOWDOWN=ON; a normal build defines nothing here and
// TestSlowdown is an empty object the compiler removes.
//
// With the option, every block of points the kernel evaluates (evaluate_block) spins, after its
// work, for EPC_FAST_TEST_SLOWDOWN_PERCENT (default 10) percent of the wall time the block took:
// every caller of the kernel (evaluate, the inverse solvers, scans) runs that much slower on any
// instruction-set level and thread count, while its results stay bit-identical.
#pragma once

#ifdef EPC_FAST_TEST_SLOWDOWN
#include <chrono>
#ifndef EPC_FAST_TEST_SLOWDOWN_PERCENT
#define EPC_FAST_TEST_SLOWDOWN_PERCENT 10
#endif
#endif

namespace epc_fast {

#ifdef EPC_FAST_TEST_SLOWDOWN
// Times its own lifetime and, when destroyed, spins for the given percentage of it.
class TestSlowdown {
public:
    TestSlowdown() noexcept : start_(std::chrono::steady_clock::now()) {}
    TestSlowdown(const TestSlowdown&) = delete;
    TestSlowdown& operator=(const TestSlowdown&) = delete;
    ~TestSlowdown() {
        const auto now = std::chrono::steady_clock::now();
        const auto until = now + (now - start_) * EPC_FAST_TEST_SLOWDOWN_PERCENT / 100;
        while (std::chrono::steady_clock::now() < until) {
        }
    }

private:
    std::chrono::steady_clock::time_point start_;
};
inline constexpr bool test_slowdown_built = true;
#else
struct TestSlowdown {};
inline constexpr bool test_slowdown_built = false;
#endif

}  // namespace epc_fast
