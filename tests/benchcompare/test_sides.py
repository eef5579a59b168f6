"""``epc-fast bench compare`` against sides that fail: a side that stops answering (in its
setup or mid-rounds) is killed, its whole process group with it, after ``--timeout``; one that
answers garbage, JSON of the wrong shape, or times that are not a positive number of seconds
ends the comparison with a line naming the side and the fault. The sides here are fake
workers (FAKE_SIDE), so that every test runs in a second or two."""

import json
import shlex
import sys
import time
from pathlib import Path

import pytest

from epc_fast.__main__ import main
from epc_fast.benchcompare.compare import run_comparison
from epc_fast.benchcompare.sides import TIMEOUT, Side

#: A worker that speaks the protocol of epc_fast.benchcompare.worker with made-up answers.
#: Its first argument is JSON: {op: reply} for "setup" and "time", a reply being "ok" (a
#: well-formed answer), "hang" (no answer, ever), another string (printed as it is) or any
#: other JSON value (printed as JSON); "pids": a file to which it appends its own process id
#: and that of a child it starts, which sleeps, in its process group; "stderr": bytes it
#: writes to its stderr before each answer.
FAKE_SIDE = '''
import json, os, subprocess, sys, time
behaviour = json.loads(sys.argv[1])
if "pids" in behaviour:
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    with open(behaviour["pids"], "a") as handle:
        handle.write(f"{os.getpid()} {child.pid}\\n")
build = {"version": "0.0", "isa": "fake", "openmp": False, "python": "3", "numpy": "2",
         "executable": sys.executable, "module": "fake"}
for line in sys.stdin:
    request = json.loads(line)
    if request["op"] == "quit":
        break
    reply = behaviour.get(request["op"], "ok")
    sys.stderr.write("x" * behaviour.get("stderr", 0))
    sys.stderr.flush()
    if reply == "hang":
        time.sleep(600)
    if reply == "ok" and request["op"] == "setup":
        reply = {"build": build, "seconds": {name: 0.001 for name in request["workloads"]},
                 "unavailable": {}}
    elif reply == "ok":
        reply = {"seconds": 0.001, "cpu_seconds": 0.001}
    print(reply if isinstance(reply, str) else json.dumps(reply), flush=True)
'''


@pytest.fixture
def fake(tmp_path):
    """fake(**behaviour): the command line of a fake side."""
    script = tmp_path / "fake_side.py"
    script.write_text(FAKE_SIDE)

    def command(**behaviour):
        return " ".join(shlex.quote(word) for word in
                        (sys.executable, str(script), json.dumps(behaviour)))
    return command


def _compare(tmp_path, baseline, candidate, *options):
    return main(["bench", "compare", "--only", "default-1e4", "--rounds", "3", "--blocks", "1",
                 "--out", str(tmp_path / "out"), *options, baseline, candidate])


def _running(pid: int) -> bool:
    """Whether the process is alive (a zombie, dead and not yet reaped, is not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rpartition(")")[2].split()[0] not in ("Z", "X")


def _all_gone(pids_file: Path) -> bool:
    pids = [int(word) for word in pids_file.read_text().split()]
    assert len(pids) >= 4  # both sides and their children
    deadline = time.monotonic() + 10
    while any(_running(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    return not any(_running(pid) for pid in pids)


@pytest.mark.parametrize("op", ["setup", "time"])
@pytest.mark.parametrize("hung", ["BASELINE", "CANDIDATE"])
def test_a_side_that_stops_answering_is_killed_with_its_process_group_and_named(
        op, hung, fake, tmp_path, capsys):
    pids = tmp_path / "pids"
    sides = [fake(pids=str(pids)), fake(pids=str(pids), **{op: "hang"})]
    started = time.monotonic()
    code = _compare(tmp_path, *(sides if hung == "CANDIDATE" else sides[::-1]),
                    "--timeout", "1")
    assert code == 1 and time.monotonic() - started < 30
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"{hung} " in err and f"no answer to {op} within 1 s (--timeout)" in err
    assert "killed" in err
    assert _all_gone(pids)  # the hung side, the other side, and both their children
    assert not (tmp_path / "out" / "compare.json").exists()


def test_the_timeout_has_a_default_of_minutes_not_forever():
    assert 60 <= TIMEOUT <= 3600
    side = Side("BASELINE", shlex.quote(sys.executable) + " -c pass")
    try:
        assert side.timeout == TIMEOUT
    finally:
        side.close()


def test_run_comparison_takes_a_timeout(fake):
    with pytest.raises(RuntimeError, match=r"CANDIDATE .*no answer to setup within 0\.5 s"):
        run_comparison(fake(), fake(setup="hang"), rounds=3, blocks=1, only=["default-1e4"],
                       timeout=0.5)


@pytest.mark.parametrize("op, reply", [("setup", "garbage"), ("time", "garbage"),
                                       ("setup", "{\"build\":"), ("time", "1.5 seconds")])
def test_a_side_that_answers_garbage_is_named(op, reply, fake, tmp_path, capsys):
    code = _compare(tmp_path, fake(), fake(**{op: reply}))
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "CANDIDATE " in err and f"answered {op} with {reply!r}: not JSON" in err
    assert "JSONDecodeError" not in err


BUILD = {"version": "0.0", "isa": "fake", "openmp": False, "python": "3", "module": "fake"}


@pytest.mark.parametrize("op, reply, words", [
    ("setup", [1, 2], "answered setup with a JSON array, expected an object"),
    ("time", 3, "answered time with a JSON number, expected an object"),
    ("setup", {"build": BUILD, "unavailable": {}}, "answered setup without 'seconds'"),
    ("setup", {"seconds": {"default-1e4": 0.001}, "unavailable": {}},
     "answered setup without 'build'"),
    ("setup", {"build": {"isa": "fake"}, "seconds": {"default-1e4": 0.001}, "unavailable": {}},
     "answered setup with a build without 'version'"),
    ("setup", {"build": BUILD, "seconds": {}, "unavailable": {}},
     "answered setup with neither a time nor a reason for default-1e4"),
    ("setup", {"build": BUILD, "seconds": {"default-1e4": "fast"}, "unavailable": {}},
     "its setup time of default-1e4 is 'fast': expected a finite number of seconds above 0"),
    ("time", {"seconds": 0.001}, "answered time without 'cpu_seconds'"),
    ("time", {"cpu_seconds": 0.001}, "answered time without 'seconds'"),
])
def test_a_side_that_answers_the_wrong_json_is_named(op, reply, words, fake, tmp_path, capsys):
    code = _compare(tmp_path, fake(**{op: reply}), fake())
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "BASELINE " in err and words in err
    assert "KeyError" not in err and "TypeError" not in err


@pytest.mark.parametrize("value, shown", [(float("nan"), "nan"), (0, "0"), (-0.001, "-0.001"),
                                          (float("inf"), "inf"), (True, "True")])
@pytest.mark.parametrize("key", ["cpu_seconds", "seconds"])
def test_a_time_that_is_not_a_positive_number_of_seconds_is_named(key, value, shown, fake,
                                                                  tmp_path, capsys):
    reply = {"seconds": 0.001, "cpu_seconds": 0.001, key: value}
    code = _compare(tmp_path, fake(), fake(time=reply))
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "CANDIDATE " in err
    assert (f"its time ({key}) of default-1e4 is {shown}: expected a finite number of "
            f"seconds above 0") in err


@pytest.mark.parametrize("value, shown", [(float("nan"), "nan"), (0.0, "0.0"), (-1, "-1")])
def test_a_setup_time_that_is_not_a_positive_number_of_seconds_is_named(value, shown, fake,
                                                                        tmp_path, capsys):
    reply = {"build": BUILD, "seconds": {"default-1e4": value}, "unavailable": {}}
    code = _compare(tmp_path, fake(setup=reply), fake())
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "BASELINE " in err
    assert (f"its setup time of default-1e4 is {shown}: expected a finite number of seconds "
            f"above 0") in err


def test_a_side_that_writes_much_to_its_stderr_is_not_taken_for_a_hung_one(fake, tmp_path):
    # more than a pipe holds before each answer: a stderr no one reads would stop the worker
    assert _compare(tmp_path, fake(), fake(stderr=2**20), "--timeout", "20") == 0


def test_well_behaved_fake_sides_compare_as_the_same(fake, tmp_path):
    assert _compare(tmp_path, fake(), fake()) == 0
    report = json.loads((tmp_path / "out" / "compare.json").read_text())
    assert report["passed"] is True and report["baseline"]["isa"] == "fake"
