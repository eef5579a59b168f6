// What the bindings share (register_*.cpp): NumPy columns read as the kernel's Columns, the
// options and spectrum of a call checked and parsed, output arrays made or checked, and the
// kernel run chunk by chunk with the GIL released. Python (python/epc_fast/api.py) has already
// validated types, broadcast the shapes and made every column a contiguous float64 array of
// size 1 or n. Only the files under cpp/src include pybind11; the headers under
// cpp/include/epc_fast never do.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "epc_fast/output_cache.h"
#include "epc_fast/params.h"

namespace epc_fast {

struct Reduction;  // scan/states.h

namespace bindings {

namespace py = pybind11;

using double_array = py::array_t<double, py::array::c_style>;

// Column `index` of the parameter table, or (index -1) the target EPC: a contiguous 1-D
// float64 array of 1 (broadcast) or n values.
Column column_of(const py::handle& obj, int index, py::ssize_t n);

// The bytes of one output array (begin, end) and its name in the output dict.
struct OutputBytes {
    py::handle name;
    const char* begin;
    const char* end;
};

// The bytes of each array of `outputs` (output name -> array), in the dict's order.
std::vector<OutputBytes> output_bytes_of(const py::dict& outputs);

// A ValueError naming the first two outputs (in the dict's order) that share memory: the
// kernel would write both at once.
void check_apart(const std::vector<OutputBytes>& outputs);

// Each column of `in` that shares memory with an output replaced by a copy kept in `copies`:
// the kernel reads its inputs block by block while it writes its outputs, and an input
// overwritten before it is read would give wrong values.
void copy_overlapping(Inputs& in, py::ssize_t n, const std::vector<OutputBytes>& outputs,
                      std::vector<std::vector<double>>& copies);

// A polychromatic spectrum from its wavelengths (nm, > 0) and weights (>= 0, summing to 1).
Spectrum spectrum_of(const double_array& wavelengths_nm, const double_array& weights);

// The columns and domains of one design set, as the kernel reads them.
Inputs inputs_of(const py::list& columns, bool size_is_pixel_count, const double_array& domains,
                 const double_array& wavelengths_nm, const double_array& weights, py::ssize_t n);

// One MTF table (tabulated.h) from a (knots, values, coefficients) triple of 1-D float64 arrays
// (as set_lens_tables takes them), checked: a std::invalid_argument otherwise.
MtfTable table_of(const py::handle& triple);

// The call's lens tables into `in` (tabulated.h): `tables` None or a list of
// (knots, values, coefficients) triples of 1-D float64 arrays (epc_fast.mtf_table.MtfTable's
// frequencies, values and its (knots - 1, 4) coefficients flattened). With tables, a wavefront
// error other than 0 is outside its domain (a lens table includes its aberrations).
void set_lens_tables(Inputs& in, const py::object& tables);

// A colour sensor's demosaicker's table into `in` (Inputs::demosaic): None, or one
// (knots, values, coefficients) triple as set_lens_tables reads them, in cycles per pixel.
void set_demosaic_table(Inputs& in, const py::object& table);

// The readout modes of a call or a scan (modes.h): a sequence of (binning, binning_readout
// code, frames, alignment_error_um) tuples, 1 to 32767 of them, None for a parameter the mode
// leaves to the call's column; a std::invalid_argument otherwise.
std::vector<ReadoutMode> readout_modes_of(const py::object& modes);

// The solvers, tolerances and precision of a call, by their Python names.
Options options_of(const std::string& f50_solver, double f50_rtol,
                   const std::string& t_mpe_solver, double t_mpe_rtol,
                   const std::string& precision = "float64");

// Quantiles' octave bins (histograms.py _OctaveBins), checked: keys below 2^52
// (octave_slot_of), the last bin's among them.
void set_octave_bins(Reduction& r, std::int64_t first_key, std::int32_t bins, int shift);

// The cache of output memory (output_cache.h) that evaluate's new arrays come from, one for
// the module. Never destroyed: an array may outlive the module's static objects at
// interpreter exit.
OutputCache& output_cache();

// Gives an OutputCache::Block of new_column's back to the cache (a capsule's destructor).
void release_block(void* block);

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

// A caller's output array `obj` for output `name`: 1-D, C-contiguous, writeable, of dtype T and
// length n, else an error naming it.
template <class T>
T* output_array(const py::handle& obj, const char* name, py::ssize_t n) {
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

}  // namespace bindings
}  // namespace epc_fast
