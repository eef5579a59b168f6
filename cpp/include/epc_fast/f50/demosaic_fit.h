// The f50 start fitted to a colour sensor's demosaicker (PixelStart), so that a Bayer sensor's
// lane, whose demosaicker the other starts do not know, takes two evaluations of its MTF
// instead of up to five.
//
// A lane at full resolution with the full pixel aperture (binning 1, fill factor 1) and
// neither denoising nor a wavefront error has one pixel factor Pi(f p) = sinc(f p) M_dem(f p):
// the same function of f p for every such lane of the call (the demosaicker's table is the
// call's). With x_p = p / X_pi (X_pi: where Pi falls to 1/2) in place of the aperture's p / X50,
// f50 sqrt(S) is a function P(a, w) of the accurate start's coordinates a = 2 v_d - 1 and
// w = v_p^2 - v_m^2, but no longer even in w (pixel and motion are not alike): P is a
// polynomial of total degree pixel_start_degree in a and w, its coefficients fitted per
// threshold row as spectrum_fit.h fits a spectrum's, on the same grid, to f50 solved by the
// kernel's own Halley iteration. Once per distinct table (the core keeps the last 8 by value);
// the same table gets the same coefficients, bit for bit, in every call.
//
// The start only decides how many steps the solver takes, never where it converges.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../block.h"
#include "../cfa.h"
#include "../params.h"
#include "../polynomials.h"
#include "../tabulated.h"
#include "guesses.h"
#include "least_squares.h"
#include "solvers.h"
#include "spectrum_fit.h"

namespace epc_fast {

// Fits the demosaicker's start (every row). Throws std::invalid_argument where the fit is
// rank-deficient.
inline PixelStart fit_pixel_start(const MtfTable& table) {
    using namespace detail;
    // X_pi: sinc(x) M_dem(x) = 1/2 by bisection on (0, X50] (M_dem <= 1: at or below sinc's)
    auto pixel = [&](double x) { return mtf_pixel(x, 1.0) * tabulated(table, x).value; };
    double lo = 0.0, hi = start_x50;
    for (int k = 0; k < 200 && hi - lo > 1e-17 * hi; ++k) {
        const double mid = lo + 0.5 * (hi - lo);
        (pixel(mid) > 0.5 ? lo : hi) = mid;
    }
    const double x50 = lo + 0.5 * (hi - lo);
    static const Spectrum monochromatic{};
    auto lanes = [&](Block<double>& b, double, double ln_inv_c, double scale, auto node) {
        b.demosaic_table = &table;
        for (std::size_t i = 0; i < block_size; ++i) {
            const FitNode u = node(i);
            // lengths whose x_i are v_d, v_p, v_m (S = 1)
            const double lambda_f = u.v_d * start_nu50;
            const double pitch = u.v_p * x50;
            const double blur = u.v_m * start_x50;
            b.f_number[i] = 1.0;
            b.lambda_f_mm[i] = lambda_f;
            b.aperture_mm[i] = pitch;
            b.output_pitch_mm[i] = pitch;
            b.blur_mm[i] = blur;
            b.hi[i] = f50_bracket<false>(lambda_f, pitch, blur, 0.0, ln_inv_c);
            const double f0 = start_guess<true, -1>(lambda_f, pitch, blur, 0.0, scale, -1);
            b.at[i] = (f0 > 0.0) & (f0 < b.hi[i]) ? f0 : 0.5 * b.hi[i];
        }
    };
    PixelStart fitted = fit_start<PixelStart, pixel_start_terms>(
        lanes,
        [&](Block<double>& b) {
            polish<true, false, false, false, true>(monochromatic, spectrum_start_target_rtol, b);
        },
        [&](const Block<double>& b, std::size_t i, double* monomials) {
            const PixelPoint<double> q = pixel_point(b.lambda_f_mm[i], b.aperture_mm[i], b.blur_mm[i], x50);
            pixel_start_monomials(q.a, q.w, monomials);
            return q.r;
        });
    fitted.x50 = x50;
    return fitted;
}

// The table's fitted start (null where none can be fitted, or none is needed: a table that leaves
// the pixel's 1/2 point where the sinc's is, 1 up to it as Menon's is, where the accurate start is
// within 1e-7 at MTF50 already and its lanes stop after one step), from the last few tables
// fitted (by their exact knots and coefficients) or fitted now. Thread-safe.
inline std::shared_ptr<const PixelStart> pixel_start_of(const MtfTable& table) {
    using Key = std::pair<std::vector<double>, std::vector<double>>;
    static RecentFits<Key, PixelStart> recent;
    return recent_fit(recent, Key{table.knots, table.coefficients}, [&] {
        auto start = fit_if_possible<PixelStart>([&] { return fit_pixel_start(table); });
        const bool needed = start != nullptr && start->x50 > 0.0 && start->x50 < detail::start_x50 * (1.0 - 1e-6);
        return needed ? start : nullptr;
    });
}

}  // namespace epc_fast
