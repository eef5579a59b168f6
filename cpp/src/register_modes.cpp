// Readout modes' pick (modes.h): the best mode of every point from the modes' EPCs, and any
// output gathered by it, for python/epc_fast/modes.py.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "binding_support.h"
#include "epc_fast/modes.h"
#include "register.h"

namespace epc_fast {
namespace bindings {

namespace {

using mode_array = py::array_t<std::int16_t, py::array::c_style>;

// The 1-d C-contiguous arrays of `arrays`, each of n items of `dtype` (a ValueError otherwise),
// as pointers to their data.
std::vector<const void*> columns_of(const py::list& arrays, const py::dtype& dtype, py::ssize_t n,
                                    const char* what) {
    std::vector<const void*> data;
    for (const py::handle item : arrays) {
        const auto a = py::reinterpret_borrow<py::array>(item);
        if (a.ndim() != 1 || a.size() != n || !a.dtype().is(dtype) ||
            !(a.flags() & py::array::c_style))
            throw std::invalid_argument(std::string(what) + ": one C-contiguous 1-d array of " +
                                        std::to_string(n) + " items per mode, all of one dtype");
        data.push_back(a.data());
    }
    if (data.empty() || data.size() > 32767)
        throw std::invalid_argument(std::string(what) + ": between 1 and 32767 modes");
    return data;
}

mode_array best_mode_py(const py::list& epcs, int threads) {
    if (epcs.empty()) throw std::invalid_argument("epcs: between 1 and 32767 modes");
    const py::ssize_t n = py::reinterpret_borrow<py::array>(epcs[0]).size();
    const std::vector<const void*> columns = columns_of(epcs, py::dtype::of<double>(), n, "epcs");
    std::vector<const double*> epc;
    for (const void* c : columns) epc.push_back(static_cast<const double*>(c));
    mode_array mode(n);
    std::int16_t* out = mode.mutable_data();
    {
        py::gil_scoped_release release;
        best_modes(epc, out, static_cast<std::size_t>(n), threads);
    }
    return mode;
}

py::array take_mode_py(const mode_array& mode, const py::list& values, int threads) {
    if (values.empty()) throw std::invalid_argument("values: between 1 and 32767 modes");
    const py::ssize_t n = mode.size();
    const py::dtype dtype = py::reinterpret_borrow<py::array>(values[0]).dtype();
    const py::ssize_t item = dtype.itemsize();
    if (!(item == 1 || item == 2 || item == 4 || item == 8))
        throw std::invalid_argument("values: items of 1, 2, 4 or 8 bytes");
    const std::vector<const void*> columns = columns_of(values, dtype, n, "values");
    const std::int16_t* m = mode.data();
    for (py::ssize_t i = 0; i < n; ++i)
        if (m[i] >= static_cast<std::int16_t>(columns.size()))
            throw std::invalid_argument("mode: an index past the modes given");
    py::array out(dtype, std::vector<py::ssize_t>{n});
    void* to = out.mutable_data();
    {
        py::gil_scoped_release release;
        take_modes(m, columns, static_cast<std::size_t>(item), to, static_cast<std::size_t>(n), threads);
    }
    return out;
}

}  // namespace

void register_modes(py::module_& m) {
    m.def("best_mode", &best_mode_py, py::arg("epcs"), py::arg("threads"),
          "int16 array: per point the first mode with the largest finite EPC among the modes' "
          "float64 arrays `epcs` (1-d, one length), -1 where none is finite.");
    m.def("take_mode", &take_mode_py, py::arg("mode"), py::arg("values"), py::arg("threads"),
          "values[mode[i]][i] for every point (the first mode's where mode is -1), from one "
          "1-d array per mode of one dtype.");
}

}  // namespace bindings
}  // namespace epc_fast
