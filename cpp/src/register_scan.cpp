// Scans (scan/pass.h): the space, group keys and reductions arrive as plain dicts and lists built
// by python/epc_fast/scan/running/core_plan.py, which has validated them; a chunk's pass runs with
// the GIL released and each reduction's partial results come back as a dict of arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "binding_support.h"
#include "epc_fast/scan/pass.h"
#include "register.h"

namespace epc_fast {
namespace bindings {

namespace {

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

std::vector<std::uint32_t> words_of(const py::handle& obj) {
    const auto arr = py::cast<py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>>(obj);
    return std::vector<std::uint32_t>(arr.data(), arr.data() + arr.size());
}

// The spec's "sobol" entry: None (Monte Carlo) or the direction numbers (dimensions x 32), the
// scrambling keys (dimensions x replicates) and the replicate axis (-1: none).
void sobol_of(const py::dict& spec, ScanSpace& space) {
    if (!spec.contains("sobol") || spec["sobol"].is_none()) return;
    const auto d = py::reinterpret_borrow<py::dict>(spec["sobol"]);
    SobolSampling& s = space.sobol;
    s.on = true;
    s.dimensions = item<std::uint32_t>(d, "dimensions");
    s.replicates = item<std::uint32_t>(d, "replicates");
    s.directions = words_of(d["directions"]);
    s.keys = words_of(d["keys"]);
    set_reversed(s);
    space.replicate_axis = item<int>(d, "replicate_axis");
    if (s.replicates < 1 || s.dimensions > sobol_max_dimensions || s.directions.size() != 32u * s.dimensions ||
        s.keys.size() != static_cast<std::size_t>(s.replicates) * s.dimensions)
        throw std::invalid_argument("scan spec: the Sobol' tables' sizes");
    if (space.replicate_axis >= static_cast<int>(space.axes.size()) ||
        (space.replicate_axis < 0 && s.replicates != 1) ||
        (space.replicate_axis >= 0 &&
         space.axes[static_cast<std::size_t>(space.replicate_axis)].size != static_cast<std::int64_t>(s.replicates)))
        throw std::invalid_argument("scan spec: the replicate axis");
    for (const DiscreteAxis& axis : space.axes)
        if (!axis.grid && axis.dimension >= s.dimensions) throw std::invalid_argument("scan spec: an axis's dimension");
    for (const ParamSource& p : space.params)
        if (p.kind == ParamSource::drawn && p.dimension >= s.dimensions)
            throw std::invalid_argument("scan spec: a parameter's dimension");
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
        axis.dimension = item<std::uint32_t>(d, "dimension");
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
            p.dimension = item<std::uint32_t>(d, "dimension");
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
    sobol_of(spec, space);
    set_cycles(space);
    py::list columns;
    for (int j = 0; j < n_params; ++j) columns.append(py::array_t<double>(1));
    space.inputs = inputs_of(columns, item<bool>(spec, "size_is_pixel_count"),
                             item<double_array>(spec, "domains"), item<double_array>(spec, "wavelengths_nm"),
                             item<double_array>(spec, "weights"), 1);
    // the space's lens tables and a colour sensor's demosaicker's table (None or absent: none)
    if (spec.contains("lens_tables")) set_lens_tables(space.inputs, spec["lens_tables"]);
    if (spec.contains("demosaic_table")) set_demosaic_table(space.inputs, spec["demosaic_table"]);
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

// The reductions. `beyond_table`: the points may be Status::beyond_table (lens tables), which a
// summary's cycle tally has no field for; `modes`: the readout modes, whose picks a summary
// counts per group. Either way summaries fold without the cycle.
std::vector<Reduction> reductions_of(const py::list& specs, const std::vector<GroupKey>& keys,
                                     bool beyond_table, std::size_t modes) {
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
            const bool summary = r.kind == ReductionKind::summary;
            const bool cycle = r.kind != ReductionKind::histogram &&
                               !(summary && (beyond_table || modes > 0));
            if (summary) r.modes = static_cast<std::int64_t>(modes);
            if (cycle) r.cycle = keys[static_cast<std::size_t>(r.key)].cycle.size();
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
                       int threads, bool epc_both, const py::object& modes) {
    if (threads < 1) throw std::invalid_argument("threads must be >= 1");
    if (start % scan_block_points != 0 || stop < start)
        throw std::invalid_argument("a chunk starts at a scan block and is not reversed");
    const ScanSpace space = scan_space_of(space_spec);
    const std::vector<GroupKey> keys = keys_of(key_specs, space);
    const std::vector<ReadoutMode> readout = modes.is_none() ? std::vector<ReadoutMode>{} : readout_modes_of(modes);
    const std::vector<Reduction> reductions =
        reductions_of(reduction_specs, keys, !space.inputs.lens_tables.empty(), readout.size());
    const Options opt = options_of(f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision);
    if (epc_both)
        for (const Reduction& r : reductions)
            if (r.of >= 6)
                throw std::invalid_argument("a scan in both directions folds no share in the "
                                            "fused pass");
    ChunkResult chunk;
    {
        py::gil_scoped_release release;
        chunk = scan_chunk(space, opt, keys, reductions, start, stop, threads, epc_both, readout);
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
                d["status"] = array_of(s.counts, {g, static_cast<py::ssize_t>(ReductionState::n_status)});
                d["count"] = array_of(m.count, {n_blocks, g});
                d["mean"] = array_of(m.mean, {n_blocks, g});
                d["m2"] = array_of(m.m2, {n_blocks, g});
                d["min"] = array_of(s.low, {g});
                d["max"] = array_of(s.high, {g});
                if (red.modes > 0) d["modes"] = array_of(s.mode_counts, {g, static_cast<py::ssize_t>(red.modes + 1)});
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

void register_scan(py::module_& m) {
    m.def("scan_chunk", &scan_chunk_py, py::arg("space"), py::arg("keys"), py::arg("reductions"),
          py::arg("f50_solver"), py::arg("f50_rtol"), py::arg("t_mpe_solver"), py::arg("t_mpe_rtol"),
          py::arg("precision"), py::arg("start"), py::arg("stop"), py::arg("threads"),
          py::arg("epc_both") = false, py::arg("modes") = py::none(),
          "Draws, evaluates and reduces points [start, stop) of a scan (scan/pass.h); one dict of "
          "partial results per reduction. epc_both: EPC and the status counted in both "
          "directions (no share folded). modes: every point's readout modes, as evaluate takes "
          "them (each point in the mode of the largest EPC), or None. The space's spec may "
          "carry lens_tables and demosaic_table, as evaluate takes them.");
    m.def("scan_points", &scan_points_py, py::arg("space"), py::arg("index"),
          "The parameters (None where fixed) and discrete axes' indices of the points `index`.");
    m.attr("scan_block_points") = scan_block_points;
}

}  // namespace bindings
}  // namespace epc_fast
