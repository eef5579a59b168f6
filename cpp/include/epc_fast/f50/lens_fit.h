// The accurate f50 start fitted to a lens table (FittedStart, guesses.h), so that a lane whose
// optics are a lens's table converges after one evaluation of its MTF, as the paper camera's
// does, instead of two or three from the start scaled by where the table falls to 1/2.
//
// A lens table is one fixed function of f for every lane that takes it, as a spectrum's
// diffraction is one function of f lambda_mean F: f50 sqrt(S) is again P(a, z) of the accurate
// start, with the optics coordinate x_d = 1 / half (lens_start_lengths), and only P's
// coefficients depend on the table. They are fitted as a spectrum's are (spectrum_fit.h
// fit_accurate_start): on the same grid, each node's f50 solved by the kernel's own Halley
// iteration; a node whose MTF stays above the threshold to the table's end holds no f50 and is
// left out. The fit is a fixed sequence of operations on the table's values: the same table
// gets the same coefficients, bit for bit, in every call.
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
#include "../lens.h"
#include "../params.h"
#include "../tabulated.h"
#include "spectrum_fit.h"

namespace epc_fast {

// Fits the table's start (every row).
inline FittedStart fit_lens_start(const MtfTable& table) {
    using namespace detail;
    std::vector<MtfTable> one{table};  // the fit's lanes' table (the targets from the cubic start)
    one[0].start = nullptr;
    static const Spectrum monochromatic{};
    const double d_length = start_nu50 / table.half;  // lens_start_lengths' f50_length
    const double zero_length = 1.0 / table.end;       // and its zero_length
    const double x_d = d_length * (1.0 / start_nu50);
    auto lanes = [&](Block<double>& b, double c, double ln_inv_c, double scale, auto node) {
        b.lens_tables = &one;
        for (std::size_t i = 0; i < block_size; ++i) {
            const FitNode u = node(i);
            // the table fixes x_d: the node's scale x_d / v_d sets the pixel's and the motion's
            const double node_scale = x_d / u.v_d;
            const double aperture = u.v_p * start_x50 * node_scale;
            const double blur = u.v_m * start_x50 * node_scale;
            b.f_number[i] = 1.0;  // (the table replaces diffraction: unused)
            b.aperture_mm[i] = aperture;
            b.blur_mm[i] = blur;
            b.lambda_f_mm[i] = d_length;
            b.hi[i] = f50_bracket<false>(zero_length, aperture, blur, 0.0, ln_inv_c);
            b.at[i] = b.hi[i];
        }
        // a node whose MTF is still above c at the bracket's end (the table's) holds no f50
        system_mtf<true, false, false, false>(monochromatic, b);
        for (std::size_t i = 0; i < block_size; ++i) {
            b.solve[i] = b.mtf[i] <= c;
            const double f0 = start_guess<true, -1>(d_length, b.aperture_mm[i], b.blur_mm[i], 0.0, scale, -1);
            b.at[i] = (f0 > 0.0) & (f0 < b.hi[i]) ? f0 : 0.5 * b.hi[i];
        }
    };
    return fit_accurate_start(lanes, [&](Block<double>& b) {
        polish<true, false, false, false, true>(monochromatic, spectrum_start_target_rtol, b);
    });
}

// The table's fitted start (null where none can be fitted: a rank-deficient fit, say, for a
// table whose MTF stays above the thresholds over most of the grid; its lanes then take the
// start scaled by where it falls to 1/2), from the last few tables fitted (by their exact knots
// and coefficients) or fitted now. Thread-safe.
inline std::shared_ptr<const FittedStart> lens_start_of(const MtfTable& table) {
    using Key = std::pair<std::vector<double>, std::vector<double>>;
    static RecentFits<Key, FittedStart> recent;
    return recent_fit(recent, Key{table.knots, table.coefficients}, [&] {
        return fit_if_possible<FittedStart>([&] { return fit_lens_start(table); });
    });
}

}  // namespace epc_fast
