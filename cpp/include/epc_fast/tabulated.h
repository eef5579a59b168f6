// Tabulated MTFs (docs/model.md, "Tabulated MTFs"; python/epc_fast/mtf_table.py checks and
// builds them): a falling curve interpolated by the monotone piecewise cubic of Fritsch and
// Carlson, each segment k stored as y_k + d_k s + c2_k s^2 + c3_k s^3 in s = f - f_k, so that
// the core evaluates the NumPy reference's polynomial. Past the last frequency it holds its last
// value.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace epc_fast {

struct MtfTable {
    std::vector<double> knots;         // f_0 = 0 < f_1 < ... < f_m
    std::vector<double> coefficients;  // 4 per segment: y_k, d_k, c2_k, c3_k
    double last_value = 0.0;           // the MTF at f_m
    double end = 0.0;   // where f50's bracket ends on it: its first knot of MTF 0, else f_m
    double half = 0.0;  // where it falls to 1/2 (f_m if it never does): f50's start's scale
};

// The interpolant and its first two derivatives in f.
struct TableValue {
    double value, d1, d2;
};

inline TableValue tabulated(const MtfTable& t, double f) {
    const std::size_t m = t.knots.size() - 1;  // segments
    if (f > t.knots[m]) return {t.last_value, 0.0, 0.0};
    const std::size_t upper = static_cast<std::size_t>(
        std::upper_bound(t.knots.begin(), t.knots.end(), f) - t.knots.begin());
    const std::size_t k = upper == 0 ? 0 : (upper - 1 < m ? upper - 1 : m - 1);
    const double* c = &t.coefficients[4 * k];
    const double s = f - t.knots[k];
    return {c[0] + s * (c[1] + s * (c[2] + s * c[3])), c[1] + s * (2.0 * c[2] + 3.0 * c[3] * s),
            2.0 * c[2] + 6.0 * c[3] * s};
}

// `end` and `half` of a table whose knots, coefficients and last value are set. The interpolant
// never rises (the Python side refuses a table that does), so its 1/2 crossing is found by
// bisection to adjacent doubles.
inline void finish_table(MtfTable& t) {
    const std::size_t m = t.knots.size() - 1;
    t.end = t.knots[m];
    for (std::size_t k = 1; k <= m; ++k) {
        const double v = k < m ? t.coefficients[4 * k] : t.last_value;
        if (v == 0.0) {
            t.end = t.knots[k];
            break;
        }
    }
    if (!(tabulated(t, t.end).value < 0.5)) {
        t.half = t.end;
        return;
    }
    double lo = 0.0, hi = t.end;
    for (int step = 0; step < 2200; ++step) {
        const double mid = lo + 0.5 * (hi - lo);
        if (!(mid > lo && mid < hi)) break;
        (tabulated(t, mid).value > 0.5 ? lo : hi) = mid;
    }
    t.half = hi;
}

}  // namespace epc_fast
