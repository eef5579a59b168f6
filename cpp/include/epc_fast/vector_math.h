// Lets the compiler vectorise the lane loops' sin, acos and exp with glibc's vector maths
// library (libmvec). glibc declares those vector variants only under -ffast-math, which would
// also drop IEEE NaN and infinity semantics; declaring them here keeps strict semantics.
// libmvec's functions are accurate to 4 ulp (glibc manual, "Errors in Math Functions").
// Elsewhere (other compilers, other C libraries) this header declares nothing and the loops
// stay scalar with the same results up to those ulps.
#pragma once

#include <cmath>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    defined(EPC_FAST_LIBMVEC)
extern "C" {
__attribute__((simd("notinbranch"))) double sin(double) noexcept;
__attribute__((simd("notinbranch"))) double acos(double) noexcept;
__attribute__((simd("notinbranch"))) double exp(double) noexcept;
}
#define EPC_FAST_SIMD _Pragma("omp simd")
#else
#define EPC_FAST_SIMD
#endif
