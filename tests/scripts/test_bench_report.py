"""bench/report.py: the Markdown tables it makes from a pytest-benchmark JSON run."""

import pytest

from helpers.scripts import load_script


@pytest.fixture(scope="module")
def report():
    return load_script("bench/report.py")


def _bench(name, median_s, group="evaluate 1e6 points", **extra_info):
    return {"name": name, "group": group, "stats": {"median": median_s}, "extra_info": extra_info}


def _run(*benchmarks):
    return {"datetime": "2026-11-22", "machine_info": {}, "commit_info": {},
            "benchmarks": list(benchmarks)}


def test_ratios_are_of_points_per_second_against_the_groups_peers(report):
    text = report.report(_run(
        _bench("test_core", 0.02, peer="core", points=10**6, max_rel_error=1.9e-13),
        _bench("test_numba", 0.16, peer="numba", points=10**6),
        # the reference on a tenth of the points in a fifth of the time: half the points/s
        _bench("test_reference", 0.032, peer="reference", points=10**5)))
    core_row = next(line for line in text.splitlines() if line.startswith("| test_core "))
    cells = [c.strip() for c in core_row.strip("|").split("|")]
    # name, median, points, M points/s, vs reference, vs numba, same algorithm, errors
    assert cells[2] == "1,000,000"
    assert cells[3] == "50"            # 1e6 / 0.02 s
    assert cells[4] == "16×"           # 50 M/s against 3.125 M/s
    assert cells[5] == "8×"            # 50 M/s against 6.25 M/s
    assert cells[7] == "1.9e-13"


def test_a_paired_benchmark_is_a_row_of_its_own_table_not_of_the_group_table(report):
    paired = _bench("test_paired_core_vs_numba", 1.0, paired=True, pair_points=10**6,
                    first="core, 2 threads", second="numba", paired_rounds=9,
                    first_points_per_s=4.2e7, second_points_per_s=5.0e6,
                    speedup_median=8.4, speedup_min=7.9, speedup_max=9.95)
    text = report.report(_run(_bench("test_numba", 0.2, peer="numba", points=10**6), paired))
    lines = text.splitlines()
    assert not any(line.startswith("| test_paired") for line in lines)
    row = next(line for line in lines if line.startswith("| core, 2 threads vs numba"))
    assert [c.strip() for c in row.strip("|").split("|")] == [
        "core, 2 threads vs numba", "9", "42", "5", "8.4×", "7.9×", "9.95×"]
    # the group's own table comes first, then the pairs'
    assert lines.index(row) > next(i for i, line in enumerate(lines) if line.startswith("| test_numba"))


def test_a_group_of_pairs_run_without_timing_gets_an_empty_table_not_an_error(report):
    # --benchmark-disable: the pair ran once, untimed, and recorded no speed-up
    text = report.report(_run(_bench("test_paired_2_threads_vs_1", 0.5, paired=True,
                                     first="core, 2 threads", second="core, 1 thread")))
    assert "| pair, taken in turn |" in text
    assert "core, 2 threads vs" not in text
