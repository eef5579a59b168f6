// The only file that includes pybind11: it turns NumPy columns into epc_fast::Inputs, runs the
// kernel with the GIL released, chunk by chunk so that Ctrl-C is honoured between chunks, and
// hands the output columns back. Python (python/epc_fast/api.py) has already validated types,
// broadcast the shapes and made every column a contiguous float64 array of size 1 or n.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "epc_fast/inverse.h"
#include "epc_fast/kernel.h"
#include "epc_fast/output_cache.h"
#include "epc_fast/scan.h"
#include "epc_fast/spectrum_start.h"

namespace py = pybind11;
using namespace epc_fast;

namespace {

using double_array = py::array_t<double, py::array::c_style>;

// Column `index` of the parameter table, or (index -1) the target EPC: a contiguous 1-D
// float64 array of 1 (broadcast) or n values.
Column column_of(const py::handle& obj, int index, py::ssize_t n) {
    const std::string what = index < 0 ? "target_epc" : "column " + std::to_string(index);
    if (!py::isinstance<py::array>(obj)) throw std::invalid_argument(what + " is not an ndarray");
    auto arr = py::reinterpret_borrow<py::array>(obj);
    // Equivalence, not identity: an unpickled array carries an equal but distinct dtype object.
    if (!py::isinstance<py::array_t<double, py::array::c_style>>(arr) || arr.ndim() != 1)
        throw std::invalid_argument(what + " must be a contiguous 1-D float64 array");
    if (arr.size() != 1 && arr.size() != n)
        throw std::invalid_argument(what + " has " + std::to_string(arr.size()) +
                                    " values, expected 1 or " + std::to_string(n));
    return Column{static_cast<const double*>(arr.data()), arr.size() == 1 ? 0 : 1};
}

// Calls (chunks) of fewer points than this write their fresh outputs without first_touch: a
// float64 column of them spans at most a quarter of a 2 MiB huge page.
constexpr std::size_t first_touch_points = std::size_t{1} << 16;

constexpr const char* output_names[] = {"electron_rate_e_per_s", "electrons", "t_mpe_s",
                                        "blur_mm", "f50_cyc_per_mm", "epc", "status", "cause"};
// The outputs computed only when named (sensitivity.h): the shares, in Share's order, and
// the elasticities: parameter j's as "elasticity_" + param_names[j], or all of them as
// "elasticities", n_params rows of n points in one array (row j parameter j's).
constexpr const char* share_names[] = {"share_diffraction", "share_pixel", "share_motion",
                                       "share_jitter"};

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
    return in(output_names) || in(share_names) || name == elasticities_name || elasticity_of(name) >= 0;
}

// The cache of output memory (output_cache.h) that evaluate's new arrays come from. Never
// destroyed: an array may outlive the module's static objects at interpreter exit.
OutputCache& output_cache() {
    static auto* cache = new OutputCache();
    return *cache;
}

void release_block(void* block) {
    auto* b = static_cast<OutputCache::Block*>(block);
    output_cache().release(b->data, b->capacity);
    delete b;
}

// A new 1-D array of n values of T for an output; `fresh` says whether its pages are new (never
// touched). Arrays of at least OutputCache::min_bytes take their memory from the cache while
// it keeps any (limit > 0): the array's base is a capsule that gives the memory back.
template <class T>
py::array new_column(py::ssize_t n, bool& fresh) {
    OutputCache& cache = output_cache();
    const auto count = static_cast<std::size_t>(n);
    if (count > static_cast<std::size_t>(PTRDIFF_MAX) / sizeof(T) ||
        count * sizeof(T) < OutputCache::min_bytes || cache.limit() == 0) {
        fresh = true;
        return py::array_t<T>(n);  // NumPy's own memory, or its error for an impossible n
    }
    auto block = std::make_unique<OutputCache::Block>();  // before acquire: nothing to leak
    *block = cache.acquire(count * sizeof(T));
    py::capsule owner;
    try {
        owner = py::capsule(block.get(), &release_block);
    } catch (...) {
        cache.release(block->data, block->capacity);
        throw;
    }
    const OutputCache::Block* kept = block.release();  // owner's now
    fresh = kept->fresh;
    return py::array_t<T>({n}, {static_cast<py::ssize_t>(sizeof(T))}, static_cast<T*>(kept->data),
                          owner);
}

// A caller's output array: 1-D, C-contiguous, writeable, of dtype T and length n; null when
// `out` has no such field (that output is not computed).
template <class T>
T* output_column(const py::dict& out, const char* name, py::ssize_t n) {
    if (!out.contains(name)) return nullptr;
    py::object obj = out[name];
    if (!py::isinstance<py::array>(obj))
        throw std::invalid_argument(std::string("out['") + name + "'] is not an ndarray");
    auto arr = py::reinterpret_borrow<py::array>(obj);
    if (!py::isinstance<py::array_t<T, py::array::c_style>>(arr) || arr.ndim() != 1 ||
        !arr.writeable() || arr.size() != n)
        throw std::invalid_argument(std::string("out['") + name + "'] must be a writeable, " +
                                    "contiguous 1-D array of " + std::to_string(n) + " " +
                                    (sizeof(T) == 1 ? "uint8" : "float64") + " values");
    return static_cast<T*>(arr.mutable_data());
}

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

// A polychromatic spectrum from its wavelengths (nm, > 0) and weights (>= 0, summing to 1).
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

// The columns and domains of one design set, as the kernel reads them.
Inputs inputs_of(const py::list& columns, bool size_is_pixel_count, const double_array& domains,
                 const double_array& wavelengths_nm, const double_array& weights, py::ssize_t n) {
    if (static_cast<int>(columns.size()) != n_params)
        throw std::invalid_argument("expected " + std::to_string(n_params) + " columns");
    if (domains.ndim() != 2 || domains.shape(0) != n_params || domains.shape(1) != 4)
        throw std::invalid_argument("domains must have shape (n_params, 4)");
    if (wavelengths_nm.size() != weights.size())
        throw std::invalid_argument("wavelengths_nm and weights differ in length");
    if (n < 0) throw std::invalid_argument("n must be >= 0");
    Inputs in;
    in.size_is_pixel_count = size_is_pixel_count;
    auto d = domains.unchecked<2>();
    for (int j = 0; j < n_params; ++j) {
        in.columns[j] = column_of(columns[j], j, n);
        in.domains[j] = Domain{d(j, 0), d(j, 1), d(j, 2) != 0.0, d(j, 3) != 0.0};
    }
    if (wavelengths_nm.size() != 0) {  // none: monochromatic at each point's wavelength
        in.spectrum = spectrum_of(wavelengths_nm, weights);
        in.spectrum.start = spectrum_start_of(in.spectrum);
    }
    return in;
}

Options options_of(const std::string& f50_solver, double f50_rtol,
                   const std::string& t_mpe_solver, double t_mpe_rtol,
                   const std::string& precision = "float64") {
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

// Runs work(start, stop) over [0, n) in chunks with the GIL released, checking for Ctrl-C
// (and any other pending signal) between chunks.
template <class Work>
void run_chunked(py::ssize_t n, py::ssize_t chunk_points, int threads, Work&& work) {
    if (threads < 1) throw std::invalid_argument("threads must be >= 1");
    if (chunk_points < 1) throw std::invalid_argument("chunk_points must be >= 1");
    const auto total = static_cast<std::size_t>(n);
    const auto chunk = static_cast<std::size_t>(chunk_points);
    for (std::size_t start = 0; start < total; start += chunk) {
        {
            py::gil_scoped_release release;
            work(start, std::min(total, start + chunk));
        }
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
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

// The kernel's view of `arrays` (output name -> array): null for the outputs it lacks.
Outputs outputs_in(const py::dict& arrays, py::ssize_t n) {
    Outputs out{output_column<double>(arrays, "electron_rate_e_per_s", n),
                output_column<double>(arrays, "electrons", n),
                output_column<double>(arrays, "t_mpe_s", n),
                output_column<double>(arrays, "blur_mm", n),
                output_column<double>(arrays, "f50_cyc_per_mm", n),
                output_column<double>(arrays, "epc", n),
                output_column<std::uint8_t>(arrays, "status", n),
                output_column<std::uint8_t>(arrays, "cause", n)};
    for (int k = 0; k < n_shares; ++k)
        out.sensitivity.share[k] = output_column<double>(arrays, share_names[k], n);
    // the elasticities asked for, by one pass over the names: when the dict holds more
    // outputs than those found so far (most calls ask for none)
    const double* values[] = {out.electron_rate_e_per_s, out.electrons, out.t_mpe_s, out.blur_mm,
                              out.f50_cyc_per_mm, out.epc};
    std::size_t found = (out.status != nullptr) + (out.cause != nullptr);
    for (const double* v : values) found += v != nullptr;
    for (const double* v : out.sensitivity.share) found += v != nullptr;
    if (arrays.size() == found) return out;
    double* every = output_column<double>(arrays, elasticities_name, output_size(elasticities_name, n));
    for (auto item : arrays) {
        if (!py::isinstance<py::str>(item.first)) continue;
        const std::string name = py::cast<std::string>(item.first);
        const int j = elasticity_of(name);
        if (j < 0) continue;
        if (every != nullptr)
            throw std::invalid_argument("out has both 'elasticities' (every elasticity) and '" + name + "'");
        out.sensitivity.elasticity[j] = output_column<double>(arrays, name.c_str(), n);
    }
    if (every != nullptr)
        for (int j = 0; j < n_params; ++j) out.sensitivity.elasticity[j] = every + j * n;
    return out;
}

py::dict evaluate_py(const py::list& columns, bool size_is_pixel_count, const double_array& domains,
                     const double_array& wavelengths_nm, const double_array& weights, py::ssize_t n,
                     const std::string& f50_solver, double f50_rtol,
                     const std::string& t_mpe_solver, double t_mpe_rtol,
                     const std::string& precision, int threads, py::ssize_t chunk_points,
                     const py::object& out, const py::object& allocate) {
    const Inputs in = inputs_of(columns, size_is_pixel_count, domains, wavelengths_nm, weights, n);
    const Options opt = options_of(f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision);
    py::dict fresh;
    py::dict result = outputs_of(out, allocate, n, fresh);
    // A large call's outputs are written with streaming stores (stream.h)
    const Outputs outputs = streaming_for(outputs_in(result, n), static_cast<std::size_t>(n));
    // New pages are faulted in on all threads first (first_touch), except at sizes where they
    // are too few to matter; the cache's kept blocks and the caller's arrays are mapped already.
    const Outputs untouched = outputs_in(fresh, n);
    const bool touch = !fresh.empty() && threads > 1;
    run_chunked(n, chunk_points, threads, [&](std::size_t start, std::size_t stop) {
        if (touch && stop - start >= first_touch_points) first_touch(untouched, start, stop, threads);
        evaluate(in, opt, outputs, start, stop, threads);
    });
    return result;
}

// The output cache's limit (bytes) set, when `limit_bytes` is not None, and its state.
py::dict output_cache_py(const py::object& limit_bytes) {
    if (!limit_bytes.is_none()) {
        const auto limit = py::cast<long long>(limit_bytes);
        if (limit < 0) throw std::invalid_argument("limit_bytes must be >= 0, got " + std::to_string(limit));
        output_cache().set_limit(static_cast<std::size_t>(limit));
    }
    py::dict state;
    state["limit_bytes"] = output_cache().limit();
    state["retained_bytes"] = output_cache().retained();
    return state;
}

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
                        double lux_lo, double lux_hi, double rtol, double f50_rtol, int threads) {
    const Inputs in = inputs_of(columns, size_is_pixel_count, domains, wavelengths_nm, weights, n);
    const Column target = column_of(target_epc, -1, n);
    const Options opt = options_of("halley", f50_rtol, "closed_form", 0.0);
    const InverseOptions inv = inverse_options_of(lux_lo, lux_hi, rtol, 2);
    InverseResult result(n);
    const InverseOutputs out = result.outputs();
    run_chunked(n, 1 << 14, threads, [&](std::size_t start, std::size_t stop) {
        lux_for_epc(in, target, opt, inv, out, start, stop, threads);
    });
    return result.dict();
}

py::dict crossover_lux_py(const py::list& columns_a, const py::list& columns_b,
                          bool size_is_pixel_count_a, bool size_is_pixel_count_b,
                          const double_array& domains, const double_array& wavelengths_nm,
                          const double_array& weights, py::ssize_t n, double lux_lo,
                          double lux_hi, int grid_points, double rtol, double f50_rtol,
                          int threads) {
    const Inputs a = inputs_of(columns_a, size_is_pixel_count_a, domains, wavelengths_nm, weights, n);
    const Inputs b = inputs_of(columns_b, size_is_pixel_count_b, domains, wavelengths_nm, weights, n);
    const Options opt = options_of("halley", f50_rtol, "closed_form", 0.0);
    const InverseOptions inv = inverse_options_of(lux_lo, lux_hi, rtol, grid_points);
    InverseResult result(n);
    const InverseOutputs out = result.outputs();
    run_chunked(n, 1 << 12, threads, [&](std::size_t start, std::size_t stop) {
        crossover_lux(a, b, opt, inv, out, start, stop, threads);
    });
    return result.dict();
}


// ---- scans (scan.h): the space, keys and reductions arrive as plain dicts and lists built by
// python/epc_fast/scan/core_plan.py, which has validated them.

template <class T>
T item(const py::dict& d, const char* key) {
    if (!d.contains(key)) throw std::invalid_argument(std::string("scan spec: missing '") + key + "'");
    return py::cast<T>(d[key]);
}

std::vector<double> doubles_of(const py::handle& obj) {
    if (obj.is_none()) return {};
    const auto arr = py::cast<py::array_t<double, py::array::c_style | py::array::forcecast>>(obj);
    return std::vector<double>(arr.data(), arr.data() + arr.size());
}

Draw draw_of(const py::dict& d) {
    static const char* kinds[] = {"affine", "exp_affine", "normal", "lognormal", "empirical"};
    const auto kind = item<std::string>(d, "kind");
    Draw draw;
    const auto at = std::find(std::begin(kinds), std::end(kinds), kind);
    if (at == std::end(kinds)) throw std::invalid_argument("scan spec: unknown draw kind '" + kind + "'");
    draw.kind = static_cast<DrawKind>(at - std::begin(kinds));
    draw.a = item<double>(d, "a");
    draw.b = item<double>(d, "b");
    draw.pa = item<double>(d, "pa");
    draw.pb = item<double>(d, "pb");
    draw.low = item<double>(d, "low");
    draw.high = item<double>(d, "high");
    draw.mirror = item<bool>(d, "mirror");
    draw.samples = doubles_of(d["samples"]);
    if (draw.kind == DrawKind::empirical && draw.samples.empty())
        throw std::invalid_argument("scan spec: an empirical draw needs samples");
    return draw;
}

ScanSpace scan_space_of(const py::dict& spec) {
    ScanSpace space;
    const auto seed = item<py::int_>(spec, "seed");
    space.seed = py::cast<std::uint64_t>(seed);
    for (auto a : item<py::list>(spec, "axes")) {
        const auto d = py::reinterpret_borrow<py::dict>(a);
        DiscreteAxis axis;
        axis.grid = item<bool>(d, "grid");
        axis.size = item<std::int64_t>(d, "size");
        axis.stream = item<std::uint32_t>(d, "stream");
        axis.cumulative = doubles_of(d["cumulative"]);
        if (axis.size < 1 || axis.size > INT32_MAX) throw std::invalid_argument("scan spec: axis size");
        space.axes.push_back(std::move(axis));
    }
    space.set_grid();
    const auto params = item<py::list>(spec, "params");
    if (static_cast<int>(params.size()) != n_params)
        throw std::invalid_argument("scan spec: expected " + std::to_string(n_params) + " params");
    for (int j = 0; j < n_params; ++j) {
        const auto d = py::reinterpret_borrow<py::dict>(params[static_cast<std::size_t>(j)]);
        const auto kind = item<std::string>(d, "kind");
        ParamSource& p = space.params[j];
        if (kind == "fixed") {
            p.kind = ParamSource::fixed;
            p.value = item<double>(d, "value");
        } else if (kind == "drawn") {
            p.kind = ParamSource::drawn;
            p.stream = item<std::uint32_t>(d, "stream");
            p.draw = draw_of(item<py::dict>(d, "draw"));
        } else if (kind == "axis") {
            p.kind = ParamSource::axis_value;
            p.axis = item<int>(d, "axis");
            p.values = doubles_of(d["values"]);
            if (p.axis < 0 || static_cast<std::size_t>(p.axis) >= space.axes.size() ||
                static_cast<std::int64_t>(p.values.size()) != space.axes[static_cast<std::size_t>(p.axis)].size)
                throw std::invalid_argument("scan spec: param " + std::to_string(j) + "'s axis values");
        } else {
            throw std::invalid_argument("scan spec: unknown param kind '" + kind + "'");
        }
    }
    set_cycles(space);
    py::list columns;
    for (int j = 0; j < n_params; ++j) columns.append(py::array_t<double>(1));
    space.inputs = inputs_of(columns, item<bool>(spec, "size_is_pixel_count"),
                             item<double_array>(spec, "domains"), item<double_array>(spec, "wavelengths_nm"),
                             item<double_array>(spec, "weights"), 1);
    return space;
}

std::vector<GroupKey> keys_of(const py::list& keys, const ScanSpace& space) {
    static const char* kinds[] = {"axis", "lookup", "binned", "binned_log"};
    std::vector<GroupKey> result;
    for (auto k : keys) {
        GroupKey key;
        for (auto p : py::reinterpret_borrow<py::list>(k)) {
            const auto d = py::reinterpret_borrow<py::dict>(p);
            const auto kind = item<std::string>(d, "kind");
            const auto at = std::find(std::begin(kinds), std::end(kinds), kind);
            if (at == std::end(kinds)) throw std::invalid_argument("scan spec: unknown key part '" + kind + "'");
            KeyPart part;
            part.kind = static_cast<KeyPart::Kind>(at - std::begin(kinds));
            part.size = item<std::int32_t>(d, "size");
            if (part.size < 1) throw std::invalid_argument("scan spec: a key part's size must be >= 1");
            if (part.kind == KeyPart::axis || part.kind == KeyPart::lookup) {
                part.axis_index = item<int>(d, "axis");
                if (part.axis_index < 0 || static_cast<std::size_t>(part.axis_index) >= space.axes.size())
                    throw std::invalid_argument("scan spec: a key part's axis");
                const auto axis_size = space.axes[static_cast<std::size_t>(part.axis_index)].size;
                if (part.kind == KeyPart::lookup) {
                    for (double v : doubles_of(d["lookup"])) part.lookup_table.push_back(static_cast<std::int32_t>(v));
                    if (static_cast<std::int64_t>(part.lookup_table.size()) != axis_size)
                        throw std::invalid_argument("scan spec: a lookup part's table");
                    for (auto v : part.lookup_table)
                        if (v < 0 || v >= part.size) throw std::invalid_argument("scan spec: a lookup value");
                } else if (axis_size != part.size) {
                    throw std::invalid_argument("scan spec: an axis part's size");
                }
            } else {
                part.param = item<int>(d, "param");
                if (part.param < 0 || part.param >= n_params) throw std::invalid_argument("scan spec: a key part's param");
                part.inner_edges = doubles_of(d["inner_edges"]);
                part.first = item<double>(d, "first");
                part.scale = item<double>(d, "scale");
                if (part.kind == KeyPart::binned &&
                    static_cast<std::int64_t>(part.inner_edges.size()) != part.size - 1)
                    throw std::invalid_argument("scan spec: a binned part's edges");
            }
            key.parts.push_back(std::move(part));
        }
        std::int64_t size = 1;
        for (const KeyPart& part : key.parts) {
            size *= part.size;
            if (size > INT32_MAX) throw std::invalid_argument("scan spec: a key of 2^31 groups or more");
        }
        key.size = size;
        set_cycle(key, space);
        result.push_back(std::move(key));
    }
    return result;
}

// Quantiles' octave bins (histograms.py _OctaveBins), checked: keys below 2^52
// (octave_slot_of), the last bin's among them.
void set_octave_bins(Reduction& r, std::int64_t first_key, std::int32_t bins, int shift) {
    if (shift < 12 || shift > 52 || bins < 1 || first_key < 0 ||
        first_key + bins > (std::int64_t{1} << (64 - shift)))
        throw std::invalid_argument("octave bins: shift in [12, 52], bins >= 1, keys from first_key >= 0 below 2^(64 - shift)");
    r.first_key = first_key;
    r.bins = bins;
    r.shift = shift;
}

std::vector<Reduction> reductions_of(const py::list& specs, const std::vector<GroupKey>& keys) {
    static const char* kinds[] = {"summary", "histogram", "quantiles", "fraction_below", "top_k"};
    std::vector<Reduction> result;
    for (auto s : specs) {
        const auto d = py::reinterpret_borrow<py::dict>(s);
        const auto kind = item<std::string>(d, "kind");
        const auto at = std::find(std::begin(kinds), std::end(kinds), kind);
        if (at == std::end(kinds)) throw std::invalid_argument("scan spec: unknown reduction '" + kind + "'");
        Reduction r;
        r.kind = static_cast<ReductionKind>(at - std::begin(kinds));
        r.of = item<int>(d, "of");
        if (r.of < 0 || r.of >= n_scan_outputs) throw std::invalid_argument("scan spec: a reduction's output");
        if (r.kind == ReductionKind::top_k) {
            r.k = item<std::int64_t>(d, "k");
            r.largest = item<bool>(d, "largest");
            if (r.k < 1 || r.k > (std::int64_t{1} << 20)) throw std::invalid_argument("scan spec: top_k's k");
        } else {
            r.key = item<int>(d, "key");
            if (r.key < 0 || static_cast<std::size_t>(r.key) >= keys.size())
                throw std::invalid_argument("scan spec: a reduction's key");
            r.groups = keys[static_cast<std::size_t>(r.key)].size;
            // a histogram keeps no sums per position of the cycle
            if (r.kind != ReductionKind::histogram) r.cycle = keys[static_cast<std::size_t>(r.key)].cycle.size();
        }
        if (r.kind == ReductionKind::histogram) {
            r.first = item<double>(d, "first");
            r.last = item<double>(d, "last");
            r.bins = item<std::int32_t>(d, "bins");
            r.log = item<bool>(d, "log");
            if (!(r.first < r.last) || r.bins < 1) throw std::invalid_argument("scan spec: a histogram's bins");
            r.bins_per_t = static_cast<double>(r.bins) / (r.last - r.first);
        }
        if (r.kind == ReductionKind::quantiles)
            set_octave_bins(r, item<std::int64_t>(d, "first_key"), item<std::int32_t>(d, "bins"),
                            item<int>(d, "shift"));
        if (r.kind == ReductionKind::fraction_below) r.threshold = item<double>(d, "threshold");
        result.push_back(r);
    }
    return result;
}

template <class T>
py::array_t<T> array_of(const std::vector<T>& v, std::vector<py::ssize_t> shape) {
    py::array_t<T> a(shape);
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

py::list scan_chunk_py(const py::dict& space_spec, const py::list& key_specs,
                       const py::list& reduction_specs, const std::string& f50_solver,
                       double f50_rtol, const std::string& t_mpe_solver, double t_mpe_rtol,
                       const std::string& precision, std::uint64_t start, std::uint64_t stop,
                       int threads) {
    if (threads < 1) throw std::invalid_argument("threads must be >= 1");
    if (start % scan_block_points != 0 || stop < start)
        throw std::invalid_argument("a chunk starts at a scan block and is not reversed");
    const ScanSpace space = scan_space_of(space_spec);
    const std::vector<GroupKey> keys = keys_of(key_specs, space);
    const std::vector<Reduction> reductions = reductions_of(reduction_specs, keys);
    const Options opt = options_of(f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision);
    ChunkResult chunk;
    {
        py::gil_scoped_release release;
        chunk = scan_chunk(space, opt, keys, reductions, start, stop, threads);
    }
    const auto n_blocks = static_cast<py::ssize_t>((stop - start + scan_block_points - 1) / scan_block_points);
    py::list out;
    for (std::size_t r = 0; r < reductions.size(); ++r) {
        const Reduction& red = reductions[r];
        const ReductionState& s = chunk.states[r];
        const auto g = static_cast<py::ssize_t>(red.groups);
        py::dict d;
        switch (red.kind) {
            case ReductionKind::summary: {
                const ChunkResult::Moments& m = chunk.moments[r];
                d["status"] = array_of(s.counts, {g, 4});
                d["count"] = array_of(m.count, {n_blocks, g});
                d["mean"] = array_of(m.mean, {n_blocks, g});
                d["m2"] = array_of(m.m2, {n_blocks, g});
                d["min"] = array_of(s.low, {g});
                d["max"] = array_of(s.high, {g});
                break;
            }
            case ReductionKind::histogram:
                d["counts"] = array_of(s.counts, {g, static_cast<py::ssize_t>(red.slots())});
                d["points"] = array_of(s.points, {g});
                break;
            case ReductionKind::quantiles:
                d["counts"] = array_of(s.counts, {g, static_cast<py::ssize_t>(red.slots())});
                d["min"] = array_of(s.low, {g});
                d["max"] = array_of(s.high, {g});
                break;
            case ReductionKind::fraction_below:
                d["count"] = array_of(s.counts, {g});
                d["below"] = array_of(s.points, {g});
                break;
            case ReductionKind::top_k: {
                std::vector<Candidate> best = s.heap;
                std::sort(best.begin(), best.end());
                std::vector<double> key;
                std::vector<std::int64_t> index;
                for (const Candidate& c : best) {
                    key.push_back(c.first);
                    index.push_back(static_cast<std::int64_t>(c.second));
                }
                d["order_key"] = array_of(key, {static_cast<py::ssize_t>(key.size())});
                d["index"] = array_of(index, {static_cast<py::ssize_t>(index.size())});
                break;
            }
        }
        out.append(d);
    }
    return out;
}

// The parameters (None where fixed) and discrete axes' indices of the points `index`.
py::tuple scan_points_py(const py::dict& space_spec, const py::array_t<std::int64_t, py::array::c_style>& index) {
    const ScanSpace space = scan_space_of(space_spec);
    const auto n = static_cast<std::size_t>(index.size());
    const std::int64_t* idx = index.data();
    for (std::size_t i = 0; i < n; ++i)
        if (idx[i] < 0) throw std::invalid_argument("point indices must be >= 0");
    std::vector<std::uint64_t> points(idx, idx + n);
    py::list values;
    std::vector<double*> value_ptrs(n_params, nullptr);
    for (int j = 0; j < n_params; ++j) {
        if (space.params[j].kind == ParamSource::fixed) {
            values.append(py::none());
            continue;
        }
        py::array_t<double> a(static_cast<py::ssize_t>(n));
        value_ptrs[static_cast<std::size_t>(j)] = a.mutable_data();
        values.append(a);
    }
    py::list axes;
    std::vector<std::int32_t*> axis_ptrs;
    for (std::size_t a = 0; a < space.axes.size(); ++a) {
        py::array_t<std::int32_t> arr(static_cast<py::ssize_t>(n));
        axis_ptrs.push_back(arr.mutable_data());
        axes.append(arr);
    }
    {
        py::gil_scoped_release release;
        scan_points(space, points.data(), n, value_ptrs.data(), axis_ptrs.data());
    }
    return py::make_tuple(values, axes);
}
}  // namespace

// x86-64 micro-architecture levels this CPU supports, asked of the baseline module before a
// wider one is imported (importing a module built for an unsupported level could fault).
py::dict cpu_levels() {
    py::dict levels;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    levels["x86-64-v2"] = __builtin_cpu_supports("x86-64-v2") != 0;
    levels["x86-64-v3"] = __builtin_cpu_supports("x86-64-v3") != 0;
    levels["x86-64-v4"] = __builtin_cpu_supports("x86-64-v4") != 0;
#endif
    return levels;
}

#ifndef EPC_FAST_MODULE
#define EPC_FAST_MODULE _core_generic
#endif
#define EPC_FAST_STRINGIFY_(x) #x
#define EPC_FAST_STRINGIFY(x) EPC_FAST_STRINGIFY_(x)

PYBIND11_MODULE(EPC_FAST_MODULE, m) {
    m.doc() = "epc_fast's compiled core for one instruction-set level; epc_fast._core picks one.";
    m.attr("module_name") = EPC_FAST_STRINGIFY(EPC_FAST_MODULE);
    m.def("cpu_levels", &cpu_levels, "The x86-64 levels this CPU supports.");
    m.attr("n_params") = static_cast<int>(n_params);
    py::tuple parameter_names(static_cast<std::size_t>(n_params));
    for (int j = 0; j < n_params; ++j) parameter_names[j] = param_names[j];
    m.attr("parameter_names") = parameter_names;
    m.attr("block_size") = block_size;
    m.attr("stream_min_bytes") = stream_min_bytes;
    m.attr("streaming_stores") = streaming_stores;
    m.def("openmp_enabled", &openmp_enabled, "Whether the core was built with OpenMP.");
    m.def("default_threads", &default_threads,
          "Threads used when none are asked for (OMP_NUM_THREADS, else the cores).");
    m.def("evaluate", &evaluate_py, py::arg("columns"), py::arg("size_is_pixel_count"),
          py::arg("domains"), py::arg("wavelengths_nm"), py::arg("weights"), py::arg("n"),
          py::arg("f50_solver"), py::arg("f50_rtol"), py::arg("t_mpe_solver"), py::arg("t_mpe_rtol"),
          py::arg("precision"), py::arg("threads"),
          py::arg("chunk_points"), py::arg("out") = py::none(), py::arg("allocate") = py::none(),
          "Evaluates the model into the arrays of `out` (a dict of output arrays, or None) and "
          "new arrays for the outputs named in `allocate` (None: all of them when out is None, "
          "else none); only these outputs are computed. Returns the dict of them all.");
    m.def("scan_chunk", &scan_chunk_py, py::arg("space"), py::arg("keys"), py::arg("reductions"),
          py::arg("f50_solver"), py::arg("f50_rtol"), py::arg("t_mpe_solver"), py::arg("t_mpe_rtol"),
          py::arg("precision"), py::arg("start"), py::arg("stop"), py::arg("threads"),
          "Draws, evaluates and reduces points [start, stop) of a scan (scan.h); one dict of "
          "partial results per reduction.");
    m.def("scan_points", &scan_points_py, py::arg("space"), py::arg("index"),
          "The parameters (None where fixed) and discrete axes' indices of the points `index`.");
    m.attr("scan_block_points") = scan_block_points;
    m.def("stream_uniforms",
          // block by block, through the fused pass's own stream_uniforms (philox.h); the tail
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
    // the draws' block form of ndtri (draws.h ndtri_block), block by block; the tail of the
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
    // the streamed quantiles' slot of each value (scan_reductions.h octave_slot_of), as the
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
    m.def("output_cache", &output_cache_py, py::arg("limit_bytes") = py::none(),
          "Sets the most bytes of output memory kept for later calls (when limit_bytes is not "
          "None); returns {'limit_bytes', 'retained_bytes'}.");
    m.def("lux_for_epc", &lux_for_epc_py, py::arg("columns"), py::arg("size_is_pixel_count"),
          py::arg("domains"), py::arg("wavelengths_nm"), py::arg("weights"), py::arg("n"),
          py::arg("target_epc"), py::arg("lux_lo"), py::arg("lux_hi"), py::arg("rtol"),
          py::arg("f50_rtol"), py::arg("threads"),
          "Illuminance at which each design reaches target_epc (Brent on ln L).");
    m.def("crossover_lux", &crossover_lux_py, py::arg("columns_a"), py::arg("columns_b"),
          py::arg("size_is_pixel_count_a"), py::arg("size_is_pixel_count_b"), py::arg("domains"),
          py::arg("wavelengths_nm"), py::arg("weights"), py::arg("n"), py::arg("lux_lo"),
          py::arg("lux_hi"), py::arg("grid_points"), py::arg("rtol"), py::arg("f50_rtol"),
          py::arg("threads"),
          "Highest illuminance in [lux_lo, lux_hi] where designs a and b have equal EPC.");
    // Single formulas, elementwise, so that tests can hold the C++ against known values.
    m.def("sinc", py::vectorize(&sinc<double>));
    m.def("mtf_diffraction", py::vectorize(&mtf_diffraction<double>), py::arg("nu"));
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
    // A spectrum's fitted start (spectrum_start.h): its coefficients and fit errors (None where
    // none can be fitted), and the start a polychromatic float64 lane without jitter takes
    // (lambda_f_mm with the spectrum's mean wavelength; the cubic start for a threshold without
    // a row or a spectrum without a fit).
    m.def(
        "spectrum_start",
        [](const double_array& wavelengths_nm, const double_array& weights) -> py::object {
            const auto start = spectrum_start_of(spectrum_of(wavelengths_nm, weights));
            if (start == nullptr) return py::none();
            py::dict d;
            d["coefficients"] = py::array_t<double>(
                {static_cast<py::ssize_t>(detail::n_accurate_starts),
                 static_cast<py::ssize_t>(detail::accurate_start_terms)},
                &start->coefficients[0][0]);
            d["fit_error"] = py::array_t<double>(static_cast<py::ssize_t>(detail::n_accurate_starts),
                                                 start->fit_error);
            return d;
        },
        py::arg("wavelengths_nm"), py::arg("weights"));
    m.def(
        "f50_spectrum_start",
        [](const double_array& wavelengths_nm, const double_array& weights,
           const double_array& lambda_f_mm, const double_array& aperture_mm,
           const double_array& blur_mm, const double_array& mtf_threshold) {
            const auto start = spectrum_start_of(spectrum_of(wavelengths_nm, weights));
            auto one = [&start](double lambda_f, double aperture, double blur, double threshold) {
                const int row = int{detail::accurate_start_code(0.0, threshold)} - 1;
                return row < 0 || start == nullptr ? detail::f50_cubic_start(lambda_f, aperture, blur, 0.0, threshold)
                               : detail::spectrum_start_guess(start->coefficients[row], lambda_f,
                                                              aperture, blur);
            };
            return py::vectorize(one)(lambda_f_mm, aperture_mm, blur_mm, mtf_threshold);
        },
        py::arg("wavelengths_nm"), py::arg("weights"), py::arg("lambda_f_mm"),
        py::arg("aperture_mm"), py::arg("blur_mm"), py::arg("mtf_threshold"));
    // The accurate starts' polynomials (f50_start.h): one row of coefficients per threshold of
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
