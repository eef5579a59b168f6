// evaluate: NumPy columns in, the kernel (kernel.h) run over them chunk by chunk with the GIL
// released, and the output arrays asked for (the caller's, or new ones) handed back.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "binding_support.h"
#include "epc_fast/kernel.h"
#include "epc_fast/modes.h"
#include "register.h"

namespace epc_fast {
namespace bindings {

namespace {

// Calls (chunks) of fewer points than this write their fresh outputs without first_touch: a
// float64 column of them spans at most a quarter of a 2 MiB huge page.
constexpr std::size_t first_touch_points = std::size_t{1} << 16;

constexpr const char* output_names[] = {"electron_rate_e_per_s", "electrons", "t_mpe_s",
                                        "blur_mm", "f50_cyc_per_mm", "epc", "status", "cause"};
// The f50 across the motion (kernel.h across_f50), computed only when named.
constexpr const char* across_name = "f50_across_cyc_per_mm";
// The outputs computed only when named (sensitivity.h): the shares, in Share's order, and
// the elasticities: parameter j's as "elasticity_" + param_names[j], or all of them as
// "elasticities", n_params rows of n points in one array (row j parameter j's).
constexpr const char* share_names[] = {"share_diffraction", "share_pixel", "share_motion",
                                       "share_jitter", "share_alignment", "share_aberration",
                                       "share_denoise", "share_lens", "share_demosaic"};

constexpr const char* elasticity_prefix = "elasticity_";
constexpr const char* elasticities_name = "elasticities";

// How many values output `name` holds for n points.
py::ssize_t output_size(const std::string& name, py::ssize_t n) {
    return name == elasticities_name ? n * n_params : n;
}

// The parameter whose elasticity output `name` is, or -1.
int elasticity_of(const std::string& name) {
    const std::size_t length = std::strlen(elasticity_prefix);
    if (name.compare(0, length, elasticity_prefix) != 0) return -1;
    for (int j = 0; j < n_params; ++j)
        if (name.compare(length, std::string::npos, param_names[j]) == 0) return j;
    return -1;
}

bool is_output_name(const std::string& name) {
    auto in = [&](const auto& names) {
        return std::find(std::begin(names), std::end(names), name) != std::end(names);
    };
    return in(output_names) || in(share_names) || name == elasticities_name ||
           name == across_name || elasticity_of(name) >= 0;
}

// The output dict of one call: `out`'s arrays (a dict, or None for none) and new arrays for
// the outputs named in `allocate` (None: every output when `out` is None, else none). `fresh`
// gets those of the new arrays whose pages are new.
py::dict outputs_of(const py::object& out, const py::object& allocate, py::ssize_t n,
                    py::dict& fresh) {
    py::dict result;
    if (!out.is_none()) {
        if (!py::isinstance<py::dict>(out)) throw std::invalid_argument("out must be a dict or None");
        for (auto item : py::reinterpret_borrow<py::dict>(out)) result[item.first] = item.second;
    }
    std::vector<std::string> names;
    if (!allocate.is_none()) {
        for (auto name : allocate) {
            if (!py::isinstance<py::str>(name)) throw py::type_error("allocate must hold output names");
            names.push_back(py::cast<std::string>(name));
        }
    } else if (out.is_none()) {
        names.assign(std::begin(output_names), std::end(output_names));
    }
    for (const std::string& name : names) {
        const bool known = is_output_name(name);
        if (!known || result.contains(name))
            throw std::invalid_argument("allocate: '" + name + "' is " +
                                        (known ? "in out already" : "not an output"));
        bool is_fresh = false;
        py::array array = name == "status" || name == "cause"
                              ? new_column<std::uint8_t>(n, is_fresh)
                              : new_column<double>(output_size(name, n), is_fresh);
        result[name.c_str()] = array;
        if (is_fresh) fresh[name.c_str()] = array;
    }
    return result;
}

// The kernel's view of `arrays` (output name -> array): null for the outputs it lacks. One pass
// over the dict, its names read in place (keys that are not output names are left alone).
Outputs outputs_in(const py::dict& arrays, py::ssize_t n) {
    Outputs out{nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
    double** values[] = {&out.electron_rate_e_per_s, &out.electrons, &out.t_mpe_s, &out.blur_mm,
                         &out.f50_cyc_per_mm, &out.epc};
    double* every = nullptr;
    const char* single = nullptr;  // an elasticity asked for one by one
    for (auto item : arrays) {
        if (!PyUnicode_Check(item.first.ptr())) continue;
        const char* name = PyUnicode_AsUTF8(item.first.ptr());
        if (name == nullptr) throw py::error_already_set();
        const auto is = [name](const char* other) { return std::strcmp(name, other) == 0; };
        bool found = false;
        for (int k = 0; k < 6 && !found; ++k)
            if ((found = is(output_names[k]))) *values[k] = output_array<double>(item.second, name, n);
        if (found) continue;
        if (is(output_names[6])) {
            out.status = output_array<std::uint8_t>(item.second, name, n);
        } else if (is(output_names[7])) {
            out.cause = output_array<std::uint8_t>(item.second, name, n);
        } else if (is(across_name)) {
            out.f50_across_cyc_per_mm = output_array<double>(item.second, name, n);
        } else if (is(elasticities_name)) {
            every = output_array<double>(item.second, name, output_size(elasticities_name, n));
        } else {
            for (int k = 0; k < n_shares && !found; ++k)
                if ((found = is(share_names[k])))
                    out.sensitivity.share[k] = output_array<double>(item.second, name, n);
            const int j = found ? -1 : elasticity_of(name);
            if (j >= 0) {
                out.sensitivity.elasticity[j] = output_array<double>(item.second, name, n);
                single = name;
            }
        }
    }
    if (every != nullptr && single != nullptr)
        throw std::invalid_argument(std::string("out has both 'elasticities' (every elasticity) and '") +
                                    single + "'");
    if (every != nullptr)
        for (int j = 0; j < n_params; ++j) out.sensitivity.elasticity[j] = every + j * n;
    return out;
}

py::dict evaluate_py(const py::list& columns, bool size_is_pixel_count, const double_array& domains,
                     const double_array& wavelengths_nm, const double_array& weights, py::ssize_t n,
                     const std::string& f50_solver, double f50_rtol,
                     const std::string& t_mpe_solver, double t_mpe_rtol,
                     const std::string& precision, int threads, py::ssize_t chunk_points,
                     const py::object& out, const py::object& allocate,
                     const py::object& lens_tables, const py::object& demosaic_table,
                     bool epc_both, const py::object& modes) {
    Inputs in = inputs_of(columns, size_is_pixel_count, domains, wavelengths_nm, weights, n);
    set_lens_tables(in, lens_tables);
    set_demosaic_table(in, demosaic_table);
    const Options opt = options_of(f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision);
    py::dict fresh;
    py::dict result = outputs_of(out, allocate, n, fresh);
    // A large call's outputs are written with streaming stores (stream.h)
    Outputs outputs = streaming_for(outputs_in(result, n), static_cast<std::size_t>(n));
    outputs.epc_both = epc_both;
    if ((outputs.f50_across_cyc_per_mm != nullptr || epc_both) && outputs.sensitivity.any())
        throw std::invalid_argument("the f50 across the motion and EPC in both directions are "
                                    "computed without shares or elasticities");
    const std::vector<OutputBytes> written = output_bytes_of(result);
    check_apart(written);
    std::vector<std::vector<double>> copies;  // the inputs that are outputs too, as they were
    copy_overlapping(in, n, written, copies);
    // New pages are faulted in on all threads first (first_touch), except at sizes where they
    // are too few to matter; the cache's kept blocks and the caller's arrays are mapped already.
    const Outputs untouched = outputs_in(fresh, n);
    const bool touch = !fresh.empty() && threads > 1;
    if (!modes.is_none()) {  // every mode of each block, its best kept (modes.h)
        std::vector<ReadoutMode> values = readout_modes_of(modes);
        const std::vector<Inputs> each = mode_inputs(in, values);
        py::array_t<std::int16_t> picked(n);
        std::int16_t* mode = picked.mutable_data();
        outputs.stream = false;
        run_chunked(n, chunk_points, threads, [&](std::size_t start, std::size_t stop) {
            if (touch && stop - start >= first_touch_points) first_touch(untouched, start, stop, threads);
            evaluate_modes(each, opt, outputs, mode, start, stop, threads);
        });
        result["mode"] = picked;
        return result;
    }
    run_chunked(n, chunk_points, threads, [&](std::size_t start, std::size_t stop) {
        if (touch && stop - start >= first_touch_points) first_touch(untouched, start, stop, threads);
        evaluate(in, opt, outputs, start, stop, threads);
    });
    return result;
}

// evaluate's model parameters as float64 arrays and the set of their shapes but (), as
// epc_fast._validation.float_arrays documents: a Python float found in `kept` (float -> its
// read-only 0-d array) and a native float64 ndarray taken as they are, every other value (and
// -0.0, which finds 0.0's entry) handed to `convert(name, value)`, which checks it.
py::tuple float_arrays_py(const py::tuple& names, const py::tuple& values, const py::dict& kept,
                          const py::function& convert) {
    if (names.size() != values.size()) throw std::invalid_argument("names and values differ in length");
    const auto& api = py::detail::npy_api::get();
    py::list arrays(values.size());
    py::set shapes;
    bool contiguous = true;  // every array of one or more dimensions C-contiguous
    for (std::size_t j = 0; j < values.size(); ++j) {
        PyObject* value = PyTuple_GET_ITEM(values.ptr(), static_cast<py::ssize_t>(j));
        if (PyFloat_CheckExact(value)) {
            const double x = PyFloat_AS_DOUBLE(value);
            PyObject* hit = x == 0.0 && std::signbit(x) ? nullptr : PyDict_GetItemWithError(kept.ptr(), value);
            if (hit == nullptr && PyErr_Occurred() != nullptr) throw py::error_already_set();
            arrays[j] = hit != nullptr ? py::reinterpret_borrow<py::object>(hit)
                                       : convert(names[j], py::handle(value));
            continue;
        }
        py::object array = py::reinterpret_borrow<py::object>(value);
        bool is_float64 = false;
        if (Py_TYPE(value) == api.PyArray_Type_) {  // an ndarray, not a subclass (a masked array)
            const auto* descr = py::detail::array_descriptor_proxy(py::detail::array_proxy(value)->descr);
            is_float64 = descr->type_num == py::detail::npy_api::NPY_DOUBLE_ && descr->byteorder == '=';
        }
        if (!is_float64) array = convert(names[j], array);
        if (!api.PyArray_Check_(array.ptr()))
            throw py::type_error("convert must return NumPy arrays");
        const auto* proxy = py::detail::array_proxy(array.ptr());
        if (proxy->nd > 0) {
            shapes.add(array.attr("shape"));
            contiguous &= (proxy->flags & py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_) != 0;
        }
        arrays[j] = array;
    }
    return py::make_tuple(arrays, shapes, contiguous);
}

}  // namespace

void register_evaluate(py::module_& m) {
    m.attr("n_params") = static_cast<int>(n_params);
    py::tuple parameter_names(static_cast<std::size_t>(n_params));
    for (int j = 0; j < n_params; ++j) parameter_names[j] = param_names[j];
    m.attr("parameter_names") = parameter_names;
    m.def("float_arrays", &float_arrays_py, py::arg("names"), py::arg("values"), py::arg("kept"),
          py::arg("convert"),
          "(arrays, shapes, contiguous): the model parameters `values` as float64 arrays, as "
          "epc_fast._validation.float_arrays documents.");
    m.def("evaluate", &evaluate_py, py::arg("columns"), py::arg("size_is_pixel_count"),
          py::arg("domains"), py::arg("wavelengths_nm"), py::arg("weights"), py::arg("n"),
          py::arg("f50_solver"), py::arg("f50_rtol"), py::arg("t_mpe_solver"), py::arg("t_mpe_rtol"),
          py::arg("precision"), py::arg("threads"),
          py::arg("chunk_points"), py::arg("out") = py::none(), py::arg("allocate") = py::none(),
          py::arg("lens_tables") = py::none(),
          py::arg("demosaic_table") = py::none(), py::arg("epc_both") = false,
          py::arg("modes") = py::none(),
          "Evaluates the model into the arrays of `out` (a dict of output arrays, or None) and "
          "new arrays for the outputs named in `allocate` (None: all of them when out is None, "
          "else none); only these outputs are computed. Returns the dict of them all. "
          "'f50_across_cyc_per_mm' is the f50 without the motion blur; epc_both counts EPC "
          "(and the status) in both directions; neither with shares or elasticities. `modes`: "
          "(binning, binning_readout, frames, alignment_error_um) per readout mode; each point "
          "then takes the outputs of its mode with the largest finite EPC, and 'mode' (int16, "
          "-1 where no mode has one) is added.");
}

}  // namespace bindings
}  // namespace epc_fast
