// f50's solvers (docs/model.md, "The cut-off frequency f50") for every lane of a block: the
// first frequency where the system MTF falls to the threshold c, found inside the bracket
// [0, f_hi] on which MTF_sys decreases strictly from 1 to <= c.
//
// Four solvers, all safe by construction: every iterate lies strictly inside the lane's current
// bracket, and the bracket shrinks around the root with every evaluation.
// - halley (default): Halley's method on h(f) = MTF_sys(f) - c with analytic slopes and
//   curvatures of every factor (system_mtf.h), from a starting guess (start.h; in the common
//   scene accurate enough that one step converges). A step that would leave the bracket is
//   replaced by a bisection step. Cubic
//   convergence: it stops once the last step was below rtol^(1/2) relative, when the error left
//   is of order (step)^3 (far below rtol); or when the bracket is narrower than rtol.
// - newton: the same with Newton steps (quadratic: stops once the step is below rtol / 8 ...
//   precisely: once step^2 <= rtol / 16 relative, or the bracket is narrower than rtol).
//   A lane whose start is fitted to a table (a lens's, f50/lens_fit.h, or a demosaicker's,
//   f50/demosaic_fit.h) takes at least two steps unless its first is below 1e-7 relative.
//   Halley and Newton take no step at all where the start is certified within rtol
//   (guesses.h, certified_start_error: MTF50 without jitter from rtol 1e-7, and float32's
//   floor of 2^-21): that start is f50 to the tolerance asked.
// - brent: Brent's method (brent.h) per lane, on the bracket, to rtol.
// - bisection: halves the bracket until hi - lo <= rtol lo (or adjacent doubles).
//
// Every lane advances in lockstep with the others but stops on its own criterion, so a point's
// result never depends on its neighbours, the block size or the thread count.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "../block.h"
#include "../brent.h"
#include "../parallel.h"
#include "../params.h"
#include "system_mtf.h"

namespace epc_fast {

// Enough halvings to take any finite bracket down to adjacent doubles.
constexpr int max_bisection_steps = 2200;
// After this many derivative steps a lane that has not converged takes bisection steps only.
constexpr int max_derivative_steps = 64;
// The largest first step (relative) on which a lane started from a table's fitted start stops
// (polish, step_again).
constexpr double tabulated_first_step = 1e-7;

namespace detail {

// Bisection: lo, hi hold the bracket; the answer is written to b.f50.
template <bool Motion, bool Jitter, bool Binning, bool Poly, class T>
void bisect(const Spectrum& spectrum, T rtol, Block<T>& b) {
    constexpr std::size_t n = block_size;
    const LaneFlag<T>* __restrict solve = b.solve;
    T* __restrict lo = b.lo;
    T* __restrict hi = b.hi;
    T* __restrict mid = b.at;
    LaneFlag<T>* __restrict active = b.active;
    const T* __restrict mtf = b.mtf;
    const T* __restrict threshold = b.threshold;
    for (int step = 0; step < max_bisection_steps; ++step) {
        int n_active = 0;
        EPC_FAST_SIMD_REDUCTION(+ : n_active)
        for (std::size_t i = 0; i < n; ++i) {
            const T m = lo[i] + T(0.5) * (hi[i] - lo[i]);
            mid[i] = m;
            const bool a = (solve[i] != 0) & (hi[i] - lo[i] > rtol * lo[i]) & (m > lo[i]) &
                           (m < hi[i]);
            active[i] = a;
            n_active += a;
        }
        if (n_active == 0) break;
        system_mtf<Motion, Jitter, Binning, Poly>(spectrum, b);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const bool above = mtf[i] > threshold[i];
            const bool act = active[i] != 0;
            lo[i] = (act & above) ? mid[i] : lo[i];
            hi[i] = (act & !above) ? mid[i] : hi[i];
        }
    }
    for (std::size_t i = 0; i < n; ++i) b.f50[i] = lo[i] + T(0.5) * (hi[i] - lo[i]);
}

// After polish's first round: a lane that may not stop on its first step (b.step_twice: a start
// fitted to a table, whose cubics join with jumps in their curvature) and did, by a step above
// tabulated_first_step relative, goes on as if it had not: its step, bracket and abscissa are
// already those of a lane that goes on; its f50 is written again when it stops. (A smaller
// first step leaves an error of order step^3, 1e-21, even where the curvature jumps a hundred
// thousand times over.) Returns the lanes that go on again.
template <class T>
EPC_FAST_OUTLINED int step_again(Block<T>& b) {
    int n_again = 0;
    const LaneFlag<T>* __restrict twice = b.step_twice;
    const LaneFlag<T>* __restrict solve = b.solve;
    const T* __restrict previous = b.previous_step;
    const T* __restrict at = b.at;
    LaneFlag<T>* __restrict active = b.active;
    for (std::size_t i = 0; i < block_size; ++i) {
        const bool again = (twice[i] != 0) & (solve[i] != 0) & (active[i] == 0) &
                           (previous[i] > T(tabulated_first_step) * at[i]);
        active[i] = again ? LaneFlag<T>(1) : active[i];
        n_again += again;
    }
    return n_again;
}

// Newton (Halley = false) or Halley steps from b.at, safeguarded by the bracket [lo, hi].
template <bool Motion, bool Jitter, bool Binning, bool Poly, bool Halley, class T>
void polish(const Spectrum& spectrum, T rtol, Block<T>& b) {
    constexpr std::size_t n = block_size;
    // Convergence test, on the last step d and the one before, p. In the cubic (Halley) or
    // quadratic (Newton) regime d ~ K p^3 (K p^2) and the error left after d is about K d^3
    // (K d^2): far below d (d/p)^2 = d^3 / p^2, the estimate used. A slow, linear approach (a
    // root where the MTF is flat, near a factor's zero) shrinks its steps by a constant ratio
    // r and leaves an error d r / (1 - r), within a few times d r^2 for r <= 1/2. A lane stops
    // when d^3 / p^2 <= rtol / 10 and d <= (rtol/10)^(1/3) (Halley) or ^(1/2) (Newton), all
    // relative to f. The first step is measured against the bracket's width.
    if (!(b.memo_rtol == rtol && b.memo_halley == Halley)) {  // once per call, not per block
        b.memo_step_rtol = Halley ? std::cbrt(T(0.1) * rtol) : std::sqrt(T(0.1) * rtol);
        b.memo_rtol = rtol;
        b.memo_halley = Halley;
    }
    const T step_rtol = b.memo_step_rtol;
    constexpr T epsilon = std::numeric_limits<T>::epsilon();
    const T steep_bound = epsilon / (rtol > T(16) * epsilon ? rtol : T(16) * epsilon);
    T* __restrict lo = b.lo;
    T* __restrict hi = b.hi;
    T* __restrict at = b.at;
    T* __restrict f50 = b.f50;
    T* __restrict previous = b.previous_step;
    LaneFlag<T>* __restrict active = b.active;
    const T* __restrict mtf = b.mtf;
    const T* __restrict slope = b.slope;
    const T* __restrict curvature = b.curvature;
    const T* __restrict threshold = b.threshold;
    int n_to_solve = 0;
    if (b.n_settled > 0) {  // settled lanes (settle.h): their start is f50, no step
        const LaneFlag<T>* __restrict settled = b.settled;
        EPC_FAST_SIMD_REDUCTION(+ : n_to_solve)
        for (std::size_t i = 0; i < n; ++i) {
            const bool s_i = settled[i] != 0;
            active[i] = (b.solve[i] != 0) & !s_i;
            f50[i] = s_i ? at[i] : f50[i];
            n_to_solve += active[i];
        }
        if (n_to_solve == 0) return;  // (float32 may then have left the bracket unset)
    } else {
        for (std::size_t i = 0; i < n; ++i) active[i] = b.solve[i];
    }
    for (std::size_t i = 0; i < n; ++i) previous[i] = hi[i] - lo[i];
    // One round: a step for every active lane. The first round, First, needs no division for
    // its stop test: d <= step_rtol x there implies d^3 / p^2 <= step_rtol^3 x (Halley's
    // rtol / 10; Newton's is smaller still), as the first step is measured against the whole
    // bracket [0, f_hi], wider than x (start.h). Returns the lanes still active.
    auto take_steps = [&](auto first, bool derivative) EPC_FAST_LAMBDA_INLINE {
        constexpr bool First = decltype(first)::value;
        int n_active = 0;
        EPC_FAST_SIMD_REDUCTION(+ : n_active)
        for (std::size_t i = 0; i < n; ++i) {
            const T x = at[i], m = mtf[i], r = slope[i];
            const T h = m - threshold[i];
            const bool act = active[i] != 0;
            const bool above = h > T(0);
            const T l = (act & above) ? x : lo[i];
            const T u = (act & !above) ? x : hi[i];
            lo[i] = l;
            hi[i] = u;
            // Newton: -h / (M R). Halley: -2 h h' / (2 h'^2 - h h'') with h' = M R and
            // h'' = M (R^2 + S), i.e. -2 h R / (2 M R^2 - h (R^2 + S)).
            const T denominator = Halley ? T(2) * m * (r * r) - h * (r * r + curvature[i]) : m * r;
            const T d = (Halley ? T(-2) * h * r : -h) / denominator;
            // A step is usable only from a finite denominator. Below f ~ 1e-154 cycles/mm
            // (lengths beyond ~1e154 mm, such as a wavelength of 1e160 nm) R^2 or a squared
            // length in S overflows, and an infinite denominator gives d = 0, which would pass
            // for convergence: the lane takes a bisection step instead.
            const bool usable = derivative & (std::fabs(denominator) <= std::numeric_limits<T>::max());
            const T next = x + d;
            const T mid = l + T(0.5) * (u - l);
            const bool inside = usable & (next > l) & (next < u);  // false for NaN
            const T to = inside ? next : mid;
            // A converged step ends it wherever it lands: the root is within it of x, and
            // clamped to the bracket it can only come closer.
            const T ad = std::fabs(d), ap = previous[i];
            const T ratio = First ? T(0) : ad / ap;
            const T left = ad * (ratio * ratio);
            // An MTF exactly at the threshold (h = 0) puts x on the root or past it (hi = x
            // above): f50 is the first frequency where MTF <= c. x is that frequency, to rtol
            // (to 16 ulp for a tighter rtol, 0 included), where the MTF is steep enough that it
            // rounds to c only that close to its root: where c's rounding unit (at most
            // epsilon, c <= 1) is below rtol x |M'|, M' = M R, i.e. x |M R| >= steep_bound
            // (a usable step's R: finite). Elsewhere the MTF may round to c over a whole
            // stretch (a spectrum whose longest wavelength reaches its cut-off while the
            // others' D is still 1 to the last bit, the rest of the weight exactly c), and x
            // may lie far past its first point: the lane goes on bisecting towards it.
            const bool at_root = (h == T(0)) & usable & (x * std::fabs(m * r) >= steep_bound);
            const bool small = usable & (h != T(0)) & (ad <= step_rtol * x) & (First | (left <= T(0.1) * rtol * x));  // false for NaN
            previous[i] = act ? std::fabs(to - x) : ap;
            const bool converged = small | at_root | (u - l <= rtol * l) | !(mid > l) | !(mid < u);
            const T clamped = next < l ? l : (next > u ? u : next);
            const bool finish = act & converged;
            f50[i] = finish ? (at_root ? x : small ? clamped : to) : f50[i];
            at[i] = act ? to : x;
            const bool still = act & !converged;
            active[i] = still;
            n_active += still;
        }
        return n_active;
    };
    for (int step = 0; step < max_bisection_steps; ++step) {
        system_mtf_slopes<Motion, Jitter, Binning, Poly, Halley>(spectrum, b);
        // (the first round: lanes that may not stop on their first step go on, step_again)
        const int n_active =
            step == 0 ? take_steps(std::true_type{}, true) + (b.step_twice_any ? step_again(b) : 0)
                      : take_steps(std::false_type{}, step < max_derivative_steps);
        if (n_active == 0) break;
    }
}

// h = MTF - c as Brent sees it: an MTF exactly at the threshold counts as past the root (the
// least negative double), as it does for bisection and Halley, so that Brent brackets the first
// frequency where the MTF is at or below c instead of stopping on any point where h = 0 (on a
// stretch where the MTF rounds to c, that point may lie far past the first).
inline double past_root_below(double h) {
    return h == 0.0 ? -std::numeric_limits<double>::denorm_min() : h;
}

// Brent's method per lane, in lockstep: each round proposes an abscissa per active lane, the
// MTF is evaluated for all lanes at once, and each lane takes its value.
template <bool Motion, bool Jitter, bool Binning, bool Poly, class T>
void brent(const Spectrum& spectrum, T rtol, Block<T>& b) {
    constexpr std::size_t n = block_size;
    BrentState state[n];
    for (std::size_t i = 0; i < n; ++i) b.at[i] = b.hi[i];
    system_mtf<Motion, Jitter, Binning, Poly>(spectrum, b);
    for (std::size_t i = 0; i < n; ++i) {
        const double c = b.threshold[i];
        const double f_hi = past_root_below(double{b.mtf[i]} - c);
        b.active[i] = b.solve[i] && f_hi < 0.0;
        b.f50[i] = b.hi[i];  // MTF(f_hi) > c only by a rounding: f_hi is the root
        if (b.active[i]) state[i].start(b.lo[i], 1.0 - c, b.hi[i], f_hi, rtol, 0.0);
    }
    for (int step = 0; step < max_bisection_steps; ++step) {
        int n_active = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!b.active[i]) continue;
            double next = 0.0;
            if (state[i].step(next)) {
                b.active[i] = 0;
                b.f50[i] = static_cast<T>(state[i].b);
            } else {
                b.at[i] = static_cast<T>(next);
                ++n_active;
            }
        }
        if (n_active == 0) break;
        system_mtf<Motion, Jitter, Binning, Poly>(spectrum, b);
        for (std::size_t i = 0; i < n; ++i)
            if (b.active[i]) state[i].accept(past_root_below(double{b.mtf[i]} - double{b.threshold[i]}));
    }
}

}  // namespace detail
}  // namespace epc_fast
