#!/usr/bin/env bash
# Regenerate the committed benchmark baseline in one command (see bench/README.md):
#
#     bench/save_baseline.sh            # every benchmark in bench/, full sizes (~10 minutes)
#     bench/save_baseline.sh -k 1e6     # extra arguments go to pytest
#
# Runs `python -m pytest bench --benchmark-only` and saves the run as
# bench/baselines/<machine id>/0001_baseline.json (machine id: pytest-benchmark's
# "<OS>-<implementation>-<Python major.minor>-<bits>", e.g. Linux-CPython-3.11-64bit), after
# deleting this machine id's previous baseline so that the number stays 0001 and the regression
# command's --benchmark-compare=0001_baseline finds it; then writes the Markdown tables of
# bench/report.py beside it (0001_baseline.md). Run it on an otherwise idle machine, from any
# directory, with the package installed as it should be measured.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -n "${EPC_FAST_BENCH_QUICK:-}" ] && [ "${EPC_FAST_BENCH_QUICK}" != "0" ]; then
    echo "save_baseline.sh: unset EPC_FAST_BENCH_QUICK: a baseline is of the full sizes" >&2
    exit 2
fi

storage=bench/baselines
machine_id=$(python -c "from pytest_benchmark.utils import get_machine_id; print(get_machine_id())")
mkdir -p "$storage/$machine_id"
rm -f "$storage/$machine_id"/[0-9][0-9][0-9][0-9]_baseline.json \
      "$storage/$machine_id"/[0-9][0-9][0-9][0-9]_baseline.md

python -m pytest bench --benchmark-only -q --benchmark-save=baseline \
    --benchmark-storage="file://$storage" "$@"

saved="$storage/$machine_id/0001_baseline.json"
if [ ! -f "$saved" ]; then
    echo "save_baseline.sh: expected $saved; other runs in $storage/$machine_id?" >&2
    ls "$storage/$machine_id" >&2
    exit 1
fi
python bench/report.py "$saved" > "${saved%.json}.md"
echo "Baseline: $saved (tables: ${saved%.json}.md)"
