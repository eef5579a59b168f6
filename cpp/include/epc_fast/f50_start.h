// f50's bracket and starting abscissa for every lane of a block (f50.h solves from them), and
// the float32 mode's check of which lanes it can solve.
//
// Two starting guesses, both fitted by tools/fit_f50_start.py to the exact f50. The guess only
// decides how many steps the solver takes, never where it converges:
// - the accurate start, float64, for a lane with one wavelength, threshold 1/2 and no jitter
//   (the common scene): within 4.2e-8 of f50, so that Halley's first step lands at float64's
//   precision and the solver stops after one evaluation of the MTF (Newton's stop test asks
//   for a first step below 3e-8 at the default tolerance: it takes two on part of the lanes);
// - the cubic start for every other lane, and in float32 (whose tolerance one step from it
//   already meets): within 0.37%.
#pragma once

#include <cmath>
#include <cstddef>
#include <type_traits>

#include "block.h"
#include "mtf.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"

namespace epc_fast {

// float32 mode: a lane solves in float32 when its lengths (lambda F, pixel aperture, blur,
// jitter) are 0 or in [2^-40, 2^40] mm. Then f <= f_hi <= 2^40 and every product the MTF and
// its slopes form (length f, length^2, the Halley step) stays inside float32's range.
constexpr double float32_length_lo_mm = 9.094947017729282e-13;  // 2^-40
constexpr double float32_length_hi_mm = 1099511627776.0;        // 2^40

namespace detail {

// The cubic start, for the lanes the accurate one does not cover. Each factor alone reaches 1/2
// at its own frequency f_i: diffraction at NU50/(lambda F), a sinc of length l at X50/l, jitter
// at J50/sigma. With x_i = 1/f_i, S = sum x_i^2 and v_i = x_i/sqrt(S), f0 = P(v)/sqrt(S), P a cubic
// in v_d, s = v_pixel + v_motion and t = v_pixel v_motion fitted to the exact f50 (largest
// error 0.37%, median 2.4e-4, over factor ratios e^-7..e^7; jitter enters through S only).
// For c != 1/2 it is scaled by sqrt(ln(1/c) / ln 2), exact for jitter alone. The guess only
// decides how many steps the solver takes, never where it converges.
constexpr double start_nu50 = 0.4039727532995172;   // D(nu) = 1/2
constexpr double start_x50 = 0.6033545644016142;    // sinc(x) = 1/2
constexpr double start_j50 = 0.18739640236613234;   // exp(-2 pi^2 y^2) = 1/2: sqrt(ln 2 / 2) / pi

template <class T>
EPC_FAST_INLINE T start_polynomial(T v_d, T s, T t) {
    // the cubic of tools/fit_f50_start.py: sum of c_ijk v_d^i s^j t^k
    const T d2 = v_d * v_d, s2 = s * s;
    return T(1.0013379445198385) - T(0.26588191638058467) * t - T(0.15505341346674065) * s +
           T(0.1074529526372338) * (s * t) + T(0.15079619822963006) * s2 +
           T(0.002722663306764486) * (s2 * s) - T(0.29777013229383625) * v_d +
           T(0.0949786064343061) * (v_d * t) + T(0.08599482061958504) * (v_d * s) -
           T(0.08579594370107604) * (v_d * s2) + T(0.3187779135290404) * d2 +
           T(0.057129828500959906) * (d2 * s) - T(0.022016975724150373) * (d2 * v_d);
}

// The accurate start. Without jitter the unit vector v has two coordinates, v_d and
// w = v_p^2 - v_m^2, and f50 sqrt(S) = P(v_d, w) is smooth and even in w (pixel and motion are
// both sincs: swapping them changes w's sign). P: a polynomial of total degree 10 in
// a = 2 v_d - 1 and w, i.e. in a and z = w^2, coefficients of a^i z^j (i + 2j <= 10) row by
// row; largest relative error 4.2e-8 over the whole (v_d, w) domain, median 2.2e-8.
constexpr int accurate_start_degree = 10;
constexpr double accurate_start_coefficients[] = {
    // a^0: z^0 .. z^5
    0.9435411025977187,
    -0.028888374496825315,
    0.003137808182115746,
    -0.0005046480329371173,
    0.00013359214556250815,
    -2.683562844431367e-05,
    // a^1: z^0 .. z^4
    -0.01852681711788389,
    0.0013595944864183062,
    -0.00029332074707891253,
    -3.2127366902170185e-05,
    0.00012111938488791553,
    // a^2: z^0 .. z^4
    0.0700609190541451,
    -0.01015155996908029,
    0.0019168536871724735,
    -0.00046072281581195743,
    0.0002343822876773113,
    // a^3: z^0 .. z^3
    0.0007284908652694242,
    0.0006233653204402176,
    -0.00027350981579209323,
    5.1365085163319024e-05,
    // a^4: z^0 .. z^3
    0.005858279341075161,
    -0.0019552981870604876,
    0.0005699106280573547,
    -0.00032559020881622,
    // a^5: z^0 .. z^2
    -0.0007133493830427468,
    0.00041511547197716403,
    -0.00023609321535554505,
    // a^6: z^0 .. z^2
    -8.152810290792064e-05,
    -1.8746258227072046e-05,
    0.00018225852638772714,
    // a^7: z^0 .. z^1
    -0.00041993958377712135,
    0.000410953466010434,
    // a^8: z^0 .. z^1
    -0.00020280869628187866,
    7.335615787303173e-05,
    // a^9: z^0 .. z^0
    -0.00018346368614058698,
    // a^10: z^0 .. z^0
    -6.092579524054442e-05,
};

// One row of P: sum over j of c_ij z^j, by Horner (the compiler unrolls the constant loop).
template <int I, class T>
EPC_FAST_INLINE T accurate_start_row(T z) {
    constexpr int offset = [] {
        int k = 0;
        for (int i = 0; i < I; ++i) k += (accurate_start_degree - i) / 2 + 1;
        return k;
    }();
    constexpr int length = (accurate_start_degree - I) / 2 + 1;
    T acc = T(accurate_start_coefficients[offset + length - 1]);
    for (int j = length - 2; j >= 0; --j) acc = acc * z + T(accurate_start_coefficients[offset + j]);
    return acc;
}

// P(a, z): Horner in a over the rows I..degree.
template <int I = 0, class T>
EPC_FAST_INLINE T accurate_start_polynomial(T a, T z) {
    if constexpr (I == accurate_start_degree) {
        return accurate_start_row<I>(z);
    } else {
        return accurate_start_row<I>(z) + a * accurate_start_polynomial<I + 1>(a, z);
    }
}

// cycles/mm: one lane's starting guess from the lengths (mm) its frequency multiplies: lambda F
// (with a spectrum, the mean wavelength's), the pixel aperture, the blur and the jitter, and
// scale = sqrt(ln(1/c) / ln 2). `use_accurate` picks the accurate start (only for a lane with one
// wavelength, c = 1/2 and no jitter, where it holds) when the block computes both (Cubic and
// Accurate); a block whose lanes all take one computes only that one. Overflow or underflow
// in the lengths' squares gives 0, inf or NaN, which the caller replaces by f_hi / 2.
template <bool Cubic, bool Accurate, class T>
EPC_FAST_INLINE T start_guess(T lambda_f_mm, T aperture_mm, T blur_mm, T jitter_mm, T scale,
                              bool use_accurate) {
    // each length in units of its factor's own f50's inverse: x_i = 1 / f_i
    const T d = lambda_f_mm * T(1.0 / start_nu50);
    const T p = aperture_mm * T(1.0 / start_x50);
    const T m = blur_mm * T(1.0 / start_x50);
    const T j = jitter_mm * T(1.0 / start_j50);
    const T r = T(1) / std::sqrt(d * d + p * p + m * m + j * j);  // 1 / sqrt(S)
    const T pr = p * r, mr = m * r;
    T f0 = T(0);
    if (Cubic) f0 = r * start_polynomial(d * r, pr + mr, pr * mr) * scale;
    if (Accurate) {
        const T w = (pr - mr) * (pr + mr);
        const T f_accurate = r * accurate_start_polynomial(T(2) * (d * r) - T(1), w * w);
        f0 = Cubic ? (use_accurate ? f_accurate : f0) : f_accurate;
    }
    return f0;
}

constexpr double ln2 = 0.6931471805599453;

// ln(1/c) for threshold c, in T: the C library's log only for c other than 1/2.
template <class T>
T ln_inverse_threshold(double c) {
    return static_cast<T>(c == 0.5 ? ln2 : std::log(1.0 / c));
}

// The cubic start's factor for threshold c, from ln(1/c): sqrt(ln(1/c) / ln 2), 1 at c = 1/2.
template <class T>
EPC_FAST_INLINE T start_scale_of(T ln_inverse_c) {
    return std::sqrt(ln_inverse_c * T(1.0 / ln2));
}

// Whether a float64, monochromatic lane takes the accurate start: no jitter, threshold 1/2.
EPC_FAST_INLINE bool accurate_start_applies(double jitter_mm, double mtf_threshold) {
    return (jitter_mm == 0.0) & (mtf_threshold == 0.5);
}

// cycles/mm: the start start_f50 gives a monochromatic float64 lane (the formula alone, for
// tests: the accurate start where c = 1/2 and there is no jitter, else the cubic one).
inline double f50_start(double lambda_f_mm, double aperture_mm, double blur_mm, double jitter_mm,
                        double mtf_threshold) {
    const double scale = start_scale_of(ln_inverse_threshold<double>(mtf_threshold));
    return start_guess<true, true>(lambda_f_mm, aperture_mm, blur_mm, jitter_mm, scale,
                                   accurate_start_applies(jitter_mm, mtf_threshold));
}

// Whether a length (mm) is 0 or inside the range float32 lanes solve f50 for.
EPC_FAST_INLINE bool float32_length(double length_mm) {
    return (length_mm == 0.0) | ((length_mm >= float32_length_lo_mm) & (length_mm <= float32_length_hi_mm));
}

// Whether a factor of a length is inside 2^-60..2^60, where float32 multiplies it exactly as
// far as range goes (a product of two such within 2^-40..2^40 never leaves float32's range).
EPC_FAST_INLINE bool float32_factor(double x) {
    return (x >= 8.673617379884035e-19) & (x <= 1152921504606846976.0);  // 2^-60, 2^60
}

// Sets lo = 0, hi = f_hi, the starting abscissa and the solve's inputs in T for every lane;
// returns which terms the block's lanes to solve use, as bits (1 motion, 2 jitter). With T =
// float32, a lane to solve whose lengths float32 cannot hold is marked `wide` and taken out of
// the solve (kernel.h redoes it in float64).
template <class T>
int start_f50(const Spectrum& spectrum, Block<T>& b) {
    constexpr std::size_t n = block_size;
    constexpr bool narrow = sizeof(T) != sizeof(double);
    const auto& x = b.x;
    const bool poly = spectrum.polychromatic();
    double shortest_nm = inf, longest_nm = 0.0, mean_nm = 0.0;
    for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k) {
        if (spectrum.weights[k] > 0.0) shortest_nm = std::fmin(shortest_nm, spectrum.wavelengths_nm[k]);
        longest_nm = std::fmax(longest_nm, spectrum.wavelengths_nm[k]);
        mean_nm += spectrum.weights[k] * spectrum.wavelengths_nm[k];
    }
    // ln(1/c) for the jitter bracket and sqrt(ln(1/c) / ln 2) for the start's scaling; the C
    // library's log only for a threshold other than 1/2, once for a broadcast threshold.
    T* __restrict ln_inv_c = b.mtf;  // scratch until the solver runs
    T* __restrict start_scale = b.slope;
    if (b.is_broadcast(mtf_threshold)) {
        const T l = ln_inverse_threshold<T>(b.broadcast[mtf_threshold]);
        const T scale = start_scale_of(l);
        for (std::size_t i = 0; i < n; ++i) ln_inv_c[i] = l;
        for (std::size_t i = 0; i < n; ++i) start_scale[i] = scale;
    } else {
        for (std::size_t i = 0; i < n; ++i) ln_inv_c[i] = ln_inverse_threshold<T>(x[mtf_threshold][i]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) start_scale[i] = start_scale_of(ln_inv_c[i]);
    }
    const bool any_jitter = !b.broadcast_is(jitter_um, 0.0);
    const double* __restrict wavelength = x[wavelength_nm];
    const double* __restrict f_num_in = x[f_number];
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict fill = x[fill_factor];
    const double* __restrict jitter_um_ = x[jitter_um];
    const double* __restrict threshold_in = x[mtf_threshold];
    const double* __restrict blur_in = b.blur;
    unsigned char* __restrict solve = b.solve;
    unsigned char* __restrict wide = b.wide;
    T* __restrict lambda_f = b.lambda_f_mm;
    T* __restrict aperture = b.aperture_mm;
    T* __restrict jitter_mm = b.jitter_mm;
    T* __restrict blur = b.blur_mm;
    T* __restrict threshold = b.threshold;
    T* __restrict f_num = b.f_number;
    T* __restrict lo = b.lo;
    T* __restrict hi = b.hi;
    T* __restrict at = b.at;
    const double mean_mm = mean_nm * nm_to_mm;
    // every length in float64 first, then rounded once to T (float32: after checking it fits);
    // two loops, each of one type, as GCC vectorises them
    double* __restrict lf = b.scratch[0];
    double* __restrict lf_short = b.scratch[1];
    double* __restrict ap = b.scratch[2];
    double* __restrict jit = b.scratch[3];
    double* __restrict d_length = b.scratch[4];
    if (b.is_broadcast(fill_factor)) {  // pixel_aperture_mm, one sqrt
        const double root_fill = std::sqrt(b.broadcast[fill_factor]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) ap[i] = root_fill * (pitch[i] * um_to_mm);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) ap[i] = pixel_aperture_mm(pitch[i], fill[i]);
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double f_number_i = f_num_in[i];
        lf[i] = wavelength[i] * nm_to_mm * f_number_i;
        lf_short[i] = (poly ? shortest_nm : wavelength[i]) * nm_to_mm * f_number_i;
        jit[i] = jitter_um_[i] * um_to_mm;
        d_length[i] = poly ? mean_mm * f_number_i : lf[i];
    }
    if (narrow) {
        // the spectrum's wavelengths and the f-number enter the polychromatic MTF as separate
        // float32 factors, so they too must fit (2^-60..2^60)
        bool lambdas_fit = true;
        for (const double nm : spectrum.wavelengths_nm) lambdas_fit &= float32_factor(nm * nm_to_mm);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double lf_long = (poly ? longest_nm : wavelength[i]) * nm_to_mm * f_num_in[i];
            const bool fits = float32_length(lf_short[i]) & float32_length(lf_long) &
                              float32_length(ap[i]) & float32_length(blur_in[i]) &
                              float32_length(jit[i]) & lambdas_fit &
                              (!poly | float32_factor(f_num_in[i]));
            wide[i] = (solve[i] != 0) & !fits;
            solve[i] = (solve[i] != 0) & fits;
            b.f50[i] = T(0);  // what a wide lane's float32 pass writes out before it is redone
        }
    } else {
        for (std::size_t i = 0; i < n; ++i) wide[i] = 0;
    }
    // The lanes that take the accurate start (float64, one wavelength, threshold 1/2, no
    // jitter): a lane's start depends on its own inputs only. A block computes the start its
    // lanes to solve need, both only when they differ.
    unsigned char* __restrict accurate = b.flag_scratch[0];  // free after the exposure stage
    int n_accurate = 0, n_cubic = 0;
    if (!narrow && !poly) {
        EPC_FAST_SIMD_REDUCTION(+ : n_accurate, n_cubic)
        for (std::size_t i = 0; i < n; ++i) {
            const bool a = accurate_start_applies(jit[i], threshold_in[i]);
            accurate[i] = a;
            n_accurate += (solve[i] != 0) & a;
            n_cubic += (solve[i] != 0) & !a;
        }
    } else {
        for (std::size_t i = 0; i < n; ++i) accurate[i] = 0;
        n_cubic = 1;
    }
    auto finish = [&](auto with_jitter, auto with_cubic, auto with_accurate) {
        constexpr bool J = decltype(with_jitter)::value;
        constexpr bool Cubic = decltype(with_cubic)::value, Accurate = decltype(with_accurate)::value;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            // float32: a lane not solved computes on rounded stand-ins, harmlessly
            f_num[i] = static_cast<T>(f_num_in[i]);
            threshold[i] = static_cast<T>(threshold_in[i]);
            blur[i] = static_cast<T>(blur_in[i]);
            lambda_f[i] = static_cast<T>(lf[i]);
            aperture[i] = static_cast<T>(ap[i]);
            jitter_mm[i] = static_cast<T>(jit[i]);
            lo[i] = T(0);
            const T f_hi = f50_bracket<J>(static_cast<T>(lf_short[i]), aperture[i], blur[i],
                                          jitter_mm[i], ln_inv_c[i]);
            hi[i] = f_hi;
            const T f0 = start_guess<Cubic, Accurate>(static_cast<T>(d_length[i]), aperture[i],
                                                      blur[i], jitter_mm[i], start_scale[i],
                                                      accurate[i] != 0);
            at[i] = (f0 > T(0)) & (f0 < f_hi) ? f0 : T(0.5) * f_hi;
        }
    };
    using yes = std::true_type;
    using no = std::false_type;
    auto starts = [&](auto with_jitter) {
        if (n_accurate == 0) finish(with_jitter, yes{}, no{});
        else if (n_cubic == 0) finish(with_jitter, no{}, yes{});
        else finish(with_jitter, yes{}, yes{});
    };
    if (any_jitter) starts(yes{});
    else starts(no{});
    int motion = 0, jitter = 0;
    EPC_FAST_SIMD_REDUCTION(+ : motion)
    for (std::size_t i = 0; i < n; ++i) motion += (solve[i] != 0) & (blur[i] > T(0));
    EPC_FAST_SIMD_REDUCTION(+ : jitter)
    for (std::size_t i = 0; i < n; ++i) jitter += (solve[i] != 0) & (jitter_mm[i] > T(0));
    return (motion > 0 ? 1 : 0) | (jitter > 0 ? 2 : 0);
}

}  // namespace detail
}  // namespace epc_fast
