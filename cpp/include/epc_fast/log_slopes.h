// Each MTF factor's log and log-slope at f50, T_MPE's log-slopes, and from them one lane's
// elasticities: the formulas the shares and the elasticities (sensitivity.h) are made of, each
// with the name it has in python/epc_fast/reference/sensitivity.py, which derives them. Every
// formula is a ratio of sums of terms of one sign, or a series where two terms would cancel,
// so each keeps its relative precision. The lens's, the demosaicker's, the wavefront error's
// and denoising's logs are their terms' own (lens.h, cfa.h, aberration.h, denoise.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "aberration.h"
#include "block.h"
#include "cfa.h"
#include "constants.h"
#include "denoise.h"
#include "elementary.h"
#include "exposure/point.h"
#include "lens.h"
#include "mtf.h"
#include "parallel.h"
#include "params.h"
#include "polynomials.h"
#include "tabulated.h"

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
        const LensLogFactor l = lens_log_factor(f, *table, value);
        // where D(f50) is 0, the lens's share is ln L and diffraction's 0 (lens_log_factor)
        m.log[share_lens] = l.log;
        m.log[share_diffraction] = value == 0.0 ? 0.0 : m.log[share_diffraction];
        m.slope_diffraction = l.f_slope;
    }
    if (demosaic != nullptr) {  // a colour sensor's demosaicker at x = f p_out
        const DemosaicLogFactor d = demosaic_log_factor(f, pitch_mm * binning, *demosaic);
        m.log[share_demosaic] = d.log;
        m.slope_demosaic = d.f_slope;
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
// s = 10^(snr_db/10) and the PRNU (python/epc_fast/reference/sensitivity.py's module
// docstring).
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
    out[binning_readout][i] = nan;
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

}  // namespace detail
}  // namespace epc_fast
