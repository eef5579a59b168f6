"""Many Python threads calling the engine at once, and Ctrl-C during a long call.

The core releases the GIL while it computes and keeps no state between calls: threads calling
it together must get exactly (bit for bit) what each call gets alone. A long call checks for
Ctrl-C between chunks of api.CHUNK_POINTS points and must stop there with KeyboardInterrupt.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import epc_fast
from epc_fast import api
from helpers.child_env import with_python_path
from helpers.designs import random_design_points

FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc",
          "status", "cause")
THREADS = 8
CALLS_PER_THREAD = 25


@pytest.fixture(scope="module")
def points():
    return random_design_points(20_000, seed=8)


def _call(points, start, stop, options):
    part = {k: v[start:stop] for k, v in points.items()}
    if options.pop("out", False):
        out = {name: np.empty(stop - start, dtype=dtype)
               for name, dtype in api.OUTPUT_DTYPES.items()}
        return epc_fast.evaluate(**part, out=out, **options)
    return epc_fast.evaluate(**part, **options)


def _jobs(n_points, seed):
    """Slices of every size (1 to 2000 points, unaligned to the 64-point blocks) with every
    option that changes the code path: thread counts, Brent, out=, the reference."""
    rng = np.random.default_rng(seed)
    choices = [dict(threads=1), dict(threads=2), dict(threads=3, t_mpe_solver="brent"),
               dict(threads=1, out=True), dict(backend="reference")]
    jobs = []
    for _ in range(THREADS * CALLS_PER_THREAD):
        size = int(rng.integers(1, 2000))
        start = int(rng.integers(0, n_points - size))
        jobs.append((start, start + size, dict(choices[int(rng.integers(len(choices)))])))
    return jobs


def test_eight_threads_calling_at_once_get_exactly_the_serial_answers(points):
    jobs = _jobs(len(points["illuminance_lux"]), seed=1)
    serial = [_call(points, start, stop, dict(options)) for start, stop, options in jobs]
    with ThreadPoolExecutor(max_workers=THREADS) as pool:
        threaded = list(pool.map(lambda job: _call(points, job[0], job[1], dict(job[2])), jobs))
    for (start, stop, options), a, b in zip(jobs, serial, threaded):
        for name in FIELDS:
            x, y = getattr(a, name), getattr(b, name)
            # Bit for bit: as float64 bits, NaN == NaN and -0.0 != 0.0.
            assert np.array_equal(x.view(np.uint64) if x.dtype == np.float64 else x,
                                  y.view(np.uint64) if y.dtype == np.float64 else y), (
                name, start, stop, options)


def test_threads_sharing_one_input_array_and_writing_their_own_outputs_agree(points):
    # Every thread reads the same (read-only) arrays and writes its own out= arrays.
    shared = {k: v.copy() for k, v in points.items()}
    for v in shared.values():
        v.flags.writeable = False
    expected = epc_fast.evaluate(**shared, threads=1)

    def run(_):
        out = {name: np.empty(len(shared["illuminance_lux"]), dtype=dtype)
               for name, dtype in api.OUTPUT_DTYPES.items()}
        return epc_fast.evaluate(**shared, out=out, threads=1)

    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(run, range(4)))
    for r in results:
        for name in FIELDS:
            np.testing.assert_array_equal(getattr(r, name), getattr(expected, name), name)


def test_threads_passing_kept_output_memory_between_them_get_the_serial_answers():
    # Calls of 140-200 thousand points: their float64 outputs (above 1 MiB) take memory from
    # the core's output cache (epc_fast.memory), which results dropped on other threads give
    # back while the GIL is released around the kernels. Each answer must be the slice of one
    # serial call on NumPy's own memory, bit for bit.
    n = 200_000
    points = random_design_points(n, seed=9)
    before = epc_fast.output_cache().limit_bytes
    epc_fast.output_cache(0)
    try:
        expected = epc_fast.evaluate(**points, threads=1)
        epc_fast.output_cache(256 * 2**20)
        rng = np.random.default_rng(2)
        sizes = rng.integers(140_000, n, 40)
        jobs = [(int(start), int(start + size), int(threads)) for start, size, threads in
                zip(rng.integers(0, n - sizes), sizes, rng.integers(1, 3, 40))]

        def run(job):
            start, stop, threads = job
            result = epc_fast.evaluate(**{k: v[start:stop] for k, v in points.items()},
                                       threads=threads)
            same = all(getattr(result, name).tobytes() == getattr(expected, name)[start:stop]
                       .tobytes() for name in FIELDS)
            return same, epc_fast.output_cache().retained_bytes

        with ThreadPoolExecutor(max_workers=4) as pool:
            outcomes = list(pool.map(run, jobs))
        assert all(same for same, _ in outcomes)
        # the cache was in use: some call found blocks kept by another one's dropped result
        assert max(kept for _, kept in outcomes) > 0
    finally:
        epc_fast.output_cache(0)
        epc_fast.output_cache(before)


# --- Ctrl-C -------------------------------------------------------------------------------------

#: The child: times one chunk, then starts a call twelve chunks long and reports how it ended.
#: A 16-line spectrum and f50_rtol=0 make each chunk long enough (about a second here) for the
#: signal to land inside one. helpers.core_override (tests/ on the child's PYTHONPATH) keeps a
#: sanitizer run sanitized. The child installs Python's SIGINT handler itself: a child inherits
#: SIGINT ignored from a test run started as a background job, and Python then leaves it ignored.
CHILD = """
import signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)
from helpers.core_override import load_core_override
load_core_override()
import numpy as np, epc_fast
from epc_fast import api

spectrum = (np.linspace(400.0, 700.0, 16), np.ones(16))
def run(n):
    lux = np.geomspace(1e-2, 1e5, n)
    return epc_fast.evaluate(lux, 1.4, 2.8, 5.6, sensor_area_mm2=15.6751, read_noise_e=2.0,
                             spectrum=spectrum, f50_rtol=0.0, threads=1)
t0 = time.perf_counter()
run(api.CHUNK_POINTS)
print("chunk", time.perf_counter() - t0, flush=True)
print("started", flush=True)
t0 = time.perf_counter()
try:
    run(12 * api.CHUNK_POINTS)
except KeyboardInterrupt:
    print("interrupted", time.perf_counter() - t0, flush=True)
    sys.exit(0)
print("finished", time.perf_counter() - t0, flush=True)
sys.exit(3)
"""


def test_ctrl_c_stops_a_long_call_at_the_next_chunk_boundary():
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True,
                             env=with_python_path(Path(__file__).parent))
    try:
        chunk_s = float(child.stdout.readline().split()[1])
        assert child.stdout.readline().strip() == "started"
        time.sleep(min(1.0, 2.0 * chunk_s))  # well inside the call, which lasts 12 chunks
        sent = time.perf_counter()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
        latency = time.perf_counter() - sent
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == 0, out + err
    assert out.startswith("interrupted"), out + err
    # The call notices at the end of the chunk it is in: at most one chunk, plus the time to
    # leave the interpreter; 3 chunks + 2 s leave room for a loaded machine.
    assert latency < 3.0 * chunk_s + 2.0, (latency, chunk_s)
    assert float(out.split()[1]) < 6.0 * chunk_s + 2.0  # far from the 12 chunks of the call
