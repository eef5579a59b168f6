"""``epc-fast optimize``: its config (the scan's space tables, [optimize]), the files it writes
(JSON, Markdown, CSV, the curve's PNG) with the numbers the Python API gives, and its
refusals (a config mistake named in one line, a non-empty --out)."""

import csv
import json
import sys

import numpy as np
import pytest

from epc_fast import optimize, scan
from epc_fast.__main__ import main
from epc_fast.optimize.config import load_optimize_config
from helpers.scripts import ROOT

CONFIG = """\
[optimize]
points = 20_000
seed = 3
batches = 4
curve_points = 5

[optimize.bounds]
pixel_pitch_um = [0.8, 4.0]

[optimize.objective]
kind = "quantile"
q = 0.5

[[design.custom]]
name = "1/3.2 inch"
sensor_width_mm = 4.57
sensor_height_mm = 3.43
f_number = 2.8
focal_length_mm = 5.6

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }
"""
#: The same problem through the Python API.
SPACE = scan.Space(design=[{"name": "1/3.2 inch", "sensor_width_mm": 4.57,
                            "sensor_height_mm": 3.43, "f_number": 2.8, "focal_length_mm": 5.6,
                            "pixel_pitch_um": 1.0}],
                   illuminance_lux=scan.LogUniform(10, 1e5))


def _optimize(tmp_path, capsys, text=CONFIG, *args, out="out"):
    path = tmp_path / "optimize.toml"
    path.write_text(text)
    code = main(["optimize", str(path), "--out", str(tmp_path / out), *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_the_command_writes_the_optimum_and_its_curve(tmp_path, capsys):
    code, out, err = _optimize(tmp_path, capsys)
    assert code == 0 and err == ""
    written = tmp_path / "out"
    assert sorted(p.name for p in written.iterdir()) == ["curve.csv", "curve.png",
                                                         "optimum.json", "optimum.md"]
    assert (written / "curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    expected = optimize.maximize(SPACE, {"pixel_pitch_um": (0.8, 4.0)}, optimize.Quantile(0.5),
                                 points=20_000, seed=3, batches=4)
    document = json.loads((written / "optimum.json").read_text())
    assert document["x"] == expected.x and document["value"] == expected.value
    assert document["x_standard_error"] == expected.x_standard_error
    assert document["objective"]["kind"] == "Quantile" and document["config"] == CONFIG
    assert (written / "optimum.md").read_text() == expected.markdown() + "\n"
    with open(written / "curve.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [float(r["value"]) for r in rows] == list(np.linspace(0.8, 4.0, 5))
    assert max(float(r["objective"]) for r in rows) <= expected.value
    assert all(float(r["standard_error"]) > 0 for r in rows)
    assert expected.markdown() in out
    assert "held: the sensor's area (sensor_area_mm2); its pixel count follows the pitch" in out
    assert f"wrote {written / 'curve.png'}" in out


def test_a_non_empty_out_is_refused_unless_overwrite(tmp_path, capsys):
    assert _optimize(tmp_path, capsys, CONFIG, "--no-plot")[0] == 0
    assert not (tmp_path / "out" / "curve.png").exists()
    code, out, err = _optimize(tmp_path, capsys)
    assert code == 2 and out == ""
    assert err.startswith("epc-fast optimize: error: --out ") and "is not empty" in err
    assert not (tmp_path / "out" / "curve.png").exists()
    assert _optimize(tmp_path, capsys, CONFIG, "--overwrite")[0] == 0
    assert (tmp_path / "out" / "curve.png").exists()


@pytest.mark.parametrize("change, key", [
    (("q = 0.5", "q = 1.5"), "[optimize.objective]: q = 1.5"),
    (('kind = "quantile"\nq = 0.5', 'kind = "median"'), "[optimize.objective]: kind = 'median'"),
    (("pixel_pitch_um = [0.8, 4.0]", "pixel_pitch_um = [4.0, 0.8]"),
     "[optimize.bounds]: pixel_pitch_um = [4.0, 0.8]"),
    (("pixel_pitch_um = [0.8, 4.0]", "pitch = [0.8, 4.0]"),
     "[optimize.bounds]: unknown parameter 'pitch'"),
    (("pixel_pitch_um = [0.8, 4.0]", "pixel_pitch_um = [0.8, 4.0]\nfocal_length_mm = [4, 8]"),
     "[optimize.bounds]: bounds: focal_length_mm of a design that meets its SNR target at the "
     "image corner"),
    (("[parameters]\n", "[parameters]\npixel_pitch_um = 1.4\n"),
     "[parameters]: pixel_pitch_um is optimised"),
    (("batches = 4", "batches = 1"), "[optimize]: batches = 1"),
    (("points = 20_000", "points = 0"), "[optimize]: points = 0"),
    (("seed = 3\n", "seed = 3\nrounds = 2\n"), "[optimize]: unknown key(s) rounds"),
    # Unchecked, these three ended in exit code 1 and "... at index (0,) is outside its domain"
    (("[parameters]\n", "[parameters]\nreflectance = 2.0\n"),
     "[parameters]: reflectance = 2: expected a value in [0, 1] (1: reflectance"),
    (("f_number = 2.8", "f_number = -2"),
     "[design.custom[0]] '1/3.2 inch': f_number = -2: expected a value in (1e-30, inf)"),
    (("pixel_pitch_um = [0.8, 4.0]", "pixel_pitch_um = [-1.0, 1.0]"),
     "[optimize.bounds]: pixel_pitch_um = [-1.0, 1.0]: expected both bounds in (0, 1e+30) "
     "(um: pixel pitch)"),
    # Unchecked, these two named [parameters] and a midpoint the user never wrote (2.5), and
    # ended in exit code 1 ("designs read differently" raised by the Problem)
    (("pixel_pitch_um = [0.8, 4.0]", "pixel_pitch_um = [0.8, 4.0]\nbinning = [1, 4]"),
     "[optimize.bounds]: binning = [1, 4]: binning takes whole numbers only"),
    (("focal_length_mm = 5.6\n", 'focal_length_mm = 5.6\nmodes = [{binning = 1}, {binning = 2}]\n\n'
      '[[design.custom]]\nname = "B"\nsensor_width_mm = 4.57\nsensor_height_mm = 3.43\n'
      'f_number = 2.8\nfocal_length_mm = 5.6\n'),
     "[design]: the optimiser reads every design one way"),
])
def test_a_config_error_is_one_line_naming_the_key_with_exit_code_2(tmp_path, capsys, change,
                                                                     key):
    old, new = change
    assert old in CONFIG
    code, out, err = _optimize(tmp_path, capsys, CONFIG.replace(old, new))
    assert code == 2 and out == ""
    assert err.startswith("epc-fast optimize: error: optimize config") and key in err, err
    assert err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_the_example_config_is_the_documented_problem():
    config = load_optimize_config(ROOT / "examples" / "optimize_pitch.toml")
    assert config.bounds == {"pixel_pitch_um": (0.8, 4.0)}
    assert config.objective == optimize.Quantile(0.5)
    assert config.points == 10_000_000 and config.seed == 2009 and config.batches == 10
    assert config.space.design_table["sensor_area_mm2"][0] == pytest.approx(4.57 * 3.43)
    assert config.space.design_snr_at[0].startswith("corner (27.03 deg")
    assert config.space.axes["shake_deg_per_s"] == 4.39


def test_the_example_runs_on_fewer_points(tmp_path, capsys):
    code = main(["optimize", str(ROOT / "examples" / "optimize_pitch.toml"), "--points", "2e4",
                 "--out", str(tmp_path / "out"), "--no-plot"])
    out = capsys.readouterr().out
    assert code == 0 and "optimum of median EPC over 20,000 draws" in out
    document = json.loads((tmp_path / "out" / "optimum.json").read_text())
    # the median light's best pitch, about 3.06 um (docs/optimize.md), within the ~0.01 um
    # Monte Carlo error of 2 x 10^4 draws several times over
    assert 2.95 < document["x"]["pixel_pitch_um"] < 3.17


def test_without_matplotlib_the_command_stops_before_any_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    code, out, err = _optimize(tmp_path, capsys)
    assert (code, out) == (2, "")
    assert err == ("epc-fast optimize: error: matplotlib is needed for the optimiser's curve "
                   "plot and is not installed: pip install 'epc-fast[plot]' (or --no-plot)\n")
    assert not (tmp_path / "out").exists()
    assert _optimize(tmp_path, capsys, CONFIG, "--no-plot")[0] == 0


def test_without_scipy_the_command_stops_before_any_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)
    code, out, err = _optimize(tmp_path, capsys, CONFIG, "--no-plot")
    assert (code, out) == (2, "")
    assert err == ("epc-fast optimize: error: SciPy is needed for the optimiser and is not "
                   "installed: pip install 'epc-fast[optimize]'\n")
    assert not (tmp_path / "out").exists()


def test_an_out_another_run_writes_in_is_refused_naming_that_run(tmp_path, capsys):
    import os

    from epc_fast.jobs.output import OutputLock

    (tmp_path / "out").mkdir()
    holder = OutputLock(tmp_path / "out")
    holder.acquire()
    try:
        code, out, err = _optimize(tmp_path, capsys, CONFIG, "--overwrite")
    finally:
        holder.release()
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith(f"epc-fast optimize: error: --out '{tmp_path / 'out'}': another run "
                          f"writes here: pid {os.getpid()} on ")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == []


def test_overwrite_removes_the_previous_runs_files_this_run_does_not_write(tmp_path, capsys):
    assert _optimize(tmp_path, capsys)[0] == 0
    (tmp_path / "out" / "notes.txt").write_text("keep me\n")
    code, _, err = _optimize(tmp_path, capsys, CONFIG, "--overwrite", "--no-plot")
    assert code == 0 and err == ""
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "curve.csv", "notes.txt", "optimum.json", "optimum.md"]


def test_every_file_the_command_writes_is_one_overwrite_knows_as_a_commands():
    from epc_fast.commands.optimize import FILES
    from epc_fast.jobs.output import COMMAND_FILES

    assert set(FILES) <= COMMAND_FILES


def test_sigterm_while_the_files_are_written_leaves_every_file_whole(tmp_path):
    import subprocess

    config = tmp_path / "optimize.toml"
    config.write_text(CONFIG)
    out = tmp_path / "out"
    script = tmp_path / "signalled.py"
    script.write_text(f"""
import os, signal, sys
import epc_fast.commands.optimize as command
from epc_fast.__main__ import main

real_write_curves = command._write_curves

def write_curves_signalled(path, curves):
    os.kill(os.getpid(), signal.SIGTERM)
    real_write_curves(path, curves)

command._write_curves = write_curves_signalled
sys.exit(main(["optimize", {str(config)!r}, "--out", {str(out)!r}]))
""")
    finished = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                              timeout=120)
    assert finished.returncode == 143, finished.stderr
    assert finished.stderr == ("epc-fast optimize: SIGTERM while the results were written: "
                               "every file is written whole\n")
    assert sorted(p.name for p in out.iterdir()) == ["curve.csv", "curve.png", "optimum.json",
                                                     "optimum.md"]
    assert len((out / "curve.csv").read_text().splitlines()) == 1 + 5


def test_a_design_error_names_the_optimize_config(tmp_path, capsys):
    # the designs are read by the scan's parser: its mistakes are the optimize config's
    code, _, err = _optimize(tmp_path, capsys, CONFIG.replace("f_number = 2.8", "f_number = -2"))
    assert code == 2
    assert err.startswith("epc-fast optimize: error: optimize config [design.custom[0]] "
                          "'1/3.2 inch': f_number = -2: expected a value in (1e-30, inf)")
