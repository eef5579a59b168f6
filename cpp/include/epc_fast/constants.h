#pragma once

// Lane-loop helpers must be inlined: a call left in a lane loop stops its vectorisation.
#if defined(__GNUC__)
#define EPC_FAST_INLINE inline __attribute__((always_inline))
// The same for a lambda (after its parameter list): one outlined keeps its lane loops' arrays
// behind captured references, which the vectoriser must assume may alias.
#define EPC_FAST_LAMBDA_INLINE __attribute__((always_inline))
// A block's pass that most calls skip, kept out of line so that it leaves the code around it as
// it is without it.
#define EPC_FAST_OUTLINED inline __attribute__((noinline))
#else
#define EPC_FAST_INLINE inline
#define EPC_FAST_LAMBDA_INLINE
#define EPC_FAST_OUTLINED inline
#endif

// Set where the target has a hardware fused multiply-add: the x86-64-v3 and -v4 modules, which
// are also compiled with -ffp-contract=fast (CMakeLists.txt). The code that needs a product's
// exact rounding error, or must not have one product fused and its twin not, spells the fused
// operation out with std::fma under this macro; everywhere else the compiler may fuse freely.
#if defined(__FMA__)
#define EPC_FAST_FMA 1
#else
#define EPC_FAST_FMA 0
#endif

namespace epc_fast {

constexpr double pi = 3.141592653589793238462643383279502884;
constexpr double half_pi = pi / 2;
constexpr double deg_to_rad = pi / 180;
constexpr double um_to_mm = 1e-3;
constexpr double um_to_m = 1e-6;
constexpr double nm_to_mm = 1e-6;

}  // namespace epc_fast
