// The module's concepts, each added to it by one register function in register_<concept>.cpp;
// module.cpp calls them all.
#pragma once

#include <pybind11/pybind11.h>

// The module's name (CMakeLists.txt: one module per instruction-set level).
#ifndef EPC_FAST_MODULE
#define EPC_FAST_MODULE _core_generic
#endif

namespace epc_fast {
namespace bindings {

// evaluate: the model over columns of designs, and the parameters' names and order.
void register_evaluate(pybind11::module_& m);
// lux_for_epc and crossover_lux: the illuminance at which a design reaches an EPC, or two
// designs have equal EPC (inverse.h).
void register_inverse(pybind11::module_& m);
// scan_chunk and scan_points: the fused scan pass and its points (scan/pass.h).
void register_scan(pybind11::module_& m);
// best_mode and take_mode: readout modes' pick of the best mode per point (modes.h).
void register_modes(pybind11::module_& m);
// output_cache: the memory kept for evaluate's output arrays (output_cache.h).
void register_memory(pybind11::module_& m);
// The build and the machine: the module's name and levels, threads, block and streaming sizes.
void register_cpu(pybind11::module_& m);
// The submodule `testing`: single formulas and stages, elementwise, for the tests and the
// benchmarks' peers.
void register_testing(pybind11::module_& m);

}  // namespace bindings
}  // namespace epc_fast
