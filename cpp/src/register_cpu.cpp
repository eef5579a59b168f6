// The build and the machine: which module this is, which x86-64 levels the CPU runs, the
// threads a call uses and those already started, and the sizes the kernel was built with (its
// block, the call size from which outputs are streamed).
#include <pybind11/pybind11.h>

#include "epc_fast/block.h"
#include "epc_fast/parallel.h"
#include "epc_fast/stream.h"
#include "register.h"

#define EPC_FAST_STRINGIFY_(x) #x
#define EPC_FAST_STRINGIFY(x) EPC_FAST_STRINGIFY_(x)

namespace epc_fast {
namespace bindings {

namespace py = pybind11;

namespace {

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

}  // namespace

void register_cpu(py::module_& m) {
    m.attr("module_name") = EPC_FAST_STRINGIFY(EPC_FAST_MODULE);
    m.def("cpu_levels", &cpu_levels, "The x86-64 levels this CPU supports.");
    m.def("openmp_enabled", &openmp_enabled, "Whether the core was built with OpenMP.");
    m.def("default_threads", &default_threads,
          "Threads used when none are asked for (OMP_NUM_THREADS, else the cores).");
    m.def("started_threads", [] { return largest_team(); },
          "The most threads the calling thread's calls have run on (their runtime keeps them).");
    m.attr("block_size") = block_size;
    m.attr("stream_min_bytes") = stream_min_bytes;
    m.attr("streaming_stores") = streaming_stores;
}

}  // namespace bindings
}  // namespace epc_fast
