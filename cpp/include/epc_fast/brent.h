// Brent's method on a bracket (Brent 1973, "Algorithms for minimization without derivatives",
// ch. 4), written as a state machine so that it can run in lockstep over many lanes whose
// function values come from one batched evaluation (f50's Brent solver, f50/solvers.h; the
// inverse solvers, inverse.h), as well as in a plain loop (brent_root: T_MPE's general path,
// exposure/point.h). f50's bisection works on many points at once and lives in f50/solvers.h.
#pragma once

#include <cmath>
#include <limits>

namespace epc_fast {

// One Brent iteration is: step() proposes the next abscissa (or reports convergence), the
// caller evaluates f there, accept() takes the value. The root estimate is `b`.
// Tolerance on the root: 2 eps |b| + (rtol |b| + atol) / 2.
struct BrentState {
    double a = 0, b = 0, c = 0, fa = 0, fb = 0, fc = 0, d = 0, e = 0;
    double rtol = 0, atol = 0;

    // [a, b] with f(a), f(b) of opposite signs (or one of them zero).
    void start(double a0, double fa0, double b0, double fb0, double rtol_, double atol_) {
        a = a0;
        fa = fa0;
        b = b0;
        fb = fb0;
        c = a;
        fc = fa;
        d = e = b - a;
        rtol = rtol_;
        atol = atol_;
    }

    // True when b is the root to tolerance; otherwise sets `next`, where f is wanted.
    bool step(double& next) {
        constexpr double eps = std::numeric_limits<double>::epsilon();
        if ((fb > 0.0) == (fc > 0.0)) {  // keep the root between b and c
            c = a;
            fc = fa;
            d = e = b - a;
        }
        if (std::fabs(fc) < std::fabs(fb)) {  // b is the best estimate so far
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        const double tol = 2.0 * eps * std::fabs(b) + 0.5 * (rtol * std::fabs(b) + atol);
        const double m = 0.5 * (c - b);
        if (std::fabs(m) <= tol || fb == 0.0) return true;
        if (std::fabs(e) >= tol && std::fabs(fa) > std::fabs(fb)) {
            // Interpolate: secant when a == c, inverse quadratic otherwise.
            double p, q;
            const double s = fb / fa;
            if (a == c) {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                const double qa = fa / fc, r = fb / fc;
                p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if (p > 0.0) q = -q; else p = -p;
            if (2.0 * p < std::fmin(3.0 * m * q - std::fabs(tol * q), std::fabs(e * q))) {
                e = d;
                d = p / q;
            } else {  // interpolation rejected: bisect
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += std::fabs(d) > tol ? d : (m > 0.0 ? tol : -tol);
        next = b;
        return false;
    }

    void accept(double f_next) { fb = f_next; }
};

// A root of f in [a, b] by Brent's method to 2 eps |x| + (rtol |x| + atol) / 2. When f(a) and
// f(b) do not differ in sign (the ends are within rounding of the root) the end with the
// smaller |f| is returned.
template <class F>
double brent_root(F f, double a, double b, double rtol, double atol = 0.0, int max_iter = 200) {
    const double fa = f(a), fb = f(b);
    if (fa == 0.0) return a;
    if (fb == 0.0) return b;
    if ((fa > 0.0) == (fb > 0.0)) return std::fabs(fa) < std::fabs(fb) ? a : b;
    BrentState state;
    state.start(a, fa, b, fb, rtol, atol);
    double next;
    for (int iter = 0; iter < max_iter && !state.step(next); ++iter) state.accept(f(next));
    return state.b;
}

}  // namespace epc_fast
