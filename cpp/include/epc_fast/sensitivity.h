// What limits a design and how sensitive it is: each MTF factor's share of the loss at f50, and
// the elasticity d ln EPC / d ln theta of every parameter, for the lanes of a block whose f50
// is solved. python/epc_fast/reference_sensitivity.py derives the formulas and carries the
// same function names; every formula here is a ratio of sums of terms of one sign, or a series
// where two terms would cancel, so each keeps its relative precision.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "block.h"
#include "constants.h"
#include "elementary.h"
#include "exposure.h"
#include "mtf.h"
#include "optics.h"
#include "optics_stage.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"
#include "status.h"

namespace epc_fast {

namespace detail {

// zeta(2), zeta(4), ..., zeta(30), rounded to double (the Python reference holds the same).
constexpr double zeta_even[] = {
    1.6449340668482264, 1.0823232337111381, 1.0173430619844492, 1.0040773561979444,
    1.000994575127818,  1.000246086553308,  1.0000612481350588, 1.0000152822594086,
    1.000003817293265,  1.0000009539620338, 1.0000002384505027, 1.000000059608189,
    1.0000000149015549, 1.000000003725334,  1.0000000009313275,
};
constexpr int n_zeta = sizeof zeta_even / sizeof zeta_even[0];
constexpr double ln10 = 2.302585092994045684;

// Below this y the series of ln sinc are used: their 15 terms reach 4^-30 = 1e-18 of the first
// at y = 1/4; above it the direct formulas lose at most 3 bits to cancellation.
constexpr double series_below = 0.25;

// sum_k c_k y^(2k + 2) with c_k = zeta(2k + 2) / (k + 1) (Log) or zeta(2k + 2), by Horner in y^2.
template <bool Log>
EPC_FAST_INLINE double zeta_series(double y) {
    const double t = y * y;
    double total = 0.0;
    for (int k = n_zeta - 1; k >= 0; --k)
        total = (total + (Log ? zeta_even[k] / (k + 1) : zeta_even[k])) * t;
    return total;
}

}  // namespace detail

// ln sinc(y) and y d ln sinc / dy from s = sin(pi y) and inv = 1 / (y s) (1 where the series
// serves): log_sinc and sinc_log_slope with their divisions shared (1/y = s inv, 1/s = y inv).
struct LogSinc {
    double log, slope;
};

EPC_FAST_INLINE LogSinc log_sinc_given(double y, double sin_py, double inv_y_sin) {
    const bool small = y < detail::series_below;
    const double direct_log = log_any(sin_py * (sin_py * inv_y_sin) * (1.0 / pi));
    const double direct_slope = pi * y * cospi_small(y) * (y * inv_y_sin) - 1.0;
    return {small ? -detail::zeta_series<true>(y) : direct_log,
            small ? -2.0 * detail::zeta_series<false>(y) : direct_slope};
}

// 1: ln sinc(y) for 0 <= y < 1; -sum_k zeta(2k) y^(2k) / k below series_below.
EPC_FAST_INLINE double log_sinc(double y) {
    const double s = sinpi_unit(y);
    return log_sinc_given(y, s, y < detail::series_below ? 1.0 : 1.0 / (y * s)).log;
}

// 1: y d ln sinc(y) / dy = pi y cot(pi y) - 1 for 0 <= y < 1; -2 sum_k zeta(2k) y^(2k) below
// series_below, where the two terms cancel.
EPC_FAST_INLINE double sinc_log_slope(double y) {
    const double s = sinpi_unit(y);
    return log_sinc_given(y, s, y < detail::series_below ? 1.0 : 1.0 / (y * s)).slope;
}

// 1: 1 - D(nu); (2/pi) (asin nu + nu sqrt(1 - nu^2)) up to nu = 1/2 (nothing cancels where D is
// near 1), 1 - D above, 1 past the cut-off.
EPC_FAST_INLINE double diffraction_loss(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    const double low = (2.0 / pi) * (asin_small(v < 0.5 ? v : 0.5) + v * std::sqrt((1.0 - v) * (1.0 + v)));
    return v <= 0.5 ? low : 1.0 - mtf_diffraction(v);
}

// 1: nu dD/dnu = -(4/pi) nu sqrt(1 - nu^2) below the cut-off, 0 past it.
EPC_FAST_INLINE double diffraction_log_slope_numerator(double nu) {
    const double v = nu < 1.0 ? nu : 1.0;
    return -(4.0 / pi) * v * std::sqrt((1.0 - v) * (1.0 + v));
}

// 1: ln D, from D and its loss 1 - D: log1p(-loss) where the loss is below 1/2 (it keeps a
// small loss's digits), ln D elsewhere (D's own digits, down to the cut-off); one log either
// way, log1p(x) as ln(u) x / (u - 1) with u = 1 + x rounded, which corrects u's rounding
// (Goldberg, ACM Computing Surveys 23(1), 1991, Theorem 4), x itself where u = 1.
EPC_FAST_INLINE double log_mtf_diffraction(double value, double loss) {
    const bool near_one = loss < 0.5;
    const double u = near_one ? 1.0 - loss : value;
    const double log_u = log_any(u);
    const double log1p = u == 1.0 ? -loss : log_u * (-loss / (u - 1.0));
    return near_one ? log1p : log_u;
}

// Each factor's log at f, and the log-slopes f d ln M_i / df of diffraction (nu dD/dnu / D), the
// (binned) pixel and the motion, and the pixel's aperture alone, sinc(sqrt(a) p f), the part the
// fill factor moves: what the shares and the elasticities need.
struct MtfLogFactors {
    double log[n_shares];
    double slope_diffraction, slope_pixel, slope_motion, slope_fill;
    // the wavefront error's f d ln(D_W/D) / df and W d ln D_W / dW, denoising's f d ln H / df
    // and sigma d ln H / d sigma (0 where the term is off)
    double slope_aberration = 0.0, wave_aberration = 0.0, slope_denoise = 0.0, sigma_denoise = 0.0;
    double slope_demosaic = 0.0;  // f d ln M_dem / df (also p d ln M_dem / dp)
};

// (ln(D_W / D), f d ln(D_W / D) / df, W d ln D_W / dW) at f: the wavefront error's factor of the
// diffraction MTF, D_W = sum_i w_i D_i ATF_i against D = sum_i w_i D_i (`value`, with
// `slope_numerator` = sum_i w_i nu_i dD_i/dnu). D - D_W = sum_i w_i D_i a (1 - 4 (nu_i - 1/2)^2),
// a = (W/0.18)^2, is formed without cancellation, and so its log1p.
struct AberrationLogFactor {
    double log, f_slope, w_slope;
};

inline AberrationLogFactor aberration_log_factor(double f, double f_number, double wavelength_nm,
                                                 const Spectrum& spectrum, double depth,
                                                 double value, double slope_numerator) {
    double deficit = 0.0, aberrated_numerator = 0.0;
    auto line = [&](double lambda_nm, double w) {
        const double raw = f * (lambda_nm * nm_to_mm) * f_number;
        const double nu = raw < 1.0 ? raw : 1.0;
        const double d = mtf_diffraction(nu), c = nu - 0.5;
        const double bowl = 1.0 - 4.0 * (c * c);
        deficit += w * d * depth * bowl;
        aberrated_numerator += w * (diffraction_log_slope_numerator(nu) * (1.0 - depth * bowl) +
                                    d * 8.0 * depth * nu * c);
    };
    if (spectrum.polychromatic()) {
        for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k)
            line(spectrum.wavelengths_nm[k], spectrum.weights[k]);
    } else {
        line(wavelength_nm, 1.0);
    }
    const double aberrated = value - deficit;
    return {std::log1p(-deficit / value), aberrated_numerator / aberrated - slope_numerator / value,
            -2.0 * deficit / aberrated};
}

// 1: MtfLogFactors at f (cycles/mm) for one point: the diffraction of `spectrum`, or
// monochromatic at wavelength_nm when it has none; the pixel aperture sqrt(a) p, the blur and
// the jitter sigma_j in mm; binning k x k pixels of pitch p mm (the array factor
// sinc(k p f) / sinc(p f), none at k = 1) and a burst's alignment residual of rms
// sigma_a sqrt(1 - 1/n) mm.
EPC_FAST_INLINE MtfLogFactors mtf_log_factors(double f, double f_number, double wavelength_nm,
                                              double aperture_mm, double blur_mm,
                                              double jitter_mm, const Spectrum& spectrum,
                                              double pitch_mm = 0.0, double binning = 1.0,
                                              double residual_mm = 0.0, double depth = 0.0,
                                              double denoise_sigma_px = 0.0,
                                              const MtfTable* table = nullptr,
                                              const MtfTable* demosaic = nullptr) {
    double loss = 0.0, slope_numerator = 0.0, value = 0.0;
    if (spectrum.polychromatic()) {
        for (std::size_t k = 0; k < spectrum.wavelengths_nm.size(); ++k) {
            const double w = spectrum.weights[k];
            const double nu = f * (spectrum.wavelengths_nm[k] * nm_to_mm) * f_number;
            loss += w * diffraction_loss(nu);
            slope_numerator += w * diffraction_log_slope_numerator(nu);
            value += w * mtf_diffraction(nu);
        }
    } else {
        const double nu = f * (wavelength_nm * nm_to_mm) * f_number;
        loss = diffraction_loss(nu);
        slope_numerator = diffraction_log_slope_numerator(nu);
        value = mtf_diffraction(nu);
    }
    const double y_pixel = aperture_mm * f, y_motion = blur_mm * f, sigma_f = jitter_mm * f;
    const double residual_f = residual_mm * f;
    double log_pixel = log_sinc(y_pixel), slope_pixel = sinc_log_slope(y_pixel);
    const double slope_fill = slope_pixel;
    if (binning > 1.0) {
        const double y_whole = binning * pitch_mm * f, y_one = pitch_mm * f;
        log_pixel += log_sinc(y_whole) - log_sinc(y_one);
        slope_pixel += sinc_log_slope(y_whole) - sinc_log_slope(y_one);
    }
    MtfLogFactors m{{log_mtf_diffraction(value, loss), log_pixel, log_sinc(y_motion),
                     -2.0 * pi * pi * sigma_f * sigma_f, -2.0 * pi * pi * residual_f * residual_f,
                     0.0, 0.0, 0.0, 0.0},
                    slope_numerator / value, slope_pixel, sinc_log_slope(y_motion), slope_fill};
    if (depth > 0.0) {
        const AberrationLogFactor a = aberration_log_factor(f, f_number, wavelength_nm, spectrum,
                                                            depth, value, slope_numerator);
        m.log[share_aberration] = a.log;
        m.slope_aberration = a.f_slope;
        m.wave_aberration = a.w_slope;
    }
    if (table != nullptr) {  // L in place of D: ln(L / D), and the optics' slope f L'/L
        const TableValue l = tabulated(*table, f);
        // where D(f50) is 0 (a table passing frequencies past the cut-off at the point's
        // f-number), ln(L/D) is undefined: the lens's share is ln L, diffraction's 0
        const bool past = value == 0.0;
        m.log[share_lens] = past ? std::log(l.value) : std::log(l.value) - std::log(value);
        m.log[share_diffraction] = past ? 0.0 : m.log[share_diffraction];
        m.slope_diffraction = f * l.d1 / l.value;
    }
    if (demosaic != nullptr) {  // a colour sensor's demosaicker at x = f p_out
        const double x = f * (pitch_mm * binning);
        const TableValue v = tabulated(*demosaic, x);
        m.log[share_demosaic] = std::log(v.value);
        m.slope_demosaic = x * v.d1 / v.value;
    }
    if (denoise_sigma_px > 0.0) {  // on the output pitch k p
        const DenoiseLogFactor h = denoise_log_factor(f, denoise_sigma_px, pitch_mm * binning);
        m.log[share_denoise] = h.log;
        m.slope_denoise = h.f_slope;
        m.sigma_denoise = h.sigma_slope;
    }
    return m;
}

// d ln T_MPE / d ln x for the rate, the dark current, the read noise, the target
// s = 10^(snr_db/10) and the PRNU (reference_sensitivity.py's module docstring).
struct TMpeLogSlopes {
    double rate, dark, read, target, prnu;
};

// From the electrons e = r T and T_MPE, in the ratios q = D T / e and v = 2 sigma_r^2 / e, so
// that a huge dark term gives its limit rather than inf / inf.
EPC_FAST_INLINE TMpeLogSlopes t_mpe_log_slopes(double electrons, double t_mpe_s,
                                                double read_noise_e, double dark_current_e_per_s,
                                                double prnu) {
    const double q = dark_current_e_per_s * t_mpe_s / electrons;
    const double v = 2.0 * read_noise_e * read_noise_e / electrons;
    const double ue = prnu * prnu * electrons;
    const double inverse = 1.0 / (1.0 + q + v);
    const double dark = q > 0.0 ? 1.0 / (1.0 + (1.0 + v) / q) : 0.0;  // q / (1 + q + v)
    return {-1.0 - dark, dark, v * inverse, 1.0 - 0.5 * v * inverse + ue * inverse,
            2.0 * ue * inverse};
}

// 1: d ln b / d ln alpha = alpha (1 + tan^2 alpha) / tan alpha for the blur angle alpha (1 at
// no blur), tan alpha = b / f_L. The angle as blur_length_mm forms it (a scaled product where
// the plain one leaves the normal range).
EPC_FAST_INLINE double blur_angle_log_slope(double blur_mm, double focal_length_mm,
                                            double shake_deg_per_s, double stabilization,
                                            double t_mpe_s) {
    double angle = shake_deg_per_s * deg_to_rad * t_mpe_s / stabilization;
    if (!(angle >= 0x1p-900 && angle <= 0x1p900))
        angle = scaled_product({shake_deg_per_s, deg_to_rad, t_mpe_s}, {stabilization});
    const double t = blur_mm / focal_length_mm;
    return t > 0.0 ? angle * (1.0 + t * t) / t : 1.0;
}

// 1: d ln r / d ln theta = -4 theta tan theta (the cos^4 falloff), theta in radians; cos theta
// as sin(90 deg - |theta|), as electron_rate forms it.
inline double field_angle_rate_log_slope(double field_angle_deg) {
    const double theta = std::fabs(field_angle_deg) * deg_to_rad;
    return -4.0 * theta * std::sin(theta) / std::sin((90.0 - std::fabs(field_angle_deg)) * deg_to_rad);
}

namespace detail {

// -d ln MTF / d ln f at one lane, A, from the factors' log-slopes there.
EPC_FAST_INLINE double area_slope(double slope_diffraction, double slope_pixel, double slope_motion,
                                  double log_jitter) {
    return -(((slope_diffraction + slope_pixel) + slope_motion) + 2.0 * log_jitter);
}

// The wavefront error's and denoising's log-slopes (MtfLogFactors) and, for sigma, the noise
// gain's d ln g / d ln sigma times mu d ln T / d ln s: what their elasticities and the pitch's,
// f-number's and wavelength's moves of them add (0 where the terms are off).
struct OpticsSlopes {
    double aberration = 0.0, wave = 0.0, denoise = 0.0, sigma = 0.0, gain = 0.0;
};
// (denoise: the filter's and a demosaicker's f-slopes together, both functions of f p_out)

// d ln MTF / d ln theta of every parameter at one lane, from the factors' log-slopes there (m),
// T_MPE's log-slopes (t), mu = d ln M / d ln alpha, the field angle's rate log-slope and the
// SNR target's d ln s / d ln snr_db; written as elasticities 2 slope / A plus the area's part
// (two_over_a = 2 / area_slope), into row j of `out` at lane i. A lane that has none passes
// mask = NaN and a NaN two_over_a; mask = 1 otherwise.
//
// Binning and bursts: slope_fill is the log-slope of the pixel's own aperture (the binned pixel's
// slope_pixel less the array factor's), log_alignment the alignment residual's log; binning and
// frames are whole numbers, with no elasticity (NaN).
EPC_FAST_INLINE void elasticities_of_lane(double slope_diffraction, double slope_pixel,
                                          double slope_fill, double slope_motion,
                                          double log_jitter, double log_alignment,
                                          const TMpeLogSlopes& t, double mu, double field_slope,
                                          double snr_scale, bool size_is_pixel_count,
                                          double (&out)[n_params][block_size], std::size_t i,
                                          double two_over_a, double threshold_term = 1.0,
                                          double mask = 1.0, const OpticsSlopes& optics = {}) {
    const double via_rate = mu * t.rate;
    out[illuminance_lux][i] = via_rate * two_over_a;
    out[pixel_pitch_um][i] = ((size_is_pixel_count ? 2.0 : 0.0) * mask) +
                             ((slope_pixel + optics.denoise) + 2.0 * via_rate) * two_over_a;
    out[f_number][i] = ((slope_diffraction + optics.aberration) - 2.0 * via_rate) * two_over_a;
    out[focal_length_mm][i] = slope_motion * two_over_a;
    out[size][i] = mask;
    out[reflectance][i] = via_rate * two_over_a;
    out[lens_transmittance][i] = via_rate * two_over_a;
    out[field_angle_deg][i] = via_rate * field_slope * two_over_a;
    out[fill_factor][i] = (0.5 * slope_fill + via_rate) * two_over_a;
    out[electrons_per_lux_s_m2][i] = via_rate * two_over_a;
    out[read_noise_e][i] = mu * t.read * two_over_a;
    out[dark_current_e_per_s][i] = mu * t.dark * two_over_a;
    out[prnu][i] = mu * t.prnu * two_over_a;
    out[full_well_e][i] = 0.0 * mask;
    out[snr_db][i] = mu * t.target * snr_scale * two_over_a;
    out[shake_deg_per_s][i] = mu * two_over_a;
    out[stabilization][i] = -mu * two_over_a;
    out[jitter_um][i] = 2.0 * log_jitter * two_over_a;
    out[wavelength_nm][i] = (slope_diffraction + optics.aberration) * two_over_a;
    out[mtf_threshold][i] = -threshold_term * two_over_a;
    out[binning][i] = nan;
    out[frames][i] = nan;
    out[lens][i] = nan;
    // a colour sensor's transmittance is the rate's; its noise gain the target's s g
    out[cfa_transmittance][i] = via_rate * two_over_a;
    out[color_noise_gain][i] = mu * t.target * two_over_a;
    out[alignment_error_um][i] = 2.0 * log_alignment * two_over_a;
    // 0 where the term is off (W d ln ATF / dW and sigma d ln H / d sigma vanish with W and
    // sigma); denoising moves the MTF and, through the target s g, T_MPE and the blur
    out[wavefront_rms_waves][i] = optics.wave * two_over_a;
    out[denoise_sigma_px][i] = (optics.sigma + optics.gain) * two_over_a;
}

// diffraction_loss, diffraction_log_slope_numerator and mtf_diffraction at nu. `High` = false
// when the caller knows nu <= 1/2: the three then share one square root and one asin, without
// the near-cut-off form.
struct DiffractionTerms {
    double loss, slope_numerator, value;
};

template <bool High>
EPC_FAST_INLINE DiffractionTerms diffraction_terms(double nu) {
    if (High) return {diffraction_loss(nu), diffraction_log_slope_numerator(nu), mtf_diffraction(nu)};
    const double root = std::sqrt((1.0 - nu) * (1.0 + nu));
    const double asin_nu = asin_small(nu);
    return {(2.0 / pi) * (asin_nu + nu * root), -(4.0 / pi) * nu * root,
            (2.0 / pi) * ((half_pi - asin_nu) - nu * root)};
}

// diffraction_terms at the lanes' nu into loss (`Shares` only), slope_numerator and value, or
// (`Add`) w times them added to those; `high`: some lane's nu is past 1/2 (or NaN).
template <bool Shares, bool Add>
EPC_FAST_INLINE void diffraction_of_lanes(const double* __restrict nu, double w, bool high,
                                          double* __restrict loss, double* __restrict slope_numerator,
                                          double* __restrict value) {
    auto lanes = [&](auto high_tag) EPC_FAST_LAMBDA_INLINE {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < block_size; ++i) {
            const DiffractionTerms d = diffraction_terms<decltype(high_tag)::value>(nu[i]);
            if (Shares) loss[i] = Add ? loss[i] + w * d.loss : d.loss;
            slope_numerator[i] = Add ? slope_numerator[i] + w * d.slope_numerator : d.slope_numerator;
            value[i] = Add ? value[i] + w * d.value : d.value;
        }
    };
    if (high) lanes(std::true_type{});
    else lanes(std::false_type{});
}

// Above this a sinc's argument, or below this the diffraction MTF, is near the factor's zero:
// the vector path leaves such lanes (thresholds of 1e-6 and less) to sensitivity_lane.
constexpr double near_zero_argument = 1.0 - 0x1p-20;
constexpr double near_zero_diffraction = 0x1p-30;

// One OK lane's shares and elasticities by the scalar formulas (mtf_log_factors,
// t_mpe_log_slopes, blur_angle_log_slope): for the lanes whose shared divisions in
// `sensitivity` could leave the normal range, and those near a factor's zero.
//
// With a threshold c so small that f50 is a factor's zero to within rounding, that factor's
// log and log-slope at the computed f50 are not the root's (or not finite): the factors' logs
// then do not add up to ln c. That factor (the one with the least log, "pinned") takes ln c
// less the others' logs, the shares divide by ln c, and the elasticities take their limit as
// its log-slope goes to -infinity where it is not finite: f50 follows the factor's zero.
template <class T>
void sensitivity_lane(const Inputs& in, const Block<T>& b, std::size_t i, double field_slope,
                      double (&share_out)[n_shares][block_size],
                      double (&elasticity_out)[n_params][block_size]) {
    const auto& x = b.x;
    // binning and bursts (a block with them: b.sensor): the binned pixel's lengths, the
    // alignment residual, and the exposure's inputs as the output pixel of the burst sees them
    // (exposure_stage.h sensor_terms)
    const double k = x[binning][i], n = x[frames][i];
    const double residual_um = x[alignment_error_um][i] * std::sqrt(1.0 - 1.0 / n);
    auto input = [&](int param, int row) { return b.sensor ? b.sensor_store[row][i] : x[param][i]; };
    MtfLogFactors m = mtf_log_factors(
        static_cast<double>(b.f50[i]), x[f_number][i], x[wavelength_nm][i],
        pixel_aperture_mm(x[pixel_pitch_um][i], x[fill_factor][i]), b.blur[i],
        x[jitter_um][i] * um_to_mm, in.spectrum, x[pixel_pitch_um][i] * um_to_mm, k,
        residual_um * um_to_mm, aberration_depth(x[wavefront_rms_waves][i]), x[denoise_sigma_px][i],
        b.lens_tables != nullptr ? &lens_table(b, i) : nullptr, b.demosaic_table);
    const double ln_c = std::log(x[mtf_threshold][i]);
    double total = (((m.log[0] + m.log[1]) + (m.log[2] + m.log[3])) + m.log[4]) +
                   ((m.log[share_aberration] + m.log[share_denoise]) +
                    (m.log[share_lens] + m.log[share_demosaic]));
    const bool pinned = !(std::fabs(total - ln_c) <= 1e-3 * std::fabs(ln_c));
    if (pinned) {
        auto least = [&m](int s) {  // a NaN log (a sinc past its zero) counts as -inf
            return std::isnan(m.log[s]) ? -std::numeric_limits<double>::infinity() : m.log[s];
        };
        int j = 0;
        for (int s = 1; s < n_shares; ++s)
            if (least(s) < least(j)) j = s;
        double others = 0.0;
        for (int s = 0; s < n_shares; ++s) others += s == j ? 0.0 : m.log[s];
        m.log[j] = ln_c - others;
        total = ln_c;
    }
    for (int s = 0; s < n_shares; ++s) share_out[s][i] = m.log[s] / total;
    const TMpeLogSlopes t = t_mpe_log_slopes(b.electrons[i], b.t_mpe[i],
                                             input(read_noise_e, sensor_read),
                                             input(dark_current_e_per_s, sensor_dark),
                                             input(prnu, sensor_prnu));
    const double beta = blur_angle_log_slope(b.blur[i], x[focal_length_mm][i], x[shake_deg_per_s][i],
                                             input(stabilization, sensor_stab), b.t_mpe[i]);
    double slopes[4] = {m.slope_diffraction, m.slope_pixel, m.slope_motion, m.slope_fill};
    double log_jitter = m.log[share_jitter], log_alignment = m.log[share_alignment];
    double threshold_term = 1.0;
    const double sigma_px = x[denoise_sigma_px][i];
    OpticsSlopes optics{m.slope_aberration, m.wave_aberration, m.slope_denoise + m.slope_demosaic,
                        m.sigma_denoise,
                        sigma_px > 0.0 ? noise_gain_log_slope(sigma_px) : 0.0};
    int infinite = -1;
    for (int s = 0; s < 3; ++s)
        if (!(std::fabs(slopes[s]) <= std::numeric_limits<double>::max())) infinite = s;
    if (infinite >= 0) {  // the limit: every slope over |slope_k|, which goes to infinity
        for (int s = 0; s < 3; ++s) slopes[s] = s == infinite ? -1.0 : 0.0;
        slopes[3] = infinite == 1 && !(std::fabs(m.slope_fill) <= std::numeric_limits<double>::max()) ? -1.0 : 0.0;
        log_jitter = 0.0;
        log_alignment = 0.0;
        threshold_term = 0.0;
        optics = {0.0, 0.0, 0.0, 0.0, optics.gain};  // finite slopes: 0 in that limit
    }
    const double mu = slopes[2] * beta;
    optics.gain *= mu * t.target;  // the noise gain's path through T_MPE and the blur
    // a lens table's L does not move with the f-number or the wavelength: its slope is the
    // optics' in the area slope, and theirs 0
    const double diffraction_slope = b.lens_tables != nullptr ? 0.0 : slopes[0];
    elasticities_of_lane(diffraction_slope, slopes[1], slopes[3], slopes[2], log_jitter, log_alignment, t,
                         mu, field_slope, x[snr_db][i] * (ln10 / 10.0),
                         in.size_is_pixel_count, elasticity_out, i,
                         2.0 / area_slope(slopes[0] + optics.aberration, slopes[1] + optics.denoise,
                                          slopes[2], log_jitter + log_alignment),
                         threshold_term, 1.0, optics);
}

// The shares and elasticities of the block's lanes into share_out and elasticity_out (rows of
// block_size): OK lanes from their f50, NaN on the others, but where the blur is unbounded
// (f50 = 0, EPC = 0: motion takes all of the loss) the shares 0, 0, 1, 0. Each stage is a loop
// over the lanes that vectorises, with the divisions of a lane shared where one product serves
// them (the slowest vector instructions here); the other lanes compute on f = 0 (every factor
// 1) and are masked at the end. A lane whose shared products leave the normal range is redone
// by sensitivity_lane. `Exposure` = false when the block has no read noise, dark current or
// PRNU (broadcast 0): T_MPE's log-slopes are then -1 for the rate, 1 for the target, 0 else.
// `Shares` and `Elasticities` say which are asked for: the logs are formed only for the
// shares, the slopes only for the elasticities.
template <bool Exposure, bool Shares, bool Elasticities, class T>
void sensitivity_as(const Inputs& in, const Block<T>& b, double (&share_out)[n_shares][block_size],
                    double (&elasticity_out)[n_params][block_size]) {
    constexpr bool shares = Shares, elasticities = Elasticities;
    constexpr std::size_t n = block_size;
    const auto& x = b.x;
    alignas(64) double f[n], loss[n], slope_numerator[n], value[n];
    alignas(64) double logs[n_shares][n], slope_pixel[n], slope_motion[n];
    LaneFlag<double> ok[n], slow[n];
    const unsigned char* __restrict status = b.status;
    for (std::size_t i = 0; i < n; ++i) {
        ok[i] = status[i] == static_cast<unsigned char>(Status::ok);
        f[i] = ok[i] ? static_cast<double>(b.f50[i]) : 0.0;
    }
    // diffraction's loss, log-slope numerator and value, over the spectrum's lines
    const double* __restrict f_num = x[f_number];
    alignas(64) double nu[n];
    if (in.spectrum.polychromatic()) {
        for (std::size_t i = 0; i < n; ++i) loss[i] = slope_numerator[i] = value[i] = 0.0;
        for (std::size_t k = 0; k < in.spectrum.wavelengths_nm.size(); ++k) {
            const double lambda_mm = in.spectrum.wavelengths_nm[k] * nm_to_mm;
            unsigned char high = 0;
            EPC_FAST_SIMD
            for (std::size_t i = 0; i < n; ++i) {
                nu[i] = f[i] * lambda_mm * f_num[i];
                high |= !(nu[i] <= 0.5);
            }
            diffraction_of_lanes<Shares, true>(nu, in.spectrum.weights[k], high, loss, slope_numerator, value);
        }
    } else {
        const double* __restrict lambda = x[wavelength_nm];
        unsigned char high = 0;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            nu[i] = f[i] * (lambda[i] * nm_to_mm) * f_num[i];
            high |= !(nu[i] <= 0.5);
        }
        diffraction_of_lanes<Shares, false>(nu, 1.0, high, loss, slope_numerator, value);
    }
    // every factor's log and log-slope (mtf_log_factors), the sincs' and diffraction's
    // divisions in one
    const double* __restrict pitch = x[pixel_pitch_um];
    const double* __restrict fill = x[fill_factor];
    const double* __restrict jitter = x[jitter_um];
    const double* __restrict blur = b.blur;
    alignas(64) double aperture[n];
    if (b.is_broadcast(fill_factor)) {  // pixel_aperture_mm, one sqrt
        const double root_fill = std::sqrt(b.broadcast[fill_factor]);
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) aperture[i] = root_fill * (pitch[i] * um_to_mm);
    } else {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) aperture[i] = pixel_aperture_mm(pitch[i], fill[i]);
    }
    EPC_FAST_SIMD
    for (std::size_t i = 0; i < n; ++i) {
        const double y_pixel = aperture[i] * f[i];
        const double y_motion = blur[i] * f[i];
        const double sigma_f = (jitter[i] * um_to_mm) * f[i];
        const double sin_pixel = sinpi_unit(y_pixel), sin_motion = sinpi_unit(y_motion);
        const double d_pixel = y_pixel < detail::series_below ? 1.0 : y_pixel * sin_pixel;
        const double d_motion = y_motion < detail::series_below ? 1.0 : y_motion * sin_motion;
        const double d_sincs = d_pixel * d_motion, product = d_sincs * value[i];
        const double inverse = 1.0 / product;
        slow[i] = ok[i] & (!((product >= 0x1p-900) & (product <= 0x1p900)) |
                           (y_pixel > near_zero_argument) | (y_motion > near_zero_argument) |
                           (value[i] < near_zero_diffraction));
        const LogSinc pixel = log_sinc_given(y_pixel, sin_pixel, d_motion * value[i] * inverse);
        const LogSinc motion = log_sinc_given(y_motion, sin_motion, d_pixel * value[i] * inverse);
        if (Shares) {
            logs[share_diffraction][i] = log_mtf_diffraction(value[i], loss[i]);
            logs[share_pixel][i] = pixel.log;
            logs[share_motion][i] = motion.log;
        }
        logs[share_jitter][i] = -2.0 * pi * pi * sigma_f * sigma_f;
        logs[share_alignment][i] = 0.0;  // a block with bursts takes sensitivity_lane
        logs[share_aberration][i] = 0.0;  // neither term is in the core yet
        logs[share_denoise][i] = 0.0;
        logs[share_lens][i] = 0.0;
        logs[share_demosaic][i] = 0.0;
        if (Elasticities) {
            slope_numerator[i] *= d_sincs * inverse;  // now nu dD/dnu / D
            slope_pixel[i] = pixel.slope;
            slope_motion[i] = motion.slope;
        }
    }
    if (shares) {
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            const double inverse_total =
                1.0 / (((logs[0][i] + logs[1][i]) + (logs[2][i] + logs[3][i])) + logs[4][i]);
            const bool unbounded = status[i] == static_cast<unsigned char>(Status::blur_unbounded);
            for (int s = 0; s < n_shares; ++s) {
                const double other = unbounded ? (s == share_motion ? 1.0 : 0.0) : nan;
                share_out[s][i] = ok[i] ? logs[s][i] * inverse_total : other;
            }
        }
    }
    alignas(64) double field_slope[n];
    if (elasticities) {
        if (b.is_broadcast(field_angle_deg)) {
            // the last broadcast angle's slope, kept per thread: two sin calls per block else
            thread_local double memo_angle = nan, memo_slope = 0.0;
            const double angle = b.broadcast[field_angle_deg];
            if (!(angle == memo_angle)) {
                memo_slope = field_angle_rate_log_slope(angle);
                memo_angle = angle;
            }
            const double v = memo_slope;
            for (std::size_t i = 0; i < n; ++i) field_slope[i] = v;
        } else {
            for (std::size_t i = 0; i < n; ++i)
                field_slope[i] = field_angle_rate_log_slope(x[field_angle_deg][i]);
        }
        const double* __restrict focal = x[focal_length_mm];
        const double* __restrict shake = x[shake_deg_per_s];
        const double* __restrict stab = x[stabilization];
        const double* __restrict snr = x[snr_db];
        const double* __restrict read = x[read_noise_e];
        const double* __restrict dark = x[dark_current_e_per_s];
        const double* __restrict u = x[prnu];
        const double* __restrict electrons = b.electrons;
        const double* __restrict t_mpe = b.t_mpe;
        const bool count = in.size_is_pixel_count;
        EPC_FAST_SIMD
        for (std::size_t i = 0; i < n; ++i) {
            // OK lanes' exposure; the others compute on 1 e- over 1 s and are masked below
            const double t_s = ok[i] ? t_mpe[i] : 1.0;
            TMpeLogSlopes t{-1.0, 0.0, 0.0, 1.0, 0.0};
            bool exposure_ok = true;
            if (Exposure) {
                // t_mpe_log_slopes with one division by e and one by 1 + q + v
                const double inverse_e = 1.0 / (ok[i] ? electrons[i] : 1.0);
                const double e = ok[i] ? electrons[i] : 1.0;
                const double q = dark[i] * t_s * inverse_e;
                const double v = 2.0 * read[i] * read[i] * inverse_e;
                const double ue = u[i] * u[i] * e;
                const double inverse = 1.0 / (1.0 + q + v);
                const double dark_part = q * inverse;
                t = {-1.0 - dark_part, dark_part, v * inverse, 1.0 - 0.5 * v * inverse + ue * inverse,
                     2.0 * ue * inverse};
                exposure_ok = (q <= 0x1p900) & (v <= 0x1p900) & (ue <= 0x1p900);
            }
            // blur_angle_log_slope as one quotient: alpha (f_L^2 + b^2) / (b f_L), alpha =
            // omega T / k
            const double numerator = shake[i] * deg_to_rad * t_s * (focal[i] * focal[i] + blur[i] * blur[i]);
            const double denominator = stab[i] * blur[i] * focal[i];
            const double beta = blur[i] > 0.0 ? numerator / denominator : 1.0;
            slow[i] |= ok[i] & ((blur[i] > 0.0) & !((numerator >= 0x1p-900) & (numerator <= 0x1p900) &
                                                    (denominator >= 0x1p-900) & (denominator <= 0x1p900)));
            slow[i] |= ok[i] & !exposure_ok;
            const double mask = ok[i] ? 1.0 : nan;
            const double two_over_a =
                (2.0 / area_slope(slope_numerator[i], slope_pixel[i], slope_motion[i], logs[share_jitter][i])) * mask;
            elasticities_of_lane(slope_numerator[i], slope_pixel[i], slope_pixel[i], slope_motion[i],
                                 logs[share_jitter][i], 0.0, t, slope_motion[i] * beta, field_slope[i],
                                 snr[i] * (ln10 / 10.0), count, elasticity_out, i, two_over_a, 1.0,
                                 mask);
        }
    }
    // a block with binning, bursts, the wavefront error or denoising: every OK lane by
    // sensitivity_lane, which has their terms
    if (b.sensor || !b.broadcast_is(wavefront_rms_waves, 0.0) || !b.broadcast_is(denoise_sigma_px, 0.0) ||
        b.lens_tables != nullptr || b.demosaic_table != nullptr)
        for (std::size_t i = 0; i < n; ++i) slow[i] |= ok[i];
    // the slow lanes (most blocks have none)
    int n_slow = 0;
    EPC_FAST_SIMD_REDUCTION(+ : n_slow)
    for (std::size_t i = 0; i < n; ++i) n_slow += slow[i] != 0;
    if (n_slow == 0) return;
    for (std::size_t i = 0; i < n; ++i) {
        if (!slow[i]) continue;
        double lane_shares[n_shares][block_size];
        sensitivity_lane(in, b, i, elasticities ? field_slope[i] : 0.0,
                         shares ? share_out : lane_shares, elasticity_out);
    }
}

template <class T>
void sensitivity(const Inputs& in, const Block<T>& b, bool shares, bool elasticities,
                 double (&share_out)[n_shares][block_size],
                 double (&elasticity_out)[n_params][block_size]) {
    const bool exposure = !(b.broadcast_is(read_noise_e, 0.0) && b.broadcast_is(dark_current_e_per_s, 0.0) &&
                            b.broadcast_is(prnu, 0.0));
    auto run = [&](auto exposure_terms) {
        constexpr bool E = decltype(exposure_terms)::value;
        if (shares && elasticities) sensitivity_as<E, true, true>(in, b, share_out, elasticity_out);
        else if (shares) sensitivity_as<E, true, false>(in, b, share_out, elasticity_out);
        else if (elasticities) sensitivity_as<E, false, true>(in, b, share_out, elasticity_out);
    };
    if (exposure) run(std::true_type{});
    else run(std::false_type{});
}

}  // namespace detail
}  // namespace epc_fast
