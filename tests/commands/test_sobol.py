"""``epc-fast sobol``: what it writes in --out, under the scan's output policy (the indices
themselves are tested with their config in tests/scan/test_config_indices.py)."""

import os

import pytest

from epc_fast.__main__ import main
from epc_fast.jobs.output import OutputLock


def test_an_out_another_run_writes_in_is_refused_naming_that_run(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    holder = OutputLock(out)
    holder.acquire()
    try:
        code = main(["sobol", "--out", str(out), "--overwrite", "--points", "16"])
    finally:
        holder.release()
    captured = capsys.readouterr()
    assert code == 2 and captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith(f"epc-fast sobol: error: --out '{out}': another run writes "
                                   f"here: pid {os.getpid()} on ")
    assert list(out.iterdir()) == []


SCAN = """\
[scan]
points = 131072
seed = 7

[design]
presets = ["HIGH_TIER"]

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }
shake_deg_per_s = { distribution = "lognormal", median = 4.39, sigma = 0.5 }

[reductions.summary]
kind = "summary"
by = "design"

[reductions.best]
kind = "top_k"
k = 3
"""


def test_overwrite_into_a_scans_out_leaves_no_file_of_that_scan(tmp_path, capsys):
    pytest.importorskip("pyarrow")
    config = tmp_path / "scan.toml"
    config.write_text(SCAN + '[output]\nparquet = "points"\n')
    out = tmp_path / "out"
    assert main(["scan", str(config), "--out", str(out), "--no-progress", "--no-plots",
                 "--chunk-points", "65536"]) == 0
    (out / "notes.txt").write_text("keep me\n")
    (out / "points" / "mine.txt").write_text("keep me\n")
    assert main(["sobol", str(config), "--out", str(out), "--overwrite", "--points", "16"]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "points", "sobol.csv",
                                                     "sobol.md"]
    assert [p.name for p in (out / "points").iterdir()] == ["mine.txt"]


def test_a_design_error_names_the_sobol_config(tmp_path, capsys):
    # the sobol command reads a scan's config file with the scan's parser: its mistakes are
    # the sobol config's
    config = tmp_path / "scan.toml"
    config.write_text(SCAN.replace('"HIGH_TIER"', '"NOPE"'))
    assert main(["sobol", str(config), "--out", str(tmp_path / "out"), "--points", "16"]) == 2
    assert capsys.readouterr().err.startswith(
        "epc-fast sobol: error: sobol config [design]: presets: 'NOPE' is not a preset")
