// The output cache (output_cache.h, binding_support.h output_cache): the memory of dropped
// output arrays kept for later calls, and its limit, set from Python (epc_fast.memory).
#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>

#include "binding_support.h"
#include "register.h"

namespace epc_fast {
namespace bindings {

namespace {

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

}  // namespace

void register_memory(py::module_& m) {
    m.def("output_cache", &output_cache_py, py::arg("limit_bytes") = py::none(),
          "Sets the most bytes of output memory kept for later calls (when limit_bytes is not "
          "None); returns {'limit_bytes', 'retained_bytes'}.");
}

}  // namespace bindings
}  // namespace epc_fast
