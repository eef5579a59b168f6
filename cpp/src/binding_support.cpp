// The definitions of binding_support.h's functions.
#include "binding_support.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "epc_fast/f50/demosaic_fit.h"
#include "epc_fast/f50/lens_fit.h"
#include "epc_fast/f50/spectrum_fit.h"
#include "epc_fast/output_cache.h"
#include "epc_fast/params.h"
#include "epc_fast/scan/reductions.h"

namespace epc_fast {
namespace bindings {

Column column_of(const py::handle& obj, int index, py::ssize_t n) {
    // The common case read off NumPy's array struct: a native float64 C-contiguous array of 1 or
    // n values. Anything else, errors included, takes the checks below.
    if (py::detail::npy_api::get().PyArray_Check_(obj.ptr())) {
        const auto* arr = py::detail::array_proxy(obj.ptr());
        const auto* descr = py::detail::array_descriptor_proxy(arr->descr);
        if (descr->type_num == py::detail::npy_api::NPY_DOUBLE_ && descr->byteorder == '=' &&
            (arr->flags & py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_) != 0) {
            py::ssize_t size = 1;
            for (int k = 0; k < arr->nd; ++k) size *= arr->dimensions[k];
            if (size == 1 || size == n)
                return Column{reinterpret_cast<const double*>(arr->data), size == 1 ? 0 : 1};
        }
    }
    const std::string what = index < 0 ? "target_epc" : "column " + std::to_string(index);
    if (!py::isinstance<py::array>(obj)) throw std::invalid_argument(what + " is not an ndarray");
    auto arr = py::reinterpret_borrow<py::array>(obj);
    // Equivalence, not identity: an unpickled array carries an equal but distinct dtype object.
    // Any number of dimensions, read flat in C order: a 0-d array is a broadcast scalar.
    if (!py::isinstance<py::array_t<double, py::array::c_style>>(arr) ||
        !(arr.flags() & py::array::c_style))
        throw std::invalid_argument(what + " must be a C-contiguous float64 array");
    if (arr.size() != 1 && arr.size() != n)
        throw std::invalid_argument(what + " has " + std::to_string(arr.size()) +
                                    " values, expected 1 or " + std::to_string(n));
    return Column{static_cast<const double*>(arr.data()), arr.size() == 1 ? 0 : 1};
}

std::vector<OutputBytes> output_bytes_of(const py::dict& outputs) {
    std::vector<OutputBytes> ranges;
    for (auto item : outputs) {
        if (!py::isinstance<py::array>(item.second)) continue;  // outputs_in names these
        const auto arr = py::reinterpret_borrow<py::array>(item.second);
        const char* data = static_cast<const char*>(arr.data());
        ranges.push_back(OutputBytes{item.first, data, data + arr.nbytes()});
    }
    return ranges;
}

namespace {

bool overlap(const char* begin, const char* end, const OutputBytes& range) {
    return begin < range.end && range.begin < end;
}

}  // namespace

void check_apart(const std::vector<OutputBytes>& outputs) {
    for (std::size_t a = 0; a < outputs.size(); ++a)
        for (std::size_t b = a + 1; b < outputs.size(); ++b)
            if (overlap(outputs[a].begin, outputs[a].end, outputs[b]))
                throw std::invalid_argument("out['" + py::str(outputs[a].name).cast<std::string>() +
                                            "'] and out['" + py::str(outputs[b].name).cast<std::string>() +
                                            "'] share memory");
}

void copy_overlapping(Inputs& in, py::ssize_t n, const std::vector<OutputBytes>& outputs,
                      std::vector<std::vector<double>>& copies) {
    for (Column& column : in.columns) {
        const auto size = column.stride == 0 ? py::ssize_t{1} : n;
        const char* begin = reinterpret_cast<const char*>(column.data);
        const char* end = begin + size * static_cast<py::ssize_t>(sizeof(double));
        if (std::none_of(outputs.begin(), outputs.end(),
                         [&](const OutputBytes& range) { return overlap(begin, end, range); }))
            continue;
        copies.emplace_back(column.data, column.data + size);
        column.data = copies.back().data();
    }
}

namespace {

TMpeSolver solver_of(const std::string& name) {
    if (name == "closed_form") return TMpeSolver::closed_form;
    if (name == "brent") return TMpeSolver::brent;
    throw std::invalid_argument("t_mpe_solver must be 'closed_form' or 'brent', got '" + name + "'");
}

F50Solver f50_solver_of(const std::string& name) {
    if (name == "halley") return F50Solver::halley;
    if (name == "newton") return F50Solver::newton;
    if (name == "brent") return F50Solver::brent;
    if (name == "bisection") return F50Solver::bisection;
    throw std::invalid_argument(
        "f50_solver must be 'halley', 'newton', 'brent' or 'bisection', got '" + name + "'");
}

Precision precision_of(const std::string& name) {
    if (name == "float64") return Precision::float64;
    if (name == "float32") return Precision::float32;
    throw std::invalid_argument("precision must be 'float64' or 'float32', got '" + name + "'");
}

}  // namespace

Spectrum spectrum_of(const double_array& wavelengths_nm, const double_array& weights) {
    if (wavelengths_nm.size() != weights.size() || wavelengths_nm.size() == 0)
        throw std::invalid_argument("wavelengths_nm and weights must be non-empty and of one length");
    Spectrum spectrum;
    spectrum.wavelengths_nm.assign(wavelengths_nm.data(), wavelengths_nm.data() + wavelengths_nm.size());
    spectrum.weights.assign(weights.data(), weights.data() + weights.size());
    for (std::size_t k = 0; k < spectrum.weights.size(); ++k)
        if (!(spectrum.wavelengths_nm[k] > 0.0 && std::isfinite(spectrum.wavelengths_nm[k]) &&
              spectrum.weights[k] >= 0.0 && std::isfinite(spectrum.weights[k])))
            throw std::invalid_argument("wavelengths_nm must be positive and weights non-negative, finite");
    if (!(spectrum.extent().mean_nm > 0.0))
        throw std::invalid_argument("the weights must not all be 0");
    // the kernel's MTF is the weighted sum itself: weights that do not sum to 1 would scale it
    // (epc_fast.Spectrum divides them by their sum, which leaves an error of a few ulp)
    double total = 0.0;
    for (const double w : spectrum.weights) total += w;
    if (!(std::fabs(total - 1.0) <= 1e-9))
        throw std::invalid_argument("weights must sum to 1 (epc_fast.Spectrum normalises them), got sum " +
                                    py::repr(py::float_(total)).cast<std::string>());
    return spectrum;
}

Inputs inputs_of(const py::list& columns, bool size_is_pixel_count, const double_array& domains,
                 const double_array& wavelengths_nm, const double_array& weights, py::ssize_t n) {
    if (static_cast<int>(columns.size()) != n_params)
        throw std::invalid_argument("expected " + std::to_string(n_params) + " columns");
    if (domains.ndim() != 2 || domains.shape(0) != n_params || domains.shape(1) != 5)
        throw std::invalid_argument("domains must have shape (n_params, 5)");
    if (wavelengths_nm.size() != weights.size())
        throw std::invalid_argument("wavelengths_nm and weights differ in length");
    if (n < 0) throw std::invalid_argument("n must be >= 0");
    Inputs in;
    in.size_is_pixel_count = size_is_pixel_count;
    auto d = domains.unchecked<2>();
    for (int j = 0; j < n_params; ++j) {
        in.columns[j] = column_of(columns[j], j, n);
        in.domains[j] = Domain{d(j, 0), d(j, 1), d(j, 2) != 0.0, d(j, 3) != 0.0, d(j, 4) != 0.0};
    }
    if (wavelengths_nm.size() != 0) {  // none: monochromatic at each point's wavelength
        in.spectrum = spectrum_of(wavelengths_nm, weights);
        in.spectrum.start = spectrum_start_of(in.spectrum);
    }
    return in;
}

// One table from its (knots, values, coefficients) triple, checked.
MtfTable table_of(const py::handle& item) {
    const auto triple = py::reinterpret_borrow<py::tuple>(item);
    if (triple.size() != 3) throw std::invalid_argument("an MTF table is (knots, values, coefficients)");
    const auto knots = py::cast<double_array>(triple[0]);
    const auto values = py::cast<double_array>(triple[1]);
    const auto coefficients = py::cast<double_array>(triple[2]);
    const py::ssize_t m = knots.size();
    if (knots.ndim() != 1 || m < 2 || values.size() != m || coefficients.size() != 4 * (m - 1))
        throw std::invalid_argument("an MTF table needs knots and values of one length >= 2 and "
                                    "4 coefficients per segment");
    MtfTable t;
    t.knots.assign(knots.data(), knots.data() + m);
    t.coefficients.assign(coefficients.data(), coefficients.data() + 4 * (m - 1));
    t.last_value = values.data()[m - 1];
    for (py::ssize_t k = 0; k < m; ++k)
        if (!(std::isfinite(t.knots[k]) && (k == 0 ? t.knots[k] == 0.0 : t.knots[k] > t.knots[k - 1])))
            throw std::invalid_argument("an MTF table's knots must rise strictly from 0");
    finish_table(t);
    return t;
}


void set_demosaic_table(Inputs& in, const py::object& table) {
    in.demosaic = table.is_none() ? MtfTable{} : table_of(table);
    // f50's start fitted to it (f50/demosaic_fit.h)
    if (!table.is_none()) in.demosaic.pixel_start = pixel_start_of(in.demosaic);
}

void set_lens_tables(Inputs& in, const py::object& tables) {
    in.lens_tables.clear();
    if (tables.is_none()) return;
    for (const py::handle item : tables) {
        MtfTable table = table_of(item);
        table.start = lens_start_of(table);  // f50's start fitted to it (f50/lens_fit.h)
        in.lens_tables.push_back(std::move(table));
    }
    if (in.lens_tables.empty()) throw std::invalid_argument("lens tables: give at least one, or None");
    in.domains[wavefront_rms_waves] = Domain{0.0, 0.0, true, true, false};
}

std::vector<ReadoutMode> readout_modes_of(const py::object& modes) {
    std::vector<ReadoutMode> values;
    for (const py::handle item : modes) {
        const auto t = py::cast<py::sequence>(item);
        if (t.size() != 4)
            throw std::invalid_argument("modes: (binning, binning_readout, frames, "
                                        "alignment_error_um) for each mode, None where unset");
        ReadoutMode m;
        for (std::size_t p = 0; p < 4; ++p) {
            m.sets[p] = !t[p].is_none();
            m.values[p] = m.sets[p] ? py::cast<double>(t[p]) : 0.0;
        }
        values.push_back(m);
    }
    if (values.empty() || values.size() > 32767)
        throw std::invalid_argument("modes: between 1 and 32767 readout modes");
    return values;
}

Options options_of(const std::string& f50_solver, double f50_rtol,
                   const std::string& t_mpe_solver, double t_mpe_rtol,
                   const std::string& precision) {
    if (!(f50_rtol >= 0.0) || !(t_mpe_rtol >= 0.0))
        throw std::invalid_argument("tolerances must be >= 0");
    Options opt;
    opt.f50_solver = f50_solver_of(f50_solver);
    opt.f50_rtol = f50_rtol;
    opt.t_mpe_solver = solver_of(t_mpe_solver);
    opt.t_mpe_rtol = t_mpe_rtol;
    opt.precision = precision_of(precision);
    return opt;
}

void set_octave_bins(Reduction& r, std::int64_t first_key, std::int32_t bins, int shift) {
    if (shift < 12 || shift > 52 || bins < 1 || first_key < 0 ||
        first_key + bins > (std::int64_t{1} << (64 - shift)))
        throw std::invalid_argument("octave bins: shift in [12, 52], bins >= 1, keys from first_key >= 0 below 2^(64 - shift)");
    r.first_key = first_key;
    r.bins = bins;
    r.shift = shift;
}

OutputCache& output_cache() {
    static auto* cache = new OutputCache();
    return *cache;
}

void release_block(void* block) {
    auto* b = static_cast<OutputCache::Block*>(block);
    output_cache().release(b->data, b->capacity);
    delete b;
}

}  // namespace bindings
}  // namespace epc_fast
