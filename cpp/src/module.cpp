// The extension module of one instruction-set level: each concept registers its functions
// (register.h).
#include <pybind11/pybind11.h>

#include "register.h"

PYBIND11_MODULE(EPC_FAST_MODULE, m) {
    using namespace epc_fast::bindings;
    m.doc() = "epc_fast's compiled core for one instruction-set level; epc_fast._core picks one.";
    register_cpu(m);
    register_evaluate(m);
    register_scan(m);
    register_memory(m);
    register_modes(m);
    register_inverse(m);
    register_testing(m);
}
