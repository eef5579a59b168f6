// A scan's random values from its uniforms (philox.h): the inverse of each distribution's CDF, as
// docs/scan.md's draw contract writes it and python/epc_fast/scan/sampling/streams.py computes it.
//
// Python builds each distribution's spec (scan/sampling/distributions.py stream_spec): which
// transform, its constants, and for a truncated normal or log-normal the CDF's values at the
// bounds, so that the core needs only the inverse normal CDF (ndtri) and exp.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

#include "../block.h"
#include "../constants.h"
#include "../elementary.h"
#include "../parallel.h"

namespace epc_fast {

namespace detail {

// AS 241's rational for r = sqrt(-log(min(p, 1 - p))) above 5 (p below about 1e-11).
EPC_FAST_INLINE double ndtri_far(double r) {
    const double rf = r - 5.0;
    return (((((((2.01033439929228813265e-7 * rf + 2.71155556874348757815e-5) * rf +
                 1.24266094738807843860e-3) * rf + 2.65321895265761230930e-2) * rf +
               2.96560571828504891230e-1) * rf + 1.78482653991729133580e+0) * rf +
             5.46378491116411436990e+0) * rf + 6.65790464350110377720e+0) /
           (((((((2.04426310338993978564e-15 * rf + 1.42151175831644588870e-7) * rf +
                 1.84631831751005468180e-5) * rf + 7.86869131145613259100e-4) * rf +
               1.48753612908506148525e-2) * rf + 1.36929880922735805310e-1) * rf +
             5.99832206555887937690e-1) * rf + 1.0);
}

}  // namespace detail

// The inverse of the standard normal CDF for p in (0, 1): Wichura's algorithm AS 241
// (PPND16; Applied Statistics 37(3), 477-484, 1988), relative error about 1e-16. Three
// rational approximations: the centre |p - 1/2| <= 0.425, then r = sqrt(-log(min(p, 1 - p)))
// up to 5 (p down to about 1e-11) and beyond. 1 - p is exact for p >= 1/2 (Sterbenz), so both
// tails keep their precision on the uniforms' grid. Each piece is straight-line code, so that
// a lane loop over it vectorises; log is log_any (elementary.h).

// Whether p lies in the centre, where the first rational holds.
EPC_FAST_INLINE bool ndtri_centre(double p) { return std::fabs(p - 0.5) <= 0.425; }

// The centre's rational (finite for any p in [0, 1], meaningful in the centre).
EPC_FAST_INLINE double ndtri_central(double p) {
    const double q = p - 0.5;
    const double rc = 0.180625 - q * q;
    return q * (((((((2.5090809287301226727e+3 * rc + 3.3430575583588128105e+4) * rc +
                     6.7265770927008700853e+4) * rc + 4.5921953931549871457e+4) * rc +
                   1.3731693765509461125e+4) * rc + 1.9715909503065514427e+3) * rc +
                 1.3314166789178437745e+2) * rc + 3.3871328727963666080e+0) /
           (((((((5.2264952788528545610e+3 * rc + 2.8729085735721942674e+4) * rc +
                 3.9307895800092710610e+4) * rc + 2.1213794301586595867e+4) * rc +
               5.3941960214247511077e+3) * rc + 6.8718700749205790830e+2) * rc +
             4.2313330701600911252e+1) * rc + 1.0);
}

// The near tail's rational for p outside the centre, and its r (the far tail's from r > 5).
EPC_FAST_INLINE double ndtri_near_tail(double p, double& r) {
    const double q = p - 0.5;
    r = std::sqrt(-log_any(q < 0.0 ? p : 1.0 - p));
    const double rn = r - 1.6;
    const double near_num =
        (((((((7.74545014278341407640e-4 * rn + 2.27238449892691845833e-2) * rn +
              2.41780725177450611770e-1) * rn + 1.27045825245236838258e+0) * rn +
            3.64784832476320460504e+0) * rn + 5.76949722146069140550e+0) * rn +
          4.63033784615654529590e+0) * rn + 1.42343711074968357734e+0);
    const double near_den =
        (((((((1.05075007164441684324e-9 * rn + 5.47593808499534494600e-4) * rn +
              1.51986665636164571966e-2) * rn + 1.48103976427480074590e-1) * rn +
            6.89767334985100004550e-1) * rn + 1.67638483018380384940e+0) * rn +
          2.05319162663775882187e+0) * rn + 1.0);
    return (q < 0.0 ? -near_num : near_num) / near_den;
}

EPC_FAST_INLINE double ndtri(double p) {
    if (ndtri_centre(p)) return ndtri_central(p);
    double r;
    const double z = ndtri_near_tail(p, r);
    if (r <= 5.0) return z;
    return p < 0.5 ? -detail::ndtri_far(r) : detail::ndtri_far(r);
}

namespace detail {

// Gathers the lanes of a block outside ndtri's centre: their p into tail_p[0 .. m - 1] and
// their lane numbers into lane[0 .. m - 1], in lane order; returns m. Both arrays take
// block_size + 8 values (a vector's store may run past m). AVX-512 compresses each vector's
// tail lanes; AVX2 permutes them by a table of its 16 lane masks; otherwise lane by lane.
inline std::size_t gather_tail_lanes(const double* __restrict p, double* __restrict tail_p,
                                     std::int64_t* __restrict lane) {
    std::size_t m = 0;
#if defined(__AVX512F__)
    const __m512d half = _mm512_set1_pd(0.5), edge = _mm512_set1_pd(0.425);
    const __m512i eight = _mm512_set1_epi64(8);
    __m512i numbers = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
    for (std::size_t i = 0; i < block_size; i += 8) {
        const __m512d x = _mm512_loadu_pd(p + i);
        // !ndtri_centre: not |p - 1/2| <= 0.425 (unordered counts as outside)
        const __mmask8 tail = _mm512_cmp_pd_mask(_mm512_abs_pd(_mm512_sub_pd(x, half)), edge, _CMP_NLE_UQ);
        _mm512_storeu_pd(tail_p + m, _mm512_maskz_compress_pd(tail, x));
        _mm512_storeu_si512(lane + m, _mm512_maskz_compress_epi64(tail, numbers));
        m += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(tail)));
        numbers = _mm512_add_epi64(numbers, eight);
    }
#elif defined(__AVX2__)
    // for each mask of 4 lanes, the 32-bit elements that move its set lanes' doubles to the
    // front, in order
    alignas(32) static const std::int32_t front[16][8] = {
        {0, 1, 2, 3, 4, 5, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7}, {2, 3, 0, 1, 4, 5, 6, 7},
        {0, 1, 2, 3, 4, 5, 6, 7}, {4, 5, 0, 1, 2, 3, 6, 7}, {0, 1, 4, 5, 2, 3, 6, 7},
        {2, 3, 4, 5, 0, 1, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7}, {6, 7, 0, 1, 2, 3, 4, 5},
        {0, 1, 6, 7, 2, 3, 4, 5}, {2, 3, 6, 7, 0, 1, 4, 5}, {0, 1, 2, 3, 6, 7, 4, 5},
        {4, 5, 6, 7, 0, 1, 2, 3}, {0, 1, 4, 5, 6, 7, 2, 3}, {2, 3, 4, 5, 6, 7, 0, 1},
        {0, 1, 2, 3, 4, 5, 6, 7}};
    const __m256d half = _mm256_set1_pd(0.5), edge = _mm256_set1_pd(0.425);
    const __m256d sign_bit = _mm256_set1_pd(-0.0);
    const __m256i four = _mm256_set1_epi64x(4);
    __m256i numbers = _mm256_setr_epi64x(0, 1, 2, 3);
    for (std::size_t i = 0; i < block_size; i += 4) {
        const __m256d x = _mm256_loadu_pd(p + i);
        const __m256d distance = _mm256_andnot_pd(sign_bit, _mm256_sub_pd(x, half));
        const int tail = _mm256_movemask_pd(_mm256_cmp_pd(distance, edge, _CMP_NLE_UQ));
        const __m256i order = _mm256_load_si256(reinterpret_cast<const __m256i*>(front[tail]));
        _mm256_storeu_pd(tail_p + m, _mm256_castsi256_pd(_mm256_permutevar8x32_epi32(_mm256_castpd_si256(x), order)));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(lane + m), _mm256_permutevar8x32_epi32(numbers, order));
        m += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(tail)));
        numbers = _mm256_add_epi64(numbers, four);
    }
#else
    for (std::size_t i = 0; i < block_size; ++i) {
        lane[m] = static_cast<std::int64_t>(i);
        tail_p[m] = p[i];
        m += !ndtri_centre(p[i]);
    }
#endif
    return m;
}

}  // namespace detail

// z[i] = sign ndtri(p[i]) for every lane of a block. Every lane takes the central rational in
// one vector loop; the lanes outside the centre (15% of uniform p) are gathered into a short
// array for the near tail's, in a second vector loop over whole vectors of them; the lanes of
// the far tail (p below about 1e-11) are redone one by one. The same bits as ndtri lane by
// lane, at a fraction of the cost of both rationals, the log and the sqrt on every lane.
inline void ndtri_block(const double* __restrict p, double sign, double* __restrict z) {
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < block_size; ++i) z[i] = sign * ndtri_central(p[i]);
    constexpr std::size_t pad = 8;  // whole vectors of any width up to 8 doubles
    alignas(64) double tail_p[block_size + pad];
    alignas(64) std::int64_t lane[block_size + pad];
    const std::size_t m = detail::gather_tail_lanes(p, tail_p, lane);
    if (m == 0) return;
    const std::size_t whole = (m + pad - 1) / pad * pad;
    for (std::size_t j = m; j < whole; ++j) tail_p[j] = 0.25;  // any p: their results go unused
    alignas(64) double tail_z[block_size + pad];
    alignas(64) double tail_r[block_size + pad];
    EPC_FAST_SIMD
    for (std::size_t j = 0; j < whole; ++j) tail_z[j] = ndtri_near_tail(tail_p[j], tail_r[j]);
    for (std::size_t j = 0; j < m; ++j)
        z[lane[j]] = sign * (tail_r[j] > 5.0 ? ndtri(tail_p[j]) : tail_z[j]);
}

// One distribution's transform from a uniform u in (0, 1) (docs/scan.md):
//   affine      clamp(a + u b, low, high)                                   Uniform
//   exp_affine  clamp(exp(a + u b), low, high)                              LogUniform
//   normal      z = ndtri(pa + u (pb - pa)), negated if mirror; clamp(a + b z, low, high)
//   lognormal   the same z; clamp(exp(a + b z), low, high)
//   empirical   samples[min(floor(u m), m - 1)]
enum class DrawKind { affine, exp_affine, normal, lognormal, empirical };

struct Draw {
    DrawKind kind = DrawKind::affine;
    double a = 0.0, b = 0.0, pa = 0.0, pb = 1.0, low = 0.0, high = 0.0;
    bool mirror = false;
    std::vector<double> samples;
};

EPC_FAST_INLINE double clamp_to(double v, double low, double high) {
    return v < low ? low : v > high ? high : v;
}

// values[i] = the transform of u[i], for every lane of a block.
//
// exp's argument a + u b, or a + b z with |z| < 8.3 (p at least 2^-53 from 0 and 1), stays
// within [-|a| - |b| z_max, |a| + |b| z_max]; where that lies within exp_normal_bound, as for
// any distribution of camera parameters, exp_normal gives exp_any's bits at half its cost.
inline void draw_values(const Draw& d, const double* __restrict u, double* __restrict values) {
    const double a = d.a, b = d.b, low = d.low, high = d.high;
    constexpr double z_max = 9.0;
    switch (d.kind) {
        case DrawKind::affine:
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(a + u[i] * b, low, high);
            return;
        case DrawKind::exp_affine:
            if (std::fabs(a) + std::fabs(b) <= exp_normal_bound) {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i)
                    values[i] = clamp_to(exp_normal(a + u[i] * b), low, high);
                return;
            }
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i)
                values[i] = clamp_to(exp_any(a + u[i] * b), low, high);
            return;
        case DrawKind::normal:
        case DrawKind::lognormal: {
            const double pa = d.pa, width = d.pb - d.pa, sign = d.mirror ? -1.0 : 1.0;
            alignas(64) double p[block_size];
            alignas(64) double z[block_size];
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < block_size; ++i) p[i] = pa + u[i] * width;
            ndtri_block(p, sign, z);
            if (d.kind == DrawKind::normal) {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(a + b * z[i], low, high);
            } else if (std::fabs(a) + std::fabs(b) * z_max <= exp_normal_bound) {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(exp_normal(a + b * z[i]), low, high);
            } else {
                EPC_FAST_SIMD
                for (std::size_t i = 0; i < block_size; ++i) values[i] = clamp_to(exp_any(a + b * z[i]), low, high);
            }
            return;
        }
        case DrawKind::empirical: {
            const double* __restrict s = d.samples.data();
            const std::size_t m = d.samples.size();
            const double scale = static_cast<double>(m);
            for (std::size_t i = 0; i < block_size; ++i) {
                const auto k = static_cast<std::size_t>(u[i] * scale);
                values[i] = s[k < m ? k : m - 1];
            }
            return;
        }
    }
}

}  // namespace epc_fast
