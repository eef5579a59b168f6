#!/usr/bin/env bash
# The core once more, built with AddressSanitizer and UndefinedBehaviorSanitizer (every finding
# fatal), and the extremes, bad-input, concurrency and fused-scan tests run against that build's
# baseline module; then the stream and scan tests against each vector module this CPU runs
# (x86-64-v3, x86-64-v4), whose intrinsics (Philox, the inverse normal CDF's tail gathers) and
# vector loops (the Sobol' points) the baseline never reaches. The installed package supplies the Python side; tests/conftest.py
# loads the sanitized modules from EPC_FAST_CORE_DIR. CPython leaks by design, so leak detection is off; an impossible
# allocation returns NULL (NumPy then raises MemoryError, which the tests expect) instead of
# aborting.
set -euo pipefail
cd "$(dirname "$0")/.."

python -m pip install --quiet "cmake>=3.18" "pybind11>=2.12" ninja
cxx="${CXX:-g++}"
asan="$("$cxx" -print-file-name=libasan.so)"
ubsan="$("$cxx" -print-file-name=libubsan.so)"
if [[ ! -e "$asan" || ! -e "$ubsan" ]]; then
    apt-get install -y --no-install-recommends libasan8 libubsan1 >/dev/null
    asan="$("$cxx" -print-file-name=libasan.so)"
    ubsan="$("$cxx" -print-file-name=libubsan.so)"
fi

build=build/sanitize
cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DEPC_FAST_SANITIZE=ON -DEPC_FAST_DISPATCH=ON -DCMAKE_CXX_FLAGS="-fno-sanitize-recover=all" \
    -DPython_EXECUTABLE="$(command -v python)" -Dpybind11_DIR="$(python -m pybind11 --cmakedir)" \
    >/dev/null
cmake --build "$build"

export EPC_FAST_CORE_DIR="$PWD/$build"
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
LD_PRELOAD="$asan $ubsan" python -m pytest -p no:cacheprovider -q -n 0 \
    tests/test_extremes.py tests/test_bad_input.py tests/test_concurrency.py \
    tests/core/test_spectrum_start.py tests/test_memory.py tests/core/test_f50_start.py \
    tests/core/test_precision.py tests/core/test_stream.py tests/scan/running/test_core_plan.py \
    tests/scan/sampling/test_qmc.py tests/test_sensitivity.py tests/reference/test_sensitivity.py tests/test_elasticity_outputs.py \
    tests/test_axes.py tests/test_modes.py tests/core/test_tabulated.py \
    tests/core/test_lens_tables.py tests/core/test_lens_start.py tests/core/test_demosaic_start.py \
    tests/scan/running/test_camera_terms.py "$@"

levels="$(python -c 'import epc_fast._core as c
print(" ".join(level for level, ok in c._module.cpu_levels().items() if ok))')"
for level in x86-64-v3 x86-64-v4; do
    if [[ " $levels " != *" $level "* ]]; then
        echo "sanitize.sh: this CPU does not run $level: its module is not tested"
        continue
    fi
    echo "sanitize.sh: $level"
    EPC_FAST_ISA="$level" LD_PRELOAD="$asan $ubsan" python -m pytest -p no:cacheprovider -q -n 0 \
        tests/core/test_stream.py tests/scan/running/test_core_plan.py tests/scan/sampling/test_streams.py \
        tests/scan/sampling/test_qmc.py \
        tests/scan/test_reductions.py tests/scan/running/test_runner.py tests/test_sensitivity.py \
        tests/reference/test_sensitivity.py tests/test_elasticity_outputs.py \
        tests/scan/running/test_camera_terms.py "$@"
done
