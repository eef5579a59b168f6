// The kernel's f50 stage (kernel.h): every lane's bracket and start (start.h), the lanes whose
// lens table ends above the threshold set aside (Status::beyond_table), then the solver the
// call asks for (solvers.h), over one instantiation per combination of the terms the block
// uses.
#pragma once

#include <cstddef>
#include <type_traits>

#include "../block.h"
#include "../params.h"
#include "../status.h"
#include "solvers.h"
#include "start.h"
#include "system_mtf.h"

namespace epc_fast {

// float32 mode: the smallest relative tolerance f50 is solved to (4 float32 ulps).
constexpr double f50_rtol_floor_float32 = 4.76837158203125e-07;  // 2^-21

namespace detail {

// The tolerance f50 is solved to in T: float32 cannot resolve a relative tolerance much below its
// epsilon (1.2e-7), so there it is at least f50_rtol_floor_float32.
template <class T>
T effective_rtol(double rtol) {
    if (sizeof(T) == sizeof(double)) return static_cast<T>(rtol);
    return static_cast<T>(rtol > f50_rtol_floor_float32 ? rtol : f50_rtol_floor_float32);
}

template <bool Motion, bool Jitter, bool Binning, bool Poly, class T>
void solve_f50(const Spectrum& spectrum, const Options& opt, Block<T>& b) {
    const T rtol = effective_rtol<T>(opt.f50_rtol);
    switch (opt.f50_solver) {
        case F50Solver::halley: polish<Motion, Jitter, Binning, Poly, true>(spectrum, rtol, b); break;
        case F50Solver::newton: polish<Motion, Jitter, Binning, Poly, false>(spectrum, rtol, b); break;
        case F50Solver::brent: brent<Motion, Jitter, Binning, Poly>(spectrum, rtol, b); break;
        case F50Solver::bisection: bisect<Motion, Jitter, Binning, Poly>(spectrum, rtol, b); break;
    }
}

// The tolerance within which a certified start is taken as f50 (start_f50): Halley's and
// Newton's effective f50_rtol; -1 (never) for Brent and bisection, which take no start.
template <class T>
double settle_rtol(const Options& opt) {
    const bool steps = opt.f50_solver == F50Solver::halley || opt.f50_solver == F50Solver::newton;
    return steps ? static_cast<double>(effective_rtol<T>(opt.f50_rtol)) : -1.0;
}

// A lens table that ends while the system MTF is still above the threshold holds no f50: the
// lanes to solve whose MTF at their bracket's end f_hi (the table's end where that is the
// nearest) exceeds c get Status::beyond_table and are not solved (scatter writes NaN).
//
// Without jitter, every bracket ends on a zero of a factor (the pixel aperture's, the motion's,
// the binned array's: an MTF of a rounding's size there) or on the table's end, where the
// MTF is at most the table's near_end times the demosaicker's largest value (its value at 0)
// and factors of at most 1: a block whose lanes to solve all have a threshold above that
// bound (and above 1e-3, far above a rounding at a zero) holds no lane beyond its table, and
// the MTF at the brackets' ends is not evaluated.
template <class T>
bool within_tables(const Block<T>& b) {
    double near_end = 0.0;
    if (const MtfTable* one = lens_block_table(b)) {
        near_end = one->near_end;
    } else {
        for (const MtfTable& t : *b.lens_tables) near_end = near_end > t.near_end ? near_end : t.near_end;
    }
    const double demosaic = b.demosaic_table != nullptr ? b.demosaic_table->coefficients[0] : 1.0;
    const double bound = near_end * (demosaic > 1.0 ? demosaic : 1.0) * (1.0 + 1e-6);
    const T least = static_cast<T>(bound > 1e-3 ? bound : 1e-3);
    int below = 0;
    EPC_FAST_SIMD_REDUCTION(+ : below)
    for (std::size_t i = 0; i < block_size; ++i) below += (b.solve[i] != 0) & !(b.threshold[i] >= least);
    return below == 0;
}

template <bool Motion, bool Jitter, bool Binning, class T>
void beyond_tables(const Spectrum& spectrum, Block<T>& b) {
    if (!Jitter && within_tables(b)) return;
    T* __restrict at = b.at;
    T* __restrict start = b.previous_step;  // free until the solver sets it
    for (std::size_t i = 0; i < block_size; ++i) {
        start[i] = at[i];
        at[i] = b.hi[i];
    }
    system_mtf<Motion, Jitter, Binning, false>(spectrum, b);
    for (std::size_t i = 0; i < block_size; ++i) {
        const bool beyond = (b.solve[i] != 0) & (b.mtf[i] > b.threshold[i]);
        b.status[i] = beyond ? static_cast<unsigned char>(Status::beyond_table) : b.status[i];
        b.solve[i] = beyond ? 0 : b.solve[i];
        at[i] = start[i];
    }
}

// f50 for every lane to solve, into b.f50.
template <class T>
void f50(const Spectrum& spectrum, const Options& opt, Block<T>& b) {
    const int terms = start_f50(spectrum, settle_rtol<T>(opt), b);
    // One instantiation per combination of the terms a block uses.
    auto with = [&](auto motion, auto jitter, auto binning) {
        constexpr bool M = decltype(motion)::value, J = decltype(jitter)::value,
                       B = decltype(binning)::value;
        if (b.lens_tables != nullptr) beyond_tables<M, J, B>(spectrum, b);
        if (spectrum.polychromatic()) solve_f50<M, J, B, true>(spectrum, opt, b);
        else solve_f50<M, J, B, false>(spectrum, opt, b);
    };
    using yes = std::true_type;
    using no = std::false_type;
    auto with_binning = [&](auto motion, auto jitter) {
        if (terms & 4) with(motion, jitter, yes{});
        else with(motion, jitter, no{});
    };
    const bool motion = terms & 1, jitter = terms & 2;
    if (motion && jitter) with_binning(yes{}, yes{});
    else if (motion) with_binning(yes{}, no{});
    else if (jitter) with_binning(no{}, yes{});
    else with_binning(no{}, no{});
}

}  // namespace detail
}  // namespace epc_fast
