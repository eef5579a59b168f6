// The submodule `testing`: single formulas and stages of the core, elementwise, so that the
// tests can hold the C++ against known values and the references (tests/), and the constants
// the benchmarks' Numba peer reads to run the core's algorithm (bench/peers). Not part of the
// package's interface (numpy's _umath_tests plays the same part).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "binding_support.h"
#include "epc_fast/block.h"
#include "epc_fast/elementary.h"
#include "epc_fast/exposure/point.h"
#include "epc_fast/f50/demosaic_fit.h"
#include "epc_fast/f50/guesses.h"
#include "epc_fast/f50/lens_fit.h"
#include "epc_fast/f50/spectrum_fit.h"
#include "epc_fast/mtf.h"
#include "epc_fast/scan/draws.h"
#include "epc_fast/scan/philox.h"
#include "epc_fast/scan/reductions.h"
#include "epc_fast/tabulated.h"
#include "register.h"

namespace epc_fast {
namespace bindings {

namespace {

// A fitted start's coefficients (rows x Terms) and fit errors, as the testing functions give them.
template <int Terms, class Start>
py::dict fitted_dict(const Start& start) {
    py::dict d;
    d["coefficients"] = py::array_t<double>(
        {static_cast<py::ssize_t>(detail::n_accurate_starts), static_cast<py::ssize_t>(Terms)},
        &start.coefficients[0][0]);
    d["fit_error"] = py::array_t<double>(static_cast<py::ssize_t>(detail::n_accurate_starts),
                                         start.fit_error);
    return d;
}

}  // namespace

void register_testing(py::module_& parent) {
    py::module_ m = parent.def_submodule(
        "testing", "Single formulas and stages of the core, for the tests and the benchmarks' peers.");
    m.def("stream_uniforms",
          // block by block, through the fused pass's own stream_uniforms (scan/philox.h); the tail
          // lanes of a partial last block repeat its last index, as form_points pads them
          [](std::uint64_t seed, std::uint32_t stream, const py::array_t<std::int64_t, py::array::c_style>& index) {
              const auto n = static_cast<std::size_t>(index.size());
              py::array_t<double> u(index.size());
              alignas(64) std::uint64_t points[block_size];
              alignas(64) double values[block_size];
              for (std::size_t first = 0; first < n; first += block_size) {
                  const std::size_t m = std::min(block_size, n - first);
                  for (std::size_t i = 0; i < block_size; ++i)
                      points[i] = static_cast<std::uint64_t>(index.data()[first + (i < m ? i : m - 1)]);
                  stream_uniforms(seed, stream, points, values);
                  std::copy(values, values + m, u.mutable_data() + first);
              }
              return u;
          },
          py::arg("seed"), py::arg("stream"), py::arg("index"));
    m.def("ndtri", py::vectorize([](double p) { return ndtri(p); }), py::arg("p"));
    // a table's lookup at every f (tabulated.h): the grid's segment and std::upper_bound's, the
    // interpolant and its derivatives lane by lane (`tabulated`) and in table_lanes' passes, and
    // the grid's cells and steps
    m.def(
        "table_lookup",
        [](const py::tuple& triple, const py::array_t<double, py::array::c_style | py::array::forcecast>& f) {
            const MtfTable t = table_of(triple);
            const py::ssize_t n = f.size();
            py::array_t<std::int32_t> grid(n), bound(n);
            py::array_t<double> lane(std::vector<py::ssize_t>{3, n}), lanes(std::vector<py::ssize_t>{3, n});
            const std::size_t m = t.knots.size() - 1;
            for (py::ssize_t i = 0; i < n; ++i) {
                const double x = f.data()[i];
                grid.mutable_data()[i] = table_segment(t, x);
                const auto upper = static_cast<std::size_t>(
                    std::upper_bound(t.knots.begin(), t.knots.end(), x) - t.knots.begin());
                bound.mutable_data()[i] = static_cast<std::int32_t>(upper == 0 ? 0 : (upper - 1 < m ? upper - 1 : m - 1));
                const TableValue v = tabulated(t, x);
                lane.mutable_at(0, i) = v.value;
                lane.mutable_at(1, i) = v.d1;
                lane.mutable_at(2, i) = v.d2;
            }
            for (py::ssize_t first = 0; first < n; first += static_cast<py::ssize_t>(block_size)) {
                const auto k = static_cast<std::size_t>(std::min<py::ssize_t>(block_size, n - first));
                table_lanes<block_size, true>(t, f.data() + first, k, lanes.mutable_data(0, first),
                                              lanes.mutable_data(1, first), lanes.mutable_data(2, first));
            }
            return py::make_tuple(grid, bound, lane, lanes, t.first_segment.size(), t.steps);
        },
        py::arg("table"), py::arg("f"));
    // the draws' block form of ndtri (scan/draws.h ndtri_block), block by block; the tail of the
    // last block is padded with 1/2
    m.def("ndtri_blocks",
          [](py::array_t<double, py::array::c_style | py::array::forcecast> p) {
              const py::ssize_t n = p.size();
              py::array_t<double> z(n);
              const double* in = p.data();
              double* out = z.mutable_data();
              for (py::ssize_t first = 0; first < n; first += static_cast<py::ssize_t>(block_size)) {
                  const auto m = static_cast<std::size_t>(std::min<py::ssize_t>(block_size, n - first));
                  alignas(64) double lanes[block_size], values[block_size];
                  for (std::size_t i = 0; i < block_size; ++i) lanes[i] = i < m ? in[first + static_cast<py::ssize_t>(i)] : 0.5;
                  ndtri_block(lanes, 1.0, values);
                  std::copy(values, values + m, out + first);
              }
              return z;
          },
          py::arg("p"));
    m.def("elementary_exp", py::vectorize([](double x) { return exp_any(x); }), py::arg("x"));
    // the draws' exp where its argument is bounded (elementary.h); NaN outside that bound
    m.def("elementary_exp_normal", py::vectorize([](double x) {
              return std::fabs(x) <= exp_normal_bound ? exp_normal(x) : std::numeric_limits<double>::quiet_NaN();
          }), py::arg("x"));
    m.def("elementary_log", py::vectorize([](double x) { return log_any(x); }), py::arg("x"));
    // the streamed quantiles' slot of each value (scan/folds.h octave_slot_of), as the
    // fused pass bins it
    m.def(
        "octave_slots",
        [](py::array_t<double, py::array::c_style | py::array::forcecast> values,
           std::int64_t first_key, std::int32_t bins, int shift) {
            Reduction r;
            r.kind = ReductionKind::quantiles;
            set_octave_bins(r, first_key, bins, shift);
            py::array_t<std::int32_t> slots(values.size());
            const double* v = values.data();
            std::int32_t* out = slots.mutable_data();
            for (py::ssize_t i = 0; i < values.size(); ++i)
                out[i] = static_cast<std::int32_t>(detail::octave_slot_of(r, v[i]));
            return slots;
        },
        py::arg("values"), py::arg("first_key"), py::arg("bins"), py::arg("shift"));
    // Single formulas, elementwise, so that tests can hold the C++ against known values.
    m.def("sinc", py::vectorize(&sinc<double>));
    m.def("mtf_diffraction", py::vectorize(&mtf_diffraction<double>), py::arg("nu"));
    m.def("mtf_binned_pixel", py::vectorize(&mtf_binned_pixel<double>), py::arg("f_cyc_per_mm"),
          py::arg("aperture_mm"), py::arg("pitch_mm"), py::arg("binning"));
    m.def("mtf_alignment", py::vectorize(&mtf_alignment<double>), py::arg("f_cyc_per_mm"),
          py::arg("alignment_error_mm"), py::arg("frames"));
    m.def("gaussian_blur_mm", py::vectorize(&gaussian_blur_mm), py::arg("jitter_um"),
          py::arg("alignment_error_um"), py::arg("frames"));
    m.def("signal_electrons",
          py::vectorize([](double rate, double snr_db, double read, double dark, double prnu) {
              return signal_electrons(rate, SnrTarget(snr_db), read, dark, prnu);
          }));
    m.def("signal_electrons_brent",
          py::vectorize([](double rate, double snr_db, double read, double dark, double prnu,
                           double rtol) {
              return signal_electrons_brent(rate, SnrTarget(snr_db), read, dark, prnu, rtol);
          }));
    m.def("f50_start", py::vectorize(&detail::f50_start), py::arg("lambda_f_mm"),
          py::arg("aperture_mm"), py::arg("blur_mm"), py::arg("jitter_mm"),
          py::arg("mtf_threshold"));
    m.def("f50_cubic_start", py::vectorize(&detail::f50_cubic_start), py::arg("lambda_f_mm"),
          py::arg("aperture_mm"), py::arg("blur_mm"), py::arg("jitter_mm"),
          py::arg("mtf_threshold"));
    // A spectrum's fitted start (f50/spectrum_fit.h): its coefficients and fit errors (None where
    // none can be fitted), and the start a polychromatic float64 lane without jitter takes
    // (lambda_f_mm with the spectrum's mean wavelength; the cubic start for a threshold without
    // a row or a spectrum without a fit).
    m.def(
        "spectrum_start",
        [](const double_array& wavelengths_nm, const double_array& weights) -> py::object {
            const auto start = spectrum_start_of(spectrum_of(wavelengths_nm, weights));
            if (start == nullptr) return py::none();
            return fitted_dict<detail::accurate_start_terms>(*start);
        },
        py::arg("wavelengths_nm"), py::arg("weights"));
    // A lens table's fitted start (f50/lens_fit.h): its coefficients, fit errors and the table's
    // half (None where none can be fitted), from the (knots, values, coefficients) triple
    // evaluate takes.
    m.def(
        "lens_start",
        [](const py::object& triple) -> py::object {
            const MtfTable table = table_of(triple);
            const auto start = lens_start_of(table);
            if (start == nullptr) return py::none();
            py::dict d = fitted_dict<detail::accurate_start_terms>(*start);
            d["half"] = table.half;  // the start's optics length is nu50 / half
            return d;
        },
        py::arg("table"));
    // A demosaicker's fitted start (f50/demosaic_fit.h): its coefficients, fit errors and X_pi
    // (None where none can be fitted), from the (knots, values, coefficients) triple evaluate
    // takes, and the start a full-resolution lane takes from it.
    m.def(
        "pixel_start",
        [](const py::object& triple) -> py::object {
            const auto start = pixel_start_of(table_of(triple));
            if (start == nullptr) return py::none();
            py::dict d = fitted_dict<pixel_start_terms>(*start);
            d["x50"] = start->x50;
            return d;
        },
        py::arg("table"));
    m.def(
        "f50_pixel_start",
        [](const py::object& triple, const double_array& lambda_f_mm, const double_array& pitch_mm,
           const double_array& blur_mm, const double_array& mtf_threshold) {
            const auto start = pixel_start_of(table_of(triple));
            if (start == nullptr) throw std::invalid_argument("no start can be fitted to this table");
            auto one = [&start](double lambda_f, double pitch, double blur, double threshold) {
                const int row = int{detail::accurate_start_code(0.0, threshold)} - 1;
                return row < 0 ? std::nan("")
                               : detail::pixel_start_guess(start->coefficients[row], start->x50,
                                                           lambda_f, pitch, blur);
            };
            return py::vectorize(one)(lambda_f_mm, pitch_mm, blur_mm, mtf_threshold);
        },
        py::arg("table"), py::arg("lambda_f_mm"), py::arg("pitch_mm"), py::arg("blur_mm"),
        py::arg("mtf_threshold"));
    m.def(
        "f50_spectrum_start",
        [](const double_array& wavelengths_nm, const double_array& weights,
           const double_array& lambda_f_mm, const double_array& aperture_mm,
           const double_array& blur_mm, const double_array& mtf_threshold) {
            const auto start = spectrum_start_of(spectrum_of(wavelengths_nm, weights));
            auto one = [&start](double lambda_f, double aperture, double blur, double threshold) {
                const int row = int{detail::accurate_start_code(0.0, threshold)} - 1;
                return row < 0 || start == nullptr ? detail::f50_cubic_start(lambda_f, aperture, blur, 0.0, threshold)
                               : detail::fitted_start_guess(start->coefficients[row], lambda_f,
                                                              aperture, blur);
            };
            return py::vectorize(one)(lambda_f_mm, aperture_mm, blur_mm, mtf_threshold);
        },
        py::arg("wavelengths_nm"), py::arg("weights"), py::arg("lambda_f_mm"),
        py::arg("aperture_mm"), py::arg("blur_mm"), py::arg("mtf_threshold"));
    // The accurate starts' polynomials (f50/guesses.h): one row of coefficients per threshold of
    // accurate_start_thresholds, for the tests and the benchmarks' Numba peer that runs the
    // core's algorithm.
    m.attr("accurate_start_degree") = detail::accurate_start_degree;
    m.attr("accurate_start_thresholds") = py::array_t<double>(
        static_cast<py::ssize_t>(detail::n_accurate_starts), detail::accurate_start_thresholds);
    m.attr("accurate_start_coefficients") = py::array_t<double>(
        {static_cast<py::ssize_t>(detail::n_accurate_starts),
         static_cast<py::ssize_t>(detail::accurate_start_terms)},
        &detail::accurate_start_coefficients[0][0]);
    // Each start row's certified error (the thresholds' rows, then the jitter start's), within
    // which Halley and Newton take the start as f50: for the tests that check it.
    m.attr("certified_start_error") = py::array_t<double>(
        static_cast<py::ssize_t>(detail::n_start_rows), detail::certified_start_error);
}

}  // namespace bindings
}  // namespace epc_fast
