// lux_for_epc and crossover_lux (inverse.h): the illuminance at which each design reaches a
// target EPC, or two designs have equal EPC, solved block by block with the GIL released.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "binding_support.h"
#include "epc_fast/inverse.h"
#include "register.h"

namespace epc_fast {
namespace bindings {

namespace {

InverseOptions inverse_options_of(double lux_lo, double lux_hi, double rtol, int grid_points) {
    if (!(lux_lo > 0.0) || !(lux_hi > lux_lo) || !std::isfinite(lux_hi))
        throw std::invalid_argument("the illuminance range must satisfy 0 < lux_lo < lux_hi < inf");
    if (!(rtol >= 0.0)) throw std::invalid_argument("rtol must be >= 0");
    if (grid_points < 2) throw std::invalid_argument("grid_points must be >= 2");
    InverseOptions inv;
    inv.lux_lo = lux_lo;
    inv.lux_hi = lux_hi;
    inv.rtol = rtol;
    inv.grid_points = grid_points;
    return inv;
}

// A design's f50 across the motion (cycles/mm; one value or n), or a null column for None.
Column across_of(const py::object& f50_across, py::ssize_t n) {
    return f50_across.is_none() ? Column{} : column_of(f50_across, -1, n);
}

struct InverseResult {
    py::array_t<double> illuminance_lux, epc;
    py::array_t<std::uint8_t> status;

    explicit InverseResult(py::ssize_t n) : illuminance_lux(n), epc(n), status(n) {}
    InverseOutputs outputs() {
        return InverseOutputs{illuminance_lux.mutable_data(), epc.mutable_data(), status.mutable_data()};
    }
    py::dict dict() const {
        py::dict d;
        d["illuminance_lux"] = illuminance_lux;
        d["epc"] = epc;
        d["status"] = status;
        return d;
    }
};

py::dict lux_for_epc_py(const py::list& columns, bool size_is_pixel_count,
                        const double_array& domains, const double_array& wavelengths_nm,
                        const double_array& weights, py::ssize_t n, const py::object& target_epc,
                        double lux_lo, double lux_hi, double rtol, double f50_rtol, int threads,
                        const py::object& demosaic_table, const py::object& f50_across) {
    Inputs in = inputs_of(columns, size_is_pixel_count, domains, wavelengths_nm, weights, n);
    set_demosaic_table(in, demosaic_table);
    const Column target = column_of(target_epc, -1, n);
    const Column across = across_of(f50_across, n);
    const Options opt = options_of("halley", f50_rtol, "closed_form", 0.0);
    const InverseOptions inv = inverse_options_of(lux_lo, lux_hi, rtol, 2);
    InverseResult result(n);
    const InverseOutputs out = result.outputs();
    run_chunked(n, 1 << 14, threads, [&](std::size_t start, std::size_t stop) {
        lux_for_epc(in, across, target, opt, inv, out, start, stop, threads);
    });
    return result.dict();
}

py::dict crossover_lux_py(const py::list& columns_a, const py::list& columns_b,
                          bool size_is_pixel_count_a, bool size_is_pixel_count_b,
                          const double_array& domains, const double_array& wavelengths_nm,
                          const double_array& weights, py::ssize_t n, double lux_lo,
                          double lux_hi, int grid_points, double rtol, double f50_rtol,
                          int threads, const py::object& demosaic_table_a,
                          const py::object& demosaic_table_b, const py::object& f50_across_a,
                          const py::object& f50_across_b) {
    Inputs a = inputs_of(columns_a, size_is_pixel_count_a, domains, wavelengths_nm, weights, n);
    Inputs b = inputs_of(columns_b, size_is_pixel_count_b, domains, wavelengths_nm, weights, n);
    set_demosaic_table(a, demosaic_table_a);
    set_demosaic_table(b, demosaic_table_b);
    const Column across_a = across_of(f50_across_a, n), across_b = across_of(f50_across_b, n);
    const Options opt = options_of("halley", f50_rtol, "closed_form", 0.0);
    const InverseOptions inv = inverse_options_of(lux_lo, lux_hi, rtol, grid_points);
    InverseResult result(n);
    const InverseOutputs out = result.outputs();
    run_chunked(n, 1 << 12, threads, [&](std::size_t start, std::size_t stop) {
        crossover_lux(a, across_a, b, across_b, opt, inv, out, start, stop, threads);
    });
    return result.dict();
}

}  // namespace

void register_inverse(py::module_& m) {
    m.def("lux_for_epc", &lux_for_epc_py, py::arg("columns"), py::arg("size_is_pixel_count"),
          py::arg("domains"), py::arg("wavelengths_nm"), py::arg("weights"), py::arg("n"),
          py::arg("target_epc"), py::arg("lux_lo"), py::arg("lux_hi"), py::arg("rtol"),
          py::arg("f50_rtol"), py::arg("threads"), py::arg("demosaic_table") = py::none(),
          py::arg("f50_across") = py::none(),
          "Illuminance at which each design reaches target_epc (Brent on ln L).");
    m.def("crossover_lux", &crossover_lux_py, py::arg("columns_a"), py::arg("columns_b"),
          py::arg("size_is_pixel_count_a"), py::arg("size_is_pixel_count_b"), py::arg("domains"),
          py::arg("wavelengths_nm"), py::arg("weights"), py::arg("n"), py::arg("lux_lo"),
          py::arg("lux_hi"), py::arg("grid_points"), py::arg("rtol"), py::arg("f50_rtol"),
          py::arg("threads"), py::arg("demosaic_table_a") = py::none(),
          py::arg("demosaic_table_b") = py::none(), py::arg("f50_across_a") = py::none(),
          py::arg("f50_across_b") = py::none(),
          "Highest illuminance in [lux_lo, lux_hi] where designs a and b have equal EPC.");
}

}  // namespace bindings
}  // namespace epc_fast
