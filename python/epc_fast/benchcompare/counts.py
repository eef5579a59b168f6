"""Instructions a point of each workload costs, counted rather than timed, against a committed
table per build: a second gate whose verdict another process's load does not move.

The counter is Linux ``perf stat -e instructions:u`` where the machine's hardware counters are
readable, else valgrind's cachegrind (``--cache-sim=no``: instructions only, about 50 times
slower than running natively, and no AVX-512: it cannot run the x86-64-v4 build). Each count
subtracts two runs of the worker (:func:`epc_fast.benchcompare.worker.count`) that hold the
same designs and run every workload once, then ``EXTRA_CALLS`` more calls of one workload, on
fewer points in one run and on more in the other: the difference is the calls' extra points
and nothing else (Python's start-up, the imports, drawing the designs, the first call's
allocations and every call's fixed cost all cancel), divided by those points. A call's fixed
cost (:data:`PER_CALL`) is counted alike, as the difference of a run with ``CALLS`` more calls
of one point and one without them, divided by the calls.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

from .sides import WORKER, split_command

#: name -> (the worker's workload, fewer points, more points): small sizes, for the counter's
#: sake. A count a point does not depend on the size beyond these (every point is computed on
#: its own).
COUNTED = {
    "default": ("default-1e4", 10_000, 40_000),
    "f50_epc": ("f50-epc", 10_000, 40_000),
    "float32": ("float32", 10_000, 40_000),
    "spectrum": ("spectrum", 3_000, 12_000),
    "elasticities": ("elasticities", 3_000, 12_000),
    "scan": ("scan", 10_000, 40_000),
}
EXTRA_CALLS = 2
#: name -> (the worker's workload, its points): a call's fixed cost, the instructions of
#: ``CALLS`` more calls of one point, a call: evaluate's Python layer, the binding and one
#: block of the kernel.
PER_CALL = {"call": ("default-1e4", 1)}
CALLS = 20
SEED = 7
#: Relative rise of a count a point beyond which the gate fails.
TOLERANCE = 0.01
#: The builds counted by default: cachegrind runs no AVX-512, so not x86-64-v4.
DEFAULT_ISAS = ("x86-64", "x86-64-v3")


def _perf_works() -> bool:
    if shutil.which("perf") is None:
        return False
    try:
        out = subprocess.run(["perf", "stat", "-x,", "-e", "instructions:u", "--", "true"],
                             capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return out.returncode == 0 and re.search(r"^\d+,", out.stderr, re.M) is not None


def _valgrind_works() -> bool:
    if shutil.which("valgrind") is None:
        return False
    try:
        out = subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=no",
                              "--cachegrind-out-file=/dev/null", "true"],
                             capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return out.returncode == 0


def counter() -> str | None:
    """``"perf"``, ``"cachegrind"``, or None when neither counts instructions here."""
    if _perf_works():
        return "perf"
    if _valgrind_works():
        return "cachegrind"
    return None


NO_COUNTER = ("no instruction counter works on this machine: `perf stat -e instructions:u` "
              "reports no hardware counter (or perf is missing) and valgrind is not installed; "
              "install valgrind (e.g. apt-get install valgrind) or run where perf can read the "
              "counters")


def _run_counted(tool: str, words: list, spec: dict, folder: Path) -> int:
    """User-space instructions of one worker run (every process it starts)."""
    args = [*words, str(WORKER), "count", json.dumps(spec)]
    # pytest's variables (a test's name, an xdist worker's) left out: the environment's size
    # moves where the process's memory lands, which moves a call's count by up to 1.3%
    env = {name: value for name, value in os.environ.items() if not name.startswith("PYTEST_")}
    env.update(PYTHONHASHSEED="0", OMP_NUM_THREADS="1")
    if tool == "perf":
        out_file = folder / "perf.txt"
        cmd = ["perf", "stat", "-x,", "-e", "instructions:u", "-o", str(out_file), "--", *args]
    else:
        for old in folder.glob("cg.*"):
            old.unlink()
        cmd = ["valgrind", "--tool=cachegrind", "--cache-sim=no", "--trace-children=yes",
               f"--cachegrind-out-file={folder}/cg.%p", *args]
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if done.returncode != 0:
        tail = " | ".join(done.stderr.strip().splitlines()[-4:])
        raise RuntimeError(f"the counted run failed ({' '.join(words)}): {tail}")
    if tool == "perf":
        text = out_file.read_text()
        return sum(int(m.group(1)) for m in re.finditer(r"^(\d+),", text, re.M))
    return sum(cachegrind_instructions(path.read_text()) for path in folder.glob("cg.*"))


#: The C library's memory copies and allocator, which cachegrind's counts leave out: their
#: count depends on where the arrays land (``rep movsb`` copies a block as one instruction, a
#: vector loop as many, chosen by alignment and size), not on the code measured.
LEFT_OUT = re.compile(r"^(__)?(mem(cpy|move|set)|(_int_)?(malloc|free|realloc|calloc)|"
                      r"malloc_consolidate|unlink_chunk|tcache)")


def cachegrind_instructions(text: str) -> int:
    """The instructions of a cachegrind output file, less those of :data:`LEFT_OUT`'s
    functions."""
    total, left_out = 0, False
    for line in text.splitlines():
        if line.startswith("fn="):
            left_out = LEFT_OUT.match(line[3:]) is not None
        elif line[:1].isdigit() and not left_out:
            fields = line.split()
            if len(fields) >= 2:
                total += int(fields[1])
    return total


def count_per_point(python: str, isa: str | None, tool: str, names=None, progress=None) -> dict:
    """{"isa", "tool", "version", "instructions_per_point": {name: count}} of one build: the
    side's Python, with EPC_FAST_ISA set to ``isa`` when given."""
    if tool == "cachegrind" and isa == "x86-64-v4":
        raise RuntimeError("valgrind's cachegrind runs no AVX-512: it cannot count the "
                           "x86-64-v4 build (perf can, where the hardware counters are "
                           "readable)")
    words = split_command(python, "--python")
    if isa is not None:
        words = ["env", f"EPC_FAST_ISA={isa}", *words]
    names = [*COUNTED, *PER_CALL] if names is None else list(names)
    workloads = {}
    for name in (n for n in names if n in COUNTED):
        workload, fewer, more = COUNTED[name]
        workloads[f"{name}@fewer"] = [workload, fewer]
        workloads[f"{name}@more"] = [workload, more]
    say = progress or (lambda line: None)
    per_point, per_call = {}, {}
    with tempfile.TemporaryDirectory(prefix="epc-fast-counts-") as tmp:
        def run(calls: dict, held: dict) -> int:
            return _run_counted(tool, words, {"workloads": held, "seed": SEED,
                                              "calls": calls}, Path(tmp))

        for name in names:
            say(f"{isa or 'default build'}: counting {name} ({tool})")
            if name in PER_CALL:  # in a worker of its own: a call's cost is the same alone
                one = {f"{name}@one": list(PER_CALL[name])}
                runs = [run({f"{name}@one": k}, one) for k in (0, CALLS)]
                per_call[name] = round((runs[1] - runs[0]) / CALLS)
                continue
            runs = [run({f"{name}@{size}": EXTRA_CALLS}, workloads)
                    for size in ("fewer", "more")]
            _, fewer, more = COUNTED[name]
            per_point[name] = round((runs[1] - runs[0]) / (EXTRA_CALLS * (more - fewer)), 1)
    build = json.loads(subprocess.run([*words, str(WORKER), "count", json.dumps(
        {"workloads": {}, "seed": SEED})], capture_output=True, text=True,
        check=True).stdout.strip().splitlines()[-1])
    measured = {"isa": build["isa"], "tool": tool, "version": build["version"],
                "points": {n: list(COUNTED[n][1:]) for n in names if n in COUNTED},
                "instructions_per_point": per_point}
    if per_call:  # Python's and NumPy's own code is part of a call's count
        measured["instructions_per_call"] = per_call
        measured["call_runtime"] = {"python": build["python"], "numpy": build["numpy"]}
    return measured


def compare_counts(measured: dict, table: dict, tolerance: float = TOLERANCE) -> list:
    """Rows (name, committed, measured, ratio, verdict): ``"MORE"`` when a count rose by more
    than ``tolerance`` (the gate fails), ``"fewer"`` when it fell by more (update the table),
    ``"new"`` when the table lacks it, else ``"same"``. The counts a point come first, then
    those a call (:data:`PER_CALL`), which count Python's and NumPy's own code too: ``"other
    Python or NumPy"`` (no verdict) when the table's were others."""
    rows = []
    other_runtime = measured.get("call_runtime") != table.get("call_runtime")
    for section in ("instructions_per_point", "instructions_per_call"):
        old = table.get(section, {})
        for name, count in measured.get(section, {}).items():
            if name not in old:
                rows.append((name, None, count, None, "new"))
                continue
            if section == "instructions_per_call" and other_runtime:
                rows.append((name, old[name], count, count / old[name], "other Python or NumPy"))
                continue
            ratio = count / old[name]
            verdict = ("MORE" if ratio > 1 + tolerance else
                       "fewer" if ratio < 1 - tolerance else "same")
            rows.append((name, old[name], count, ratio, verdict))
    return rows
