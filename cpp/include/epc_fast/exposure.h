// Photometry, T_MPE and blur (MODEL.md sections 3 and 4). Each function is the formula of the
// same name in python/epc_fast/reference.py, for one point.
#pragma once

#include <cmath>
#include <limits>

#include "constants.h"
#include "solvers.h"

namespace epc_fast {

// e-/s: photo-electron rate of one pixel, r = L R tau cos^4(theta) / (4 F^2) * K a (p 1e-6)^2.
inline double electron_rate(double illuminance_lux, double reflectance, double lens_transmittance,
                            double field_angle_deg, double f_number, double electrons_per_lux_s_m2,
                            double fill_factor, double pixel_pitch_um) {
    const double cos_theta = std::cos(field_angle_deg * deg_to_rad);
    const double cos2 = cos_theta * cos_theta;
    const double focal_plane_lux = illuminance_lux * reflectance * lens_transmittance *
                                   (cos2 * cos2) / (4.0 * (f_number * f_number));
    const double pitch_m = pixel_pitch_um * um_to_m;
    return focal_plane_lux * electrons_per_lux_s_m2 * fill_factor * (pitch_m * pitch_m);
}

// The SNR target as the solvers use it: s = 10^(snr_db/10) and its square root.
struct SnrTarget {
    double root_s;  // 10^(snr_db/20): the target signal / noise
    double s;       // root_s^2

    explicit SnrTarget(double snr_db) : root_s(std::pow(10.0, snr_db / 20.0)), s(root_s * root_s) {}

    // PRNU caps the SNR at 1/u: unreachable when u * root_s >= 1.
    bool capped_by(double prnu) const { return prnu * root_s >= 1.0; }
};

// e-: the photo-electrons r T_MPE needed, the positive root of
// r^2 (1 - s u^2) T^2 - s (r + D) T - s sigma_r^2 = 0, written without cancellation:
// r T = q / (2 w) * (s + hypot(s, 2 sigma_r sqrt(w s) / q)), q = 1 + D/r,
// w = (1 - u sqrt(s))(1 + u sqrt(s)). Only positive terms are added, nothing that can overflow
// is squared, and s may underflow to 0 (a target far below 0 dB) without a 0 * inf.
// Meaningful only for r > 0 and u sqrt(s) < 1.
inline double signal_electrons(double rate_e_per_s, const SnrTarget& target, double read_noise_e,
                               double dark_current_e_per_s, double prnu) {
    const double w = (1.0 - prnu * target.root_s) * (1.0 + prnu * target.root_s);
    const double q = 1.0 + dark_current_e_per_s / rate_e_per_s;
    const double read_term = 2.0 * read_noise_e * std::sqrt(w) * target.root_s / q;
    return q / (2.0 * w) * (target.s + std::hypot(target.s, read_term));
}

// ln SNR - ln SNR_target after collecting `electrons` photo-electrons, with the dark
// electrons written through D/r: variance = E (1 + D/r) + sigma_r^2 + (u E)^2.
inline double log_snr_excess(double electrons, const SnrTarget& target, double read_noise_e,
                             double dark_per_signal, double prnu) {
    const double variance = electrons * (1.0 + dark_per_signal) + read_noise_e * read_noise_e +
                            (prnu * electrons) * (prnu * electrons);
    return std::log(electrons) - 0.5 * std::log(variance) - std::log(target.root_s);
}

// e-: the same root as signal_electrons, by Brent's method on ln SNR(E) = ln SNR_target.
// With a = w r^2, b = s (r + D), c = s sigma_r^2 the root T of a T^2 - b T - c = 0 lies in
// [max(b/a, sqrt(c/a)), b/a + sqrt(c/a)], so E = r T lies in
// [max(B, C), B + C], B = s (1 + D/r) / w, C = sigma_r sqrt(s / w): a bracket that provably
// holds the root, on which SNR(E) increases (u sqrt(s) < 1).
inline double signal_electrons_brent(double rate_e_per_s, const SnrTarget& target,
                                     double read_noise_e, double dark_current_e_per_s, double prnu,
                                     double rtol) {
    const double w = (1.0 - prnu * target.root_s) * (1.0 + prnu * target.root_s);
    const double dark_per_signal = dark_current_e_per_s / rate_e_per_s;
    const double shot_and_dark = target.s * (1.0 + dark_per_signal) / w;
    const double read = read_noise_e * std::sqrt(target.s / w);
    const double lo = std::fmax(shot_and_dark, read);
    const double hi = shot_and_dark + read;
    auto excess = [&](double electrons) {
        return log_snr_excess(electrons, target, read_noise_e, dark_per_signal, prnu);
    };
    return brent_root(excess, lo, hi, rtol);
}

// mm: blur length f_L tan(omega / k * T_MPE); +inf once the angle reaches pi/2.
inline double blur_length_mm(double focal_length_mm, double shake_deg_per_s, double stabilization,
                             double t_mpe_s) {
    const double angle_rad = shake_deg_per_s * deg_to_rad / stabilization * t_mpe_s;
    return angle_rad < half_pi ? focal_length_mm * std::tan(angle_rad)
                               : std::numeric_limits<double>::infinity();
}

}  // namespace epc_fast
