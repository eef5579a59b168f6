"""``epc-fast bench``: one quick run of the command, its table, CSV and plot."""

import csv
import importlib.util
import subprocess
import sys


def test_quick_bench_writes_its_table_and_plot(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "epc_fast", "bench", "--quick", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "| setting | f50 solver | rtol | precision | max rel err |" in proc.stdout
    assert (tmp_path / "trade.md").is_file()
    if importlib.util.find_spec("matplotlib") is not None:
        assert (tmp_path / "trade.png").stat().st_size > 0
    with open(tmp_path / "trade.csv", newline="") as handle:
        rows = {row["setting"]: row for row in csv.DictReader(handle)}
    default = rows["default"]
    assert float(default["max_rel_error"]) <= 1e-12
    assert int(default["status_mismatches"]) == 0
    assert float(default["speedup_vs_default"]) == 1.0
    assert float(default["points_per_s_2_threads"]) > 0
