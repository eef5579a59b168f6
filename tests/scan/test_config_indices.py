"""The ``[sobol]`` table of a scan config, ``epc-fast scan`` with it, and ``epc-fast sobol``:
the keys and their errors, the files written and their values."""

import csv
import json

import numpy as np
import pytest

from epc_fast.__main__ import main
from epc_fast.scan import sobol_indices
from epc_fast.scan.config import parse_config
from epc_fast.scan.config.indices import SobolConfig
from epc_fast.jobs.errors import ConfigError, OutputError, TooLargeError

SCAN = """\
[scan]
points = 70_000
seed = 11

[design]
presets = ["HIGH_TIER"]

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }
shake_deg_per_s = { distribution = "lognormal", median = 4.39, sigma = 0.5 }

[reductions.summary]
kind = "summary"
by = "design"
"""
SOBOL = SCAN + """
[sobol]
points = 256
of = ["epc", "log_epc"]
confidence = 0.9
"""


def test_an_empty_sobol_table_asks_for_the_defaults_seeded_with_the_scan():
    config = parse_config(SCAN + "[sobol]\n")
    assert config.sobol == SobolConfig(points=4096, seed=11, of=("epc",), confidence=0.95,
                                       resamples=100, not_ok="raise")
    assert parse_config(SCAN).sobol is None


def test_every_sobol_key_reads_as_the_argument_it_names():
    config = parse_config(SCAN + '[sobol]\npoints = 1024\nseed = 3\nof = "log_epc"\n'
                          'confidence = 0.99\nresamples = 50\nnot_ok = "raise"\n')
    assert config.sobol.kwargs() == {"points": 1024, "seed": 3, "of": ("log_epc",),
                                     "confidence": 0.99, "resamples": 50, "not_ok": "raise"}


@pytest.mark.parametrize("table, message", [
    ("points = 1000", "[sobol]: points = 1000: expected a power of 2, at least 16"),
    ("points = 8", "[sobol]: points = 8: expected an integer between 16 and"),
    ("points = 1024.5", "[sobol]: points = 1024.5: expected an integer"),
    ("seed = -1", "[sobol]: seed = -1: expected an integer between 0 and"),
    ('of = "lux"', """[sobol]: of = 'lux': expected "epc" or "log_epc", or a list of them"""),
    ("of = []", "[sobol]: of = []: expected"),
    ('of = ["epc", "epc"]', "[sobol]: of = ['epc', 'epc']: expected"),
    ("confidence = 1", "[sobol]: confidence = 1.0: expected a finite number in (0, 1)"),
    ("resamples = 1", "[sobol]: resamples = 1: expected an integer between 2 and"),
    ('not_ok = "drop"', """[sobol]: not_ok = 'drop': expected one of "raise", "zero\""""),
    ('not_ok = "zero"\nof = "log_epc"', '[sobol]: not_ok = "zero" counts unreachable points as '
                                        "EPC 0, whose log is -inf: it cannot go with of = "
                                        "['log_epc']"),
    ("point = 1024", "[sobol]: unknown key(s) point; known: points, seed, of"),
])
def test_a_sobol_key_error_names_the_key_and_value(table, message):
    with pytest.raises(ConfigError) as error:
        parse_config(SCAN + "[sobol]\n" + table + "\n")
    assert str(error.value).startswith("scan config ") and message in str(error.value)


def test_sizes_past_their_bounds_are_refused_before_any_work():
    with pytest.raises(TooLargeError, match=r"\[sobol\]: points x resamples of 13,107,200"):
        parse_config(SCAN + "[sobol]\npoints = 131072\n")
    three = SCAN.replace("[reductions.summary]", "read_noise_e = { grid = [0, 2] }\n\n"
                         "[reductions.summary]")
    with pytest.raises(TooLargeError, match=r"\[sobol\]: the design's values \(points x rows x "
                                            r"3 parameters\) of 62,914,560"):
        parse_config(three + "[sobol]\npoints = 4194304\nresamples = 2\n")


def test_a_space_without_random_parameters_has_no_sobol_indices():
    text = '[scan]\npoints = 10\n[design]\npresets = ["HIGH_TIER"]\n[parameters]\n' \
           "illuminance_lux = 100\n[sobol]\n"
    with pytest.raises(ConfigError, match=r"\[sobol\]: the space has no random parameter"):
        parse_config(text)


def test_a_reduction_writing_sobol_csv_clashes_with_the_indices(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(SOBOL + '[reductions.sobol]\nkind = "top_k"\nk = 3\n')
    assert main(["scan", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "the [sobol] indices and reduction 'sobol' (top_k) would both write sobol.csv" in err


def _rows(path) -> list[dict]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_the_scan_command_writes_the_indices_of_its_sobol_table(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(SOBOL)
    out = tmp_path / "out"
    assert main(["scan", str(path), "--out", str(out), "--no-progress", "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "Sobol' indices of epc and log_epc over 2 random parameter(s): 256 base points, " \
           "1,024 evaluations per design (4 designs), seed 11, 90% intervals: " in printed
    rows = _rows(out / "sobol.csv")
    config = parse_config(SOBOL)
    expected = sobol_indices(config.space, **config.sobol.kwargs())
    assert len(rows) == 2 * 4 * 2
    columns = expected.table()
    assert list(rows[0]) == list(columns)
    for name in ("S1", "S1 +-90%", "ST", "ST +-90%"):
        # The CSV holds each float at full precision (repr): equal to the last bit.
        np.testing.assert_array_equal([float(r[name]) for r in rows], columns[name])
    assert (out / "sobol.md").read_text().startswith("Sobol' indices of epc and log_epc")
    manifest = json.loads((out / "manifest.json").read_text())
    assert {"sobol.csv", "sobol.md"} <= set(manifest["files"])
    assert manifest["state"] == "complete"


def test_the_sobol_command_computes_the_indices_alone_with_its_overrides(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(SOBOL)
    out = tmp_path / "out"
    assert main(["sobol", str(path), "--out", str(out), "--points", "128", "--seed", "5"]) == 0
    printed = capsys.readouterr().out
    assert "128 base points, 512 evaluations per design (4 designs), seed 5" in printed
    assert sorted(p.name for p in out.iterdir()) == ["sobol.csv", "sobol.md"]
    config = parse_config(SOBOL)
    expected = sobol_indices(config.space, points=128, seed=5, of=("epc", "log_epc"),
                             confidence=0.9)
    np.testing.assert_array_equal([float(r["ST"]) for r in _rows(out / "sobol.csv")],
                                  expected.table()["ST"])
    # A second run is refused (not empty), and with --overwrite replaces the two files only.
    (out / "notes.txt").write_text("kept")
    assert main(["sobol", str(path), "--out", str(out), "--points", "64"]) == 2
    assert "--out" in capsys.readouterr().err
    assert main(["sobol", str(path), "--out", str(out), "--points", "64", "--overwrite"]) == 0
    assert "64 base points" in (out / "sobol.md").read_text()
    assert (out / "notes.txt").read_text() == "kept"


def test_the_sobol_command_without_a_table_takes_the_defaults(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(SCAN)
    assert main(["sobol", str(path), "--out", str(tmp_path / "out"), "--points", "64"]) == 0
    assert "Sobol' indices of epc over 2 random parameter(s): 64 base points, 256 " \
           "evaluations per design (4 designs), seed 11, 95% intervals" in capsys.readouterr().out


def test_unreachable_points_end_the_sobol_command_with_one_line_naming_the_policy(tmp_path,
                                                                                   capsys):
    path = tmp_path / "scan.toml"
    path.write_text(SCAN.replace("[reductions.summary]", "full_well_e = { distribution = "
                                 "\"uniform\", low = 500, high = 2000 }\n\n[reductions.summary]"))
    assert main(["sobol", str(path), "--out", str(tmp_path / "out"), "--points", "64"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("epc-fast sobol: error: sobol config [sobol]: Sobol' indices of design "
                          "'1/3.2\" 2.8 um': ") and "not_ok='zero'" in err
    assert err.count("\n") == 1


@pytest.mark.parametrize("value", ["1000", "8", "2**10", "1e3"])
def test_the_sobol_command_refuses_points_that_are_not_a_power_of_2(tmp_path, capsys, value):
    with pytest.raises(SystemExit) as stop:
        main(["sobol", "--out", str(tmp_path / "out"), "--points", value])
    assert stop.value.code == 2
    assert f"--points {value!r}: expected a power of 2 between 16 and" in capsys.readouterr().err


def test_the_output_policy_refuses_a_file_where_the_indices_go(tmp_path):
    from epc_fast.jobs.output import OutputDirectory

    (tmp_path / "out" / "sobol.csv").mkdir(parents=True)
    with pytest.raises(OutputError, match="sobol.csv is a directory"):
        OutputDirectory(tmp_path / "out", overwrite=True).prepare(
            {"sobol.csv": "the Sobol' indices"})


@pytest.mark.parametrize("line, message", [
    ("reflectance = 2.0", "[parameters]: reflectance = 2: expected a value in [0, 1]"),
    ("f_number = -2", "[parameters]: f_number = -2: expected a value in (1e-30, inf)"),
])
def test_a_value_outside_its_domain_ends_the_sobol_command_before_any_point(tmp_path, capsys,
                                                                            line, message):
    # Unchecked, reflectance = 2.0 ended in "IndexError: too many indices for array".
    path = tmp_path / "scan.toml"
    path.write_text(SCAN.replace("[reductions.summary]", line + "\n\n[reductions.summary]"))
    assert main(["sobol", str(path), "--out", str(tmp_path / "out"), "--points", "64"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("epc-fast sobol: error: sobol config") and message in err, err
    assert err.count("\n") == 1 and not (tmp_path / "out").exists()


def test_without_salib_the_sobol_command_stops_before_any_point(tmp_path, capsys, monkeypatch):
    import sys

    for module in ("SALib", "SALib.sample.sobol", "SALib.analyze.sobol"):
        monkeypatch.setitem(sys.modules, module, None)
    path = tmp_path / "scan.toml"
    path.write_text(SCAN)
    assert main(["sobol", str(path), "--out", str(tmp_path / "out"), "--points", "64"]) == 2
    assert capsys.readouterr().err == ("epc-fast sobol: error: SALib is needed for Sobol' "
                                       "indices and is not installed: pip install "
                                       "'epc-fast[sensitivity]'\n")
    assert not (tmp_path / "out").exists()
