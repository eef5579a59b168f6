// What limits a design and how sensitive it is: each MTF factor's share of the loss at f50, and
// the elasticity d ln EPC / d ln theta of every parameter, for the lanes of a block whose f50
// is solved. python/epc_fast/reference_sensitivity.py derives the formulas and carries the
// same function names; every formula here is a ratio of sums of terms of one sign, or a series
// where two terms would cancel, so each keeps its relative precision.
#pragma once

#include <cmath>
#include <cstddef>

#include "block.h"
#include "constants.h"
#include "elementary.h"
#include "exposure.h"
#include "mtf.h"
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

// ln(1 + x) for x > -1, from log_any: ln(u) x / (u - 1) with u = 1 + x rounded corrects u's
// rounding (Goldberg, ACM Computing Surveys 23(1), 1991, Theorem 4); x itself where u = 1.
EPC_FAST_INLINE double log1p_any(double x) {
    const double u = 1.0 + x;
    const double scaled = log_any(u) * (x / (u - 1.0));
    return u == 1.0 ? x : scaled;
}

}  // namespace detail

// 1: ln sinc(y) for 0 <= y < 1; -sum_k zeta(2k) y^(2k) / k below series_below.
EPC_FAST_INLINE double log_sinc(double y) {
    const double direct = log_any(sinpi_unit(y) / (pi * y));
    return y < detail::series_below ? -detail::zeta_series<true>(y) : direct;
}

// 1: y d ln sinc(y) / dy = pi y cot(pi y) - 1 for 0 <= y < 1; -2 sum_k zeta(2k) y^(2k) below
// series_below, where the two terms cancel.
EPC_FAST_INLINE double sinc_log_slope(double y) {
    const double direct = pi * y * cospi_small(y) / sinpi_unit(y) - 1.0;
    return y < detail::series_below ? -2.0 * detail::zeta_series<false>(y) : direct;
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
// small loss's digits), ln D elsewhere (D's own digits, down to the cut-off).
EPC_FAST_INLINE double log_mtf_diffraction(double value, double loss) {
    const double near_one = detail::log1p_any(-(loss < 0.5 ? loss : 0.5));
    return loss < 0.5 ? near_one : log_any(value);
}

// Each factor's log at f, and the log-slopes of diffraction (nu dD/dnu / D), the pixel and the
// motion (y d ln sinc / dy): what the shares and the elasticities need.
struct MtfLogFactors {
    double log[n_shares];
    double slope_diffraction, slope_pixel, slope_motion;
};

// 1: MtfLogFactors at f (cycles/mm) for one point: the diffraction of `spectrum`, or
// monochromatic at wavelength_nm when it has none; the pixel aperture sqrt(a) p, the blur and
// the jitter sigma_j in mm.
EPC_FAST_INLINE MtfLogFactors mtf_log_factors(double f, double f_number, double wavelength_nm,
                                              double aperture_mm, double blur_mm,
                                              double jitter_mm, const Spectrum& spectrum) {
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
    return {{log_mtf_diffraction(value, loss), log_sinc(y_pixel), log_sinc(y_motion),
             -2.0 * pi * pi * sigma_f * sigma_f},
            slope_numerator / value, sinc_log_slope(y_pixel), sinc_log_slope(y_motion)};
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

// The shares and elasticities of the block's lanes into share_out and elasticity_out (rows of
// block_size): OK lanes from their f50, NaN on the others, but where the blur is unbounded
// (f50 = 0, EPC = 0: motion takes all of the loss) the shares 0, 0, 1, 0.
template <class T>
void sensitivity(const Inputs& in, const Block<T>& b, bool shares, bool elasticities,
                 double (&share_out)[n_shares][block_size],
                 double (&elasticity_out)[n_params][block_size]) {
    const auto& x = b.x;
    const double field_slope_broadcast =
        b.is_broadcast(field_angle_deg) ? field_angle_rate_log_slope(b.broadcast[field_angle_deg]) : 0.0;
    for (std::size_t i = 0; i < block_size; ++i) {
        const unsigned char st = b.status[i];
        const bool ok = st == static_cast<unsigned char>(Status::ok);
        const bool unbounded = st == static_cast<unsigned char>(Status::blur_unbounded);
        if (!ok) {
            for (int s = 0; s < n_shares; ++s)
                share_out[s][i] = unbounded ? (s == share_motion ? 1.0 : 0.0) : nan;
            for (int j = 0; j < n_params; ++j) elasticity_out[j][i] = nan;
            continue;
        }
        const double f = static_cast<double>(b.f50[i]);
        const double aperture = pixel_aperture_mm(x[pixel_pitch_um][i], x[fill_factor][i]);
        const double blur = b.blur[i];
        const MtfLogFactors m =
            mtf_log_factors(f, x[f_number][i], x[wavelength_nm][i], aperture, blur,
                            x[jitter_um][i] * um_to_mm, in.spectrum);
        if (shares) {
            const double total = (m.log[0] + m.log[1]) + (m.log[2] + m.log[3]);
            for (int s = 0; s < n_shares; ++s) share_out[s][i] = m.log[s] / total;
        }
        if (!elasticities) continue;
        const double log_j = m.log[share_jitter];
        const double a_slope = -(((m.slope_diffraction + m.slope_pixel) + m.slope_motion) + 2.0 * log_j);
        const TMpeLogSlopes t = t_mpe_log_slopes(b.electrons[i], b.t_mpe[i], x[read_noise_e][i],
                                                 x[dark_current_e_per_s][i], x[prnu][i]);
        const double mu = m.slope_motion * blur_angle_log_slope(blur, x[focal_length_mm][i],
                                                                x[shake_deg_per_s][i],
                                                                x[stabilization][i], b.t_mpe[i]);
        const double via_rate = mu * t.rate;
        const double field_slope = b.is_broadcast(field_angle_deg)
                                       ? field_slope_broadcast
                                       : field_angle_rate_log_slope(x[field_angle_deg][i]);
        const double snr_scale = x[snr_db][i] * (ln10 / 10.0);  // d ln s / d ln snr_db
        double mtf_slope[n_params];
        mtf_slope[illuminance_lux] = via_rate;
        mtf_slope[pixel_pitch_um] = m.slope_pixel + 2.0 * via_rate;
        mtf_slope[f_number] = m.slope_diffraction - 2.0 * via_rate;
        mtf_slope[focal_length_mm] = m.slope_motion;
        mtf_slope[size] = 0.0;
        mtf_slope[reflectance] = via_rate;
        mtf_slope[lens_transmittance] = via_rate;
        mtf_slope[field_angle_deg] = via_rate * field_slope;
        mtf_slope[fill_factor] = 0.5 * m.slope_pixel + via_rate;
        mtf_slope[electrons_per_lux_s_m2] = via_rate;
        mtf_slope[read_noise_e] = mu * t.read;
        mtf_slope[dark_current_e_per_s] = mu * t.dark;
        mtf_slope[prnu] = mu * t.prnu;
        mtf_slope[full_well_e] = 0.0;
        mtf_slope[snr_db] = mu * t.target * snr_scale;
        mtf_slope[shake_deg_per_s] = mu;
        mtf_slope[stabilization] = -mu;
        mtf_slope[jitter_um] = 2.0 * log_j;
        mtf_slope[wavelength_nm] = m.slope_diffraction;
        mtf_slope[mtf_threshold] = -1.0;
        const double inverse_a = 1.0 / a_slope;
        for (int j = 0; j < n_params; ++j) {
            const double area = j == size ? 1.0 : j == pixel_pitch_um && in.size_is_pixel_count ? 2.0 : 0.0;
            elasticity_out[j][i] = area + 2.0 * mtf_slope[j] * inverse_a;
        }
    }
}

}  // namespace detail
}  // namespace epc_fast
