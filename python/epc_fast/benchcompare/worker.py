"""One side of a benchmark comparison: the workloads, run in the Python of the install measured.

``epc-fast bench compare`` starts this file as a script in each side's Python (a venv's
``python``, ``env EPC_FAST_ISA=x86-64 python``, an older release), so it imports nothing of the
comparison and only the public API of whichever ``epc_fast`` that Python has: an install
from before this module existed runs it too. Its designs are drawn here, with NumPy's
``default_rng``, so that both sides evaluate the same points whatever their version ships.

Two ways to run it:

* ``python worker.py serve``: a session on stdin/stdout, one JSON object a line. ``{"op":
  "setup", "workloads": {name: points}, "seed": s}`` draws the designs and runs each workload
  twice (answered with the build, and each workload's seconds in its second call or why it
  cannot run);
  ``{"op": "time", "workload": name, "reps": k}`` answers the mean seconds of ``k`` calls in a
  row, wall time (``seconds``) and the process's CPU time, all its threads (``cpu_seconds``);
  ``{"op": "quit"}`` ends it.
* ``python worker.py count SPEC``: SPEC is JSON ``{"workloads": {key: [name, points]},
  "calls": {key: k}, "seed": s}``; the designs are drawn, every entry runs once, then each key
  of ``calls`` ``k`` more times, on one thread. An instruction counter around the whole process
  subtracts two such runs (:mod:`epc_fast.benchcompare.counts`), so that start-up cancels.
"""

from __future__ import annotations

import gc
import json
import os
import sys
import time

#: name -> (points of the full comparison, of --quick (None: not in it), threads, what it is).
#: The default call is timed at 10^4, 10^6 (one thread) and 10^7 points (two threads, as a
#: caller's default on two cores); the others on one thread, where another process's load moves
#: a call least.
WORKLOADS = {
    "default-1e4": (10_000, 10_000, 1, "evaluate(), default outputs, float64"),
    "default-1e6": (1_000_000, 1_000_000, 1, "evaluate(), default outputs, float64"),
    "default-1e7": (10_000_000, None, 2, "evaluate(), default outputs, float64, 2 threads"),
    "f50-epc": (1_000_000, None, 1, "evaluate(outputs=('f50_cyc_per_mm', 'epc'))"),
    "float32": (1_000_000, 100_000, 1, "evaluate(precision='float32')"),
    "spectrum": (100_000, 10_000, 1, "evaluate(spectrum=3 wavelengths)"),
    "elasticities": (100_000, 10_000, 1, "evaluate(outputs=(..., 'elasticities'))"),
    "scan": (1_000_000, 100_000, 1, "scan.run(): Monte Carlo over the paper's designs, summary "
             "and quantiles by design"),
    "phone": (100_000, 10_000, 1, "evaluate(outputs=('epc',)): a phone at f/2, a Bayer sensor "
              "(Malvar), a 7-point lens table, denoising 1 px, three readout modes"),
}
SPECTRUM = ([450.0, 550.0, 650.0], [0.25, 0.5, 0.25])
#: cycles/mm and 1: the phone's lens, below f/2's diffraction at 550 nm.
PHONE_LENS = ([0.0, 50.0, 100.0, 150.0, 200.0, 250.0, 300.0],
              [1.0, 0.88, 0.74, 0.60, 0.47, 0.36, 0.27])
#: The phone's readout modes: full size, 2 x 2, 2 x 2 x 4 frames.
PHONE_MODES = [{"binning": 1}, {"binning": 2}, {"binning": 2, "frames": 4}]


def designs(n: int, seed: int) -> dict:
    """``n`` phone-camera designs and scenes (the ranges of epc_fast.selfcheck.random_designs),
    drawn here rather than by that function: the worker runs inside either side's install, and
    both sides must draw the same designs whatever their version of epc_fast."""
    import numpy as np

    rng = np.random.default_rng(seed)
    return {
        "illuminance_lux": 10 ** rng.uniform(0, 5, n),
        "pixel_pitch_um": rng.uniform(0.8, 3.0, n),
        "f_number": rng.uniform(1.4, 8.0, n),
        "focal_length_mm": rng.uniform(2.0, 20.0, n),
        "sensor_area_mm2": rng.uniform(1.0, 40.0, n),
        "read_noise_e": np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0, 5, n)),
        "shake_deg_per_s": rng.uniform(0.0, 10.0, n),
    }


def phone(n: int, seed: int) -> dict:
    """``n`` scenes of one phone camera (1-100,000 lux, pitches 0.8-3 um; f/2, 5.6 mm, 20 mm^2,
    read noise 1.5 e-, 4.39 deg/s) with the terms a real phone adds, as evaluate's keywords."""
    import numpy as np

    rng = np.random.default_rng(seed)
    return {"illuminance_lux": 10 ** rng.uniform(0, 5, n),
            "pixel_pitch_um": rng.uniform(0.8, 3.0, n), "f_number": 2.0,
            "focal_length_mm": 5.6, "sensor_area_mm2": 20.0, "read_noise_e": 1.5,
            "shake_deg_per_s": 4.39, "cfa": "bayer", "demosaic": "malvar2004",
            "lens_mtf": PHONE_LENS, "denoise_sigma_px": 1.0, "modes": PHONE_MODES}


def _evaluate_call(points, threads, **options):
    import epc_fast

    def call():
        return epc_fast.evaluate(**points, threads=threads, **options)
    return call


def _scan_call(n, threads, seed):
    from epc_fast import scan
    from epc_fast.presets import HIGH_TIER

    space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 100_000),
                       shake_deg_per_s=scan.LogNormal(median=4.39, sigma=0.5),
                       read_noise_e=scan.Choice([0.0, 2.0], weights=[0.3, 0.7]))

    def call():
        reductions = {"summary": scan.Summary(by="design"),
                      "quantiles": scan.Quantiles([0.05, 0.5, 0.95], by="design")}
        return scan.run(space, points=n, seed=seed, threads=threads, reductions=reductions)
    return call


def make_call(name: str, n: int, seed: int, threads: int | None = None):
    """A function of no arguments that runs workload ``name`` on ``n`` points."""
    if name not in WORKLOADS:
        raise ValueError(f"workload {name!r}: expected one of {', '.join(WORKLOADS)}")
    threads = WORKLOADS[name][2] if threads is None else threads
    if name == "scan":
        return _scan_call(n, threads, seed)
    if name == "phone":
        return _evaluate_call(phone(n, seed), threads, outputs=("epc",))
    points = designs(n, seed)
    if name.startswith("default"):
        return _evaluate_call(points, threads)
    if name == "float32":
        return _evaluate_call(points, threads, precision="float32")
    if name == "spectrum":
        return _evaluate_call(points, threads, spectrum=SPECTRUM)
    if name == "f50-epc":
        return _evaluate_call(points, threads, outputs=("f50_cyc_per_mm", "epc"))
    return _evaluate_call(points, threads, outputs=("epc", "f50_cyc_per_mm", "status",
                                                    "elasticities"))


def build() -> dict:
    """What this side runs: version, the core's level, OpenMP, the Python, NumPy and the
    module file."""
    import numpy

    import epc_fast
    from epc_fast import _core

    return {"version": epc_fast.__version__, "isa": _core.isa,
            "openmp": bool(_core.openmp_enabled()), "python": sys.version.split()[0],
            "numpy": numpy.__version__, "executable": sys.executable,
            "module": os.path.dirname(epc_fast.__file__)}


def _setup(request) -> dict:
    calls, seconds, unavailable = {}, {}, {}
    for name, n in request["workloads"].items():
        try:
            call = make_call(name, int(n), int(request["seed"]))
            call()  # the first call pays for the output cache's and the threads' start
            start = time.perf_counter()
            call()
            seconds[name] = time.perf_counter() - start
            calls[name] = call
        except Exception as exc:  # an older install may lack a workload's keyword
            unavailable[name] = f"{type(exc).__name__}: {exc}"
    return calls, {"build": build(), "seconds": seconds, "unavailable": unavailable}


def serve(stdin, stdout) -> None:
    """Answers setup, time and quit requests, one JSON line each, until quit or end of input."""
    calls = {}
    for line in stdin:
        request = json.loads(line)
        if request["op"] == "quit":
            break
        if request["op"] == "setup":
            calls, answer = _setup(request)
        elif request["op"] == "time":
            call, reps = calls[request["workload"]], int(request["reps"])
            start, start_cpu = time.perf_counter(), time.process_time()
            for _ in range(reps):
                call()
            answer = {"seconds": (time.perf_counter() - start) / reps,
                      "cpu_seconds": (time.process_time() - start_cpu) / reps}
        else:
            answer = {"error": f"unknown op {request['op']!r}"}
        stdout.write(json.dumps(answer) + "\n")
        stdout.flush()


def count(spec: dict) -> None:
    """Every entry of ``spec['workloads']`` ({key: [workload, points]}) called once, then each
    key of ``spec['calls']`` ({key: k}) ``k`` more times, on one thread. Python's garbage
    collector is off: a collection, run or not depending on what else the process holds,
    costs as many instructions as thousands of points."""
    gc.disable()
    calls = {key: make_call(name, int(n), int(spec["seed"]), threads=1)
             for key, (name, n) in spec["workloads"].items()}
    for call in calls.values():
        call()
    for key, k in spec.get("calls", {}).items():
        for _ in range(int(k)):
            calls[key]()
    print(json.dumps(build()))


def main(argv) -> int:
    if argv[:1] == ["serve"]:
        # the protocol owns stdout; anything the package prints goes to stderr
        protocol = os.fdopen(os.dup(sys.stdout.fileno()), "w")
        sys.stdout = sys.stderr
        serve(sys.stdin, protocol)
        return 0
    if argv[:1] == ["count"] and len(argv) == 2:
        count(json.loads(argv[1]))
        return 0
    print("usage: worker.py serve | worker.py count SPEC_JSON", file=sys.stderr)
    return 2


if __name__ == "__main__":
    # run as a script: its own folder leaves the import path, so that `import epc_fast` finds
    # the side's install and no module of this folder stands in for a standard one
    sys.path.pop(0)
    sys.exit(main(sys.argv[1:]))
