// Linear least squares by Householder QR: the coefficients x minimising |A x - b|_2 for a tall
// matrix A (rows >= columns, full column rank). Plain loops in a fixed order, every
// multiply-add spelled out (multiply_add): the same inputs give the same bits on every run and
// in the x86-64-v3 and -v4 modules alike (left to the compiler, a sum of products is fused in
// the scalar loop and not where the vectoriser splits it, and the two modules split different
// loops). For the run-time fits (spectrum_fit.h), small problems (hundreds of rows, tens of
// columns), solved once per distinct input.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "../constants.h"

namespace epc_fast {

// a b + c, rounded once where the module has a fused multiply-add (EPC_FAST_FMA), else twice
// (those modules fuse nothing): the same in every loop, vectorised or not.
inline double multiply_add(double a, double b, double c) {
#if EPC_FAST_FMA
    return std::fma(a, b, c);
#else
    return a * b + c;
#endif
}

// a: rows x columns, row-major; b: rows. Both are overwritten (QR's factors, Q^T b). Throws
// std::invalid_argument if A is not tall or is numerically rank-deficient (a zero pivot).
inline std::vector<double> least_squares(std::vector<double>& a, std::vector<double>& b,
                                         std::size_t rows, std::size_t columns) {
    if (rows < columns || a.size() != rows * columns || b.size() != rows)
        throw std::invalid_argument("least_squares: A must be rows x columns with rows >= columns");
    auto at = [&](std::size_t i, std::size_t j) -> double& { return a[i * columns + j]; };
    std::vector<double> diagonal(columns), dots(columns);
    for (std::size_t k = 0; k < columns; ++k) {
        // the reflection H = I - v v^T / (v_k |x|) taking column k's rows k.. to (alpha, 0, ...)
        double scale = 0.0;
        // the largest |a_ik|, skipping NaN as fmax does (a select, not a call to fmax)
        for (std::size_t i = k; i < rows; ++i) {
            const double m = std::fabs(at(i, k));
            scale = m > scale ? m : scale;
        }
        if (!(scale > 0.0)) throw std::invalid_argument("least_squares: rank-deficient matrix");
        double norm2 = 0.0;
        for (std::size_t i = k; i < rows; ++i) {
            const double y = at(i, k) / scale;
            norm2 = multiply_add(y, y, norm2);
        }
        const double norm = scale * std::sqrt(norm2);
        const double alpha = at(k, k) > 0.0 ? -norm : norm;  // no cancellation in v_k
        at(k, k) -= alpha;                                   // v = x - alpha e_k
        const double beta = -alpha * at(k, k);  // v^T v / 2 = |x| (|x_k| + |x|)
        // > 0 for finite columns; false where a NaN (which the scale skips above) reached the norm
        if (!(beta > 0.0)) throw std::invalid_argument("least_squares: rank-deficient matrix");
        // H applied to columns k+1..: each column's dot product with v, summed over the rows in
        // order, then its update. Row by row across the columns (A is row-major), so that the
        // inner loops run over contiguous, independent columns and vectorise without changing
        // any column's sequence of operations.
        double* __restrict neg_f = dots.data();
        for (std::size_t j = k + 1; j < columns; ++j) neg_f[j] = 0.0;
        for (std::size_t i = k; i < rows; ++i) {
            const double v_i = at(i, k);
            const double* __restrict row = &at(i, 0);
            for (std::size_t j = k + 1; j < columns; ++j) neg_f[j] = multiply_add(v_i, row[j], neg_f[j]);
        }
        for (std::size_t j = k + 1; j < columns; ++j) neg_f[j] = -(neg_f[j] / beta);  // the dot product, then -f_j
        for (std::size_t i = k; i < rows; ++i) {
            const double v_i = at(i, k);
            double* __restrict row = &at(i, 0);
            for (std::size_t j = k + 1; j < columns; ++j) row[j] = multiply_add(neg_f[j], v_i, row[j]);
        }
        double dot = 0.0;
        for (std::size_t i = k; i < rows; ++i) dot = multiply_add(at(i, k), b[i], dot);
        const double f = dot / beta;
        for (std::size_t i = k; i < rows; ++i) b[i] = multiply_add(-f, at(i, k), b[i]);
        diagonal[k] = alpha;
    }
    // R x = (Q^T b)[0, columns): back substitution
    std::vector<double> x(columns);
    for (std::size_t k = columns; k-- > 0;) {
        double s = b[k];
        for (std::size_t j = k + 1; j < columns; ++j) s = multiply_add(-at(k, j), x[j], s);
        x[k] = s / diagonal[k];
    }
    return x;
}

}  // namespace epc_fast
