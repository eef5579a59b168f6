"""The worker: its session protocol, its workloads and its counted runs, in this process."""

import io
import json
import subprocess
import sys

import numpy as np
import pytest

import epc_fast
from epc_fast import _core
from epc_fast.benchcompare import worker
from epc_fast.benchcompare.sides import WORKER


def _session(*requests):
    out = io.StringIO()
    worker.serve(io.StringIO("".join(json.dumps(r) + "\n" for r in requests)), out)
    return [json.loads(line) for line in out.getvalue().splitlines()]


def test_a_session_sets_up_times_and_quits():
    setup, timed = _session(
        {"op": "setup", "workloads": {"default-1e4": 2000, "spectrum": 500, "nonsense": 10},
         "seed": 1},
        {"op": "time", "workload": "spectrum", "reps": 3},
        {"op": "quit"}, {"op": "time", "workload": "spectrum", "reps": 1})
    assert setup["build"]["isa"] == _core.isa
    assert setup["build"]["version"] == epc_fast.__version__
    assert set(setup["seconds"]) == {"default-1e4", "spectrum"}
    assert all(s > 0 for s in setup["seconds"].values())
    # an unknown workload (as an older install's missing keyword) is named, not fatal
    assert "nonsense" in setup["unavailable"]["nonsense"]
    assert timed["seconds"] > 0  # and nothing after quit is answered


def test_an_unknown_request_is_answered_with_an_error():
    (answer,) = _session({"op": "launch"})
    assert answer == {"error": "unknown op 'launch'"}


def test_the_workloads_compute_what_evaluate_computes():
    points = worker.designs(300, seed=4)
    assert set(points) == {"illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm",
                           "sensor_area_mm2", "read_noise_e", "shake_deg_per_s"}
    result = worker.make_call("float32", 300, seed=4)()
    expected = epc_fast.evaluate(**points, precision="float32", threads=1)
    np.testing.assert_array_equal(result.epc, expected.epc)
    f50_epc = worker.make_call("f50-epc", 300, seed=4)()
    assert f50_epc.status is None  # those two outputs alone
    np.testing.assert_array_equal(f50_epc.epc, epc_fast.evaluate(**points, threads=1).epc)
    elasticities = worker.make_call("elasticities", 300, seed=4)()
    assert elasticities.elasticities  # the elasticities are computed
    scan = worker.make_call("scan", 4000, seed=4)()
    assert scan["summary"].count.sum() == 4000
    phone = worker.make_call("phone", 300, seed=4)()
    keywords = worker.phone(300, seed=4)
    np.testing.assert_array_equal(phone.epc, epc_fast.evaluate(**keywords, threads=1).epc)
    assert np.all(phone.mode >= 0) and len(set(phone.mode.tolist())) >= 2  # the modes matter


def test_every_workload_runs_and_its_sizes_are_whole():
    for name, (full, quick, threads, what) in worker.WORKLOADS.items():
        assert full >= 10_000 and (quick is None or quick <= full) and threads in (1, 2), name
        assert what
        assert worker.make_call(name, 64, seed=0)() is not None


def test_the_worker_file_runs_as_a_script_in_another_python():
    spec = {"workloads": {"few": ["default-1e4", 100], "many": ["default-1e4", 400]},
            "calls": {"many": 2}, "seed": 0}
    done = subprocess.run([sys.executable, str(WORKER), "count", json.dumps(spec)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.splitlines()[-1])["isa"] == _core.isa
    usage = subprocess.run([sys.executable, str(WORKER)], capture_output=True, text=True,
                           timeout=60)
    assert usage.returncode == 2 and "usage" in usage.stderr


def test_an_unknown_workload_is_refused_by_name():
    with pytest.raises(ValueError, match="workload 'fast'"):
        worker.make_call("fast", 10, seed=0)
