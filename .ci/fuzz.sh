#!/usr/bin/env bash
# A bounded run of the coverage-guided fuzz target fuzz/fuzz_evaluate.py (atheris, libFuzzer),
# then every input it kept replayed against the sanitizer build that .ci/sanitize.sh leaves in
# build/sanitize. (Fuzzing under the sanitizer itself is not possible with GCC's runtime: its
# coverage hooks shadow libFuzzer's and blind the search.) A crash, a sanitizer finding or a
# broken invariant fails the run and leaves its input in build/fuzz-artifacts/. FUZZ_SECONDS
# (default 60) bounds the search; the corpus grows in build/fuzz-corpus/ across local runs.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${FUZZ_SECONDS:-60}"
build=build/sanitize
if ! compgen -G "$build/_core_*.so" >/dev/null; then
    echo "fuzz.sh: no sanitizer build in $build: run .ci/sanitize.sh first" >&2
    exit 2
fi
python -m pip install --quiet --prefer-binary "atheris>=2.3"  # wheels: no clang needed
mkdir -p build/fuzz-corpus build/fuzz-artifacts
options=(-timeout=60 -rss_limit_mb=4096 -artifact_prefix=build/fuzz-artifacts/
         -print_final_stats=1)

echo "fuzz.sh: searching for ${seconds} s (installed core)"
python fuzz/fuzz_evaluate.py build/fuzz-corpus -max_total_time="$seconds" "${options[@]}" \
    2>&1 | grep -v "^INFO: Instrumenting"

echo "fuzz.sh: replaying $(ls build/fuzz-corpus | wc -l) corpus inputs under the sanitizers"
cxx="${CXX:-g++}"
EPC_FAST_CORE_DIR="$PWD/$build" \
ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:allocator_may_return_null=1" \
UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
LD_PRELOAD="$("$cxx" -print-file-name=libasan.so) $("$cxx" -print-file-name=libubsan.so)" \
    python fuzz/fuzz_evaluate.py build/fuzz-corpus -runs=0 "${options[@]}" 2>&1 \
    | grep -v -e "^INFO: Instrumenting" -e "^WARNING: Coverage symbols" -e "^You can likely"
