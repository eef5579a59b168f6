// Scalar root finding: Brent's method on a bracket (used for T_MPE's general path).
// f50's bisection works on many points at once and lives in kernel.h.
#pragma once

#include <cmath>
#include <limits>
#include <utility>

namespace epc_fast {

// A root of f in [a, b] by Brent's method (Brent 1973, "Algorithms for minimization without
// derivatives", ch. 4), to |error| <= 2 eps |x| + rtol |x| / 2. When f(a) and f(b) do not differ
// in sign (the ends are within rounding of the root) the end with the smaller |f| is returned.
template <class F>
double brent_root(F f, double a, double b, double rtol, int max_iter = 200) {
    constexpr double eps = std::numeric_limits<double>::epsilon();
    double fa = f(a), fb = f(b);
    if (fa == 0.0) return a;
    if (fb == 0.0) return b;
    if ((fa > 0.0) == (fb > 0.0)) return std::fabs(fa) < std::fabs(fb) ? a : b;
    double c = a, fc = fa, d = b - a, e = d;
    for (int iter = 0; iter < max_iter; ++iter) {
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
        const double tol = 2.0 * eps * std::fabs(b) + 0.5 * rtol * std::fabs(b);
        const double m = 0.5 * (c - b);
        if (std::fabs(m) <= tol || fb == 0.0) return b;
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
        fb = f(b);
    }
    return b;
}

}  // namespace epc_fast
