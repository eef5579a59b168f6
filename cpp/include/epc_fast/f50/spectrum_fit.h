// The accurate f50 start fitted to a call's spectrum (FittedStart, guesses.h), so that a
// polychromatic lane, like a monochromatic one, converges after one evaluation of its MTF (a
// sum over every wavelength) instead of two.
//
// A spectrum is shared by every point of a call, so its diffraction MTF is one function of
// f lambda_mean F, and f50 sqrt(S) = P(a, z) in the accurate start's coordinates as for one
// wavelength; only P differs. For each threshold of accurate_start_thresholds, P's 36
// coefficients are fitted by least squares on the relative error (least_squares.h) to f50
// solved to 1e-15 by the kernel's own Halley iteration (solvers.h, from the cubic start) on a grid
// of spectrum_start_nodes^2 Chebyshev nodes over the whole (v_d, w) domain: a few milliseconds,
// once per distinct spectrum (spectrum_start_of keeps the last few). The fit is a fixed sequence
// of operations on the spectrum's values: the same spectrum gets the same coefficients, bit for
// bit, in every call, so a point's result never depends on the call it is in.
//
// The start only decides how many steps the solver takes, never where it converges: a spectrum
// the polynomial fits poorly (one whose MTF has a kink where it crosses the threshold) costs
// steps, not accuracy.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../block.h"
#include "../params.h"
#include "guesses.h"
#include "least_squares.h"
#include "stage.h"

namespace epc_fast {

// Chebyshev nodes per coordinate (v_d and s = v_p^2 / (v_p^2 + v_m^2)) of the fit's grid.
constexpr int spectrum_start_nodes = 24;
// The tolerance the fit's targets are solved to.
constexpr double spectrum_start_target_rtol = 1e-15;

namespace detail {

// The monomials a^i z^j of the accurate start, in its coefficients' order (i outer).
inline void accurate_start_monomials(double a, double z, double* out) {
    int k = 0;
    double a_power = 1.0;
    for (int i = 0; i <= accurate_start_degree; ++i) {
        double term = a_power;
        for (int j = 0; j <= (accurate_start_degree - i) / 2; ++j) {
            out[k++] = term;
            term *= z;
        }
        a_power *= a;
    }
}

// The fit's grid: Chebyshev nodes of the first kind on (0, 1), interior (no length is 0).
inline double spectrum_start_node(int k) {
    return 0.5 - 0.5 * std::cos(pi * (k + 0.5) / spectrum_start_nodes);
}

// Node k of the fit's grid as the unit vector (v_d, v_p, v_m) the lanes' lengths are set from:
// v_d and s = v_p^2 / (v_p^2 + v_m^2) on the Chebyshev nodes.
struct FitNode {
    double v_d, v_p, v_m;
};
inline FitNode fit_node(int k) {
    const double v_d = spectrum_start_node(k / spectrum_start_nodes);
    const double s = spectrum_start_node(k % spectrum_start_nodes);
    const double rest = (1.0 - v_d) * (1.0 + v_d);
    return {v_d, std::sqrt(s * rest), std::sqrt((1.0 - s) * rest)};
}

}  // namespace detail

// A start's coefficients (every threshold row) fitted by least squares on the relative error to
// f50 on the fit's grid of spectrum_start_nodes^2 Chebyshev nodes over (v_d, s), v_p^2 =
// s (1 - v_d^2), v_m^2 = (1 - s)(1 - v_d^2). Every lane is to solve, without jitter, from 0 at
// the row's threshold c; lanes(b, c, ln(1/c), the row's start scale, node of lane i: node(i), a
// FitNode) sets its lengths (lambda_f_mm: the starts' optics length), bracket and start, and
// may take a lane out of the solve (its f50 lies beyond what the model holds: its node is left
// out of the fit); solve(b) solves f50 to spectrum_start_target_rtol; coordinates(b, i, monomials) writes lane i's Terms
// monomials and returns its r = 1 / sqrt(S). Start: FittedStart (the accurate start's form) or
// PixelStart (guesses.h).
template <class Start, int Terms, class Lanes, class Solve, class Coordinates>
Start fit_start(Lanes&& lanes, Solve&& solve, Coordinates&& coordinates) {
    using namespace detail;
    constexpr int points = spectrum_start_nodes * spectrum_start_nodes;
    constexpr int terms = Terms;
    auto b = std::make_unique<Block<double>>();
    Start fitted{};
    // allocated once for every row (each row overwrites all of them)
    std::vector<double> design(static_cast<std::size_t>(points) * terms), scaled(design.size()), rhs(points);
    for (int row = 0; row < n_accurate_starts; ++row) {
        const double c = accurate_start_thresholds[row];
        const double ln_inv_c = ln_inverse_threshold<double>(c);
        const double scale = start_scale_of(ln_inv_c);
        std::fill(rhs.begin(), rhs.end(), 1.0);
        for (int first = 0; first < points; first += static_cast<int>(block_size)) {
            for (std::size_t i = 0; i < block_size; ++i) {
                b->jitter_mm[i] = 0.0;
                b->threshold[i] = c;
                b->solve[i] = 1;
                b->lo[i] = 0.0;
            }
            // a point of the grid per lane (padding lanes repeat the last one)
            lanes(*b, c, ln_inv_c, scale, [&](std::size_t i) {
                return fit_node(std::min(first + static_cast<int>(i), points - 1));
            });
            solve(*b);
            for (std::size_t i = 0; i < block_size && first + static_cast<int>(i) < points; ++i) {
                const int k = first + static_cast<int>(i);
                double* out = &design[static_cast<std::size_t>(k) * terms];
                if (b->solve[i] == 0) {  // left out: a row of zeros
                    for (int t = 0; t < terms; ++t) out[t] = 0.0;
                    rhs[static_cast<std::size_t>(k)] = 0.0;
                    continue;
                }
                // relative error: the row's monomials over the target f50 sqrt(S) = f50 / r
                const double target = b->f50[i] / coordinates(*b, i, out);
                for (int t = 0; t < terms; ++t) out[t] /= target;
            }
        }
        // the design matrix is overwritten by the solve: keep what the error check needs
        std::copy(design.begin(), design.end(), scaled.begin());
        const std::vector<double> kept_rhs = rhs;
        const std::vector<double> x = least_squares(design, rhs, points, terms);
        double worst = 0.0;
        for (int k = 0; k < points; ++k) {
            if (kept_rhs[static_cast<std::size_t>(k)] == 0.0) continue;  // left out
            double fit = 0.0;
            for (int t = 0; t < terms; ++t) fit = multiply_add(scaled[static_cast<std::size_t>(k) * terms + t], x[t], fit);
            worst = std::fmax(worst, std::fabs(fit - 1.0));
        }
        for (int t = 0; t < terms; ++t) fitted.coefficients[row][t] = x[t];
        fitted.fit_error[row] = worst;
    }
    return fitted;
}

// fit_start in the accurate start's form (FittedStart): lambda_f_mm is the length of the starts'
// optics coordinate, the aperture the pixel's.
template <class Lanes, class Solve>
FittedStart fit_accurate_start(Lanes&& lanes, Solve&& solve) {
    return fit_start<FittedStart, detail::accurate_start_terms>(
        lanes, solve, [](const detail::Block<double>& b, std::size_t i, double* monomials) {
            const detail::StartPoint<double> q =
                detail::start_point(b.lambda_f_mm[i], b.aperture_mm[i], b.blur_mm[i], 0.0);
            detail::accurate_start_monomials(q.a, q.z, monomials);
            return q.r;
        });
}

// fit(), or null where it throws std::invalid_argument (least_squares: rank-deficient, as lengths
// at the ends of double's range make it) or gives a coefficient that is not finite: those lanes
// then take the start they had, which costs steps, never accuracy.
template <class Start, class Fit>
std::shared_ptr<const Start> fit_if_possible(Fit&& fit) {
    Start fitted;
    try {
        fitted = fit();
    } catch (const std::invalid_argument&) {
        return nullptr;
    }
    for (const auto& row : fitted.coefficients)
        for (const double c : row)
            if (!std::isfinite(c)) return nullptr;
    return std::make_shared<const Start>(fitted);
}

// The last few starts fitted (by their key's exact values), most recent first, and their lock.
template <class Key, class Start>
struct RecentFits {
    static constexpr std::size_t kept = 8;
    std::mutex mutex;
    std::vector<std::pair<Key, std::shared_ptr<const Start>>> fits;
};

// The start fitted to `key`: from `recent` or fitted now by fit() (a shared_ptr, null where
// none can be fitted). Thread-safe; the fit itself runs under the lock (a few milliseconds).
template <class Key, class Start, class Fit>
std::shared_ptr<const Start> recent_fit(RecentFits<Key, Start>& recent, const Key& key, Fit&& fit) {
    std::lock_guard<std::mutex> lock(recent.mutex);
    auto& fits = recent.fits;
    for (std::size_t k = 0; k < fits.size(); ++k) {
        if (fits[k].first == key) {
            auto found = fits[k];
            fits.erase(fits.begin() + static_cast<std::ptrdiff_t>(k));
            fits.insert(fits.begin(), found);  // most recent first
            return found.second;
        }
    }
    auto start = fit();
    fits.insert(fits.begin(), {key, start});
    if (fits.size() > RecentFits<Key, Start>::kept) fits.pop_back();
    return start;
}

// Fits the spectrum's start (every row). The spectrum must be polychromatic with a positive mean
// wavelength and at least one positive weight.
inline FittedStart fit_spectrum_start(const Spectrum& spectrum) {
    using namespace detail;
    Spectrum plain = spectrum;  // the targets are solved from the cubic start
    plain.start = nullptr;
    const Spectrum::Extent extent = plain.extent();
    const double mean_mm = extent.mean_nm * nm_to_mm, shortest_mm = extent.shortest_nm * nm_to_mm;
    auto lanes = [&](Block<double>& b, double, double ln_inv_c, double scale, auto node) {
        for (std::size_t i = 0; i < block_size; ++i) {
            const FitNode u = node(i);
            // lengths whose x_i = length / (factor's f50 constant) are v_d, v_p, v_m
            const double f_number = u.v_d * start_nu50 / mean_mm;
            const double aperture = u.v_p * start_x50;
            const double blur = u.v_m * start_x50;
            b.f_number[i] = f_number;
            b.aperture_mm[i] = aperture;
            b.blur_mm[i] = blur;
            b.lambda_f_mm[i] = mean_mm * f_number;
            b.hi[i] = f50_bracket<false>(shortest_mm * f_number, aperture, blur, 0.0, ln_inv_c);
            const double f0 = start_guess<true, -1>(mean_mm * f_number, aperture, blur, 0.0, scale, -1);
            b.at[i] = (f0 > 0.0) & (f0 < b.hi[i]) ? f0 : 0.5 * b.hi[i];
        }
    };
    return fit_accurate_start(lanes, [&](Block<double>& b) {
        polish<true, false, false, true, true>(plain, spectrum_start_target_rtol, b);
    });
}

// The spectrum's fitted start (null where none can be fitted: a spectrum whose lengths sit at
// the ends of double's range, subnormal wavelengths say), from the last few spectra fitted (by
// their exact values) or fitted now. Thread-safe.
inline std::shared_ptr<const FittedStart> spectrum_start_of(const Spectrum& spectrum) {
    using Key = std::pair<std::vector<double>, std::vector<double>>;
    static RecentFits<Key, FittedStart> recent;
    return recent_fit(recent, Key{spectrum.wavelengths_nm, spectrum.weights}, [&] {
        return fit_if_possible<FittedStart>([&] { return fit_spectrum_start(spectrum); });
    });
}

}  // namespace epc_fast
