"""The C++ drivers in tools/ (kernel_speed, stage_costs, memory_floor) build against the current
headers and compute what they say, and stage_ab.py compares two stage_costs builds: the README
quotes them, so they must not rot.

Built once with the system's C++ compiler, at -O1 without -march (fast to build; the unfused
arithmetic of the package's baseline module), and run on a few points: their speeds are not
checked here, only that they run and compute the right thing.
"""
from __future__ import annotations

import re
import shutil
import subprocess

import pytest

import epc_fast
from helpers.scripts import ROOT, load_script

TOOLS = ("kernel_speed", "stage_costs", "memory_floor")
COMPILER = shutil.which("g++") or shutil.which("c++")

#: tools/phone_designs.h's first design (std::mt19937_64 seeded with 1, libstdc++'s
#: uniform_real_distribution), as the driver holds it, to 17 digits.
FIRST_DESIGN = dict(illuminance_lux=4.67071340789433, pixel_pitch_um=1.100095480005634,
                    f_number=4.3780183653739515, focal_length_mm=2.3784361115010864,
                    sensor_area_mm2=14.685026437533864, read_noise_e=2.3537606624511618,
                    shake_deg_per_s=0.74425040071166726)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    if COMPILER is None:
        pytest.skip("no C++ compiler on this machine")
    if not (ROOT / "tools" / "kernel_speed.cpp").exists():
        pytest.skip("tools/ is not beside the tests (an installed package)")
    out = tmp_path_factory.mktemp("tools")
    paths = {}
    for name in TOOLS:
        paths[name] = out / name
        subprocess.run([COMPILER, "-std=c++17", "-O1", "-fopenmp", "-I", str(ROOT / "cpp" / "include"),
                        str(ROOT / "tools" / f"{name}.cpp"), "-o", str(paths[name])],
                       check=True, capture_output=True, text=True)
    return paths


def _run(path, *args):
    return subprocess.run([str(path), *map(str, args)], check=True, capture_output=True,
                          text=True, timeout=120).stdout


@pytest.mark.heavy  # compiles tools/*.cpp: about 80 s on 2 cores
def test_kernel_speed_solves_the_first_design_as_evaluate_does(built):
    text = _run(built["kernel_speed"], 300, 1)
    f50 = float(re.search(r"f50\[0\] = ([0-9.eE+-]+)", text).group(1))
    expected = float(epc_fast.evaluate(**FIRST_DESIGN).f50_cyc_per_mm)
    # the driver's unfused build and the installed (fused) module may differ in the last bits
    assert f50 == pytest.approx(expected, rel=1e-14)
    assert re.search(r"best [0-9.]+ M points/s", text)


@pytest.mark.heavy  # compiles tools/*.cpp: about 80 s on 2 cores
@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_stage_costs_reports_the_five_stages_that_add_up_to_the_whole(built, precision):
    text = _run(built["stage_costs"], 256, 2, precision)
    total = float(re.search(r"([0-9.]+) ns a point in all", text).group(1))
    stages = dict(re.findall(r"^\s+(gather|exposure|f50 start|f50 solve|scatter)\s+(-?[0-9.]+) ns",
                             text, re.M))
    assert list(stages) == ["gather", "exposure", "f50 start", "f50 solve", "scatter"]
    # the stages are differences of cumulative times, so they add up to the last one (the
    # printout rounds each to 0.01 ns)
    assert sum(float(v) for v in stages.values()) == pytest.approx(total, abs=0.03)
    assert total > 0


@pytest.mark.heavy  # compiles tools/*.cpp: about 80 s on 2 cores
@pytest.mark.parametrize("mode, per_round", [("default", 7), ("lean", 6), ("out", 7),
                                             ("stream", 7)])
def test_memory_floor_writes_the_outputs_it_times(built, mode, per_round):
    # Output 0 at point i is (1 + i % 7)(1 + (i + 1) % 7) and the first code column is
    # (1 + (i + 6) % 7 > 3) with six float64 outputs (default, out, stream) or
    # (1 + (i + 2) % 7 > 3) with two (lean), input k holding 1 + (i + k) % 7; the driver sums
    # output 0 at n/2 and code 0 at n/3 each round. n = 5000: 2500 % 7 = 1 gives 2 * 3 = 6;
    # 1666 % 7 = 0 gives 7 > 3, a 1 (default, out, stream), or 3 > 3, a 0 (lean).
    rounds = 3
    text = _run(built["memory_floor"], 5000, mode, rounds, 2)
    assert float(re.search(r"check ([0-9.eE+-]+)", text).group(1)) == rounds * per_round
    assert re.search(r"best [0-9.]+ M points/s", text)


@pytest.mark.heavy  # compiles tools/*.cpp: about 80 s on 2 cores
def test_stage_ab_alternates_two_builds_and_keeps_each_stages_least(built, tmp_path):
    stage_ab = load_script("tools/stage_ab.py")
    other = tmp_path / "stage_costs_copy"
    shutil.copy(built["stage_costs"], other)
    results = stage_ab.compare((built["stage_costs"], other), 2, (256, 2, "float64"))
    assert list(results) == [built["stage_costs"], other]
    for r in results.values():
        assert len(r["totals"]) == 2 and min(r["totals"]) > 0
        assert all(r[s] <= max(r["totals"]) for s in stage_ab.STAGES)
    text = stage_ab.report(results)
    assert text.count("least by stage: gather") == 2 and "f50 solve" in text


@pytest.mark.heavy  # compiles tools/*.cpp: about 80 s on 2 cores
def test_stage_ab_refuses_a_printout_without_every_stage_and_one_build_twice(built):
    stage_ab = load_script("tools/stage_ab.py")
    with pytest.raises(ValueError, match="no f50 solve, scatter"):
        stage_ab.parse("1 points: 3.00 ns a point in all\n  gather 1.00 ns\n  exposure 1.00 ns\n"
                       "  f50 start 1.00 ns\n")
    with pytest.raises(ValueError, match="binaries: must be different"):
        stage_ab.compare((built["stage_costs"], built["stage_costs"]), 1, (256, 1))


def test_the_mpmath_check_finds_the_reference_within_1e13_of_mpmath():
    pytest.importorskip("mpmath")
    from epc_fast.selfcheck import random_designs

    tool = load_script("tools/mpmath_check.py")
    points = random_designs(8, seed=5)
    check = tool.mpmath_check(points, epc_fast.evaluate(**points, backend="reference"), 8)
    assert check.points == 8 and check.status_mismatches == 0
    # the reference bisects f50 to adjacent floats: a few ulp of 50-digit truth
    assert check.max_rel_error["f50_cyc_per_mm"] <= 1e-13
    assert "8 points" in check.summary()


def test_the_mpmath_check_counts_a_wrong_status(capsys):
    pytest.importorskip("mpmath")
    from epc_fast.selfcheck import random_designs

    tool = load_script("tools/mpmath_check.py")
    points = random_designs(4, seed=5)
    reference = epc_fast.evaluate(**points, backend="reference")
    reference.status[1] = epc_fast.Status.INVALID  # one point's status made wrong
    assert tool.mpmath_check(points, reference, 4).status_mismatches == 1
    assert tool.main(["--points", "3", "--error-points", "8", "--seed", "5"]) == 0
    assert capsys.readouterr().out.startswith("reference vs mpmath (50 digits) on 3 points: 0 ")


def test_keyword_costs_times_every_case_against_the_scene_alone():
    tool = load_script("tools/keyword_costs.py")
    rate, by_case = tool.ratios(points=2_000, rounds=1)
    assert rate > 0 and by_case["the scene alone"] == 1.0
    assert list(by_case) == list(tool.CASES)
    assert all(ratio > 0 for ratio in by_case.values())
