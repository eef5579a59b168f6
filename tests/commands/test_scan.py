"""``epc-fast scan``: every mistake one line naming what to fix (exit code 2 for a usage
error, 1 for one that is not the user's), durations as printed, design names safe in every
file it writes, OMP_NUM_THREADS past its bound an error."""

import csv
import json
import os
import subprocess
import sys

import pytest

from epc_fast.__main__ import main
from epc_fast.commands import duration


@pytest.mark.parametrize("seconds, text", [(0.0004, "0.4 ms"), (0.053, "53 ms"), (3.214, "3.21 s"),
                                           (24.84, "24.8 s"), (125.2, "2 min 05 s")])
def test_durations_keep_the_digits_that_matter(seconds, text):
    assert duration(seconds) == text


# --- epc-fast scan: every mistake is one line naming what to fix, exit code 2 ----------------

SCAN_CONFIG = """\
[scan]
points = 100_000
seed = 3

[design]
presets = ["HIGH_TIER"]

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }
"""
CUSTOM_DESIGN = """
[[design.custom]]
name = {name}
pixel_pitch_um = 1.4
f_number = 2.8
focal_length_mm = 5.6
sensor_area_mm2 = 15.6751
"""


def _scan(tmp_path, capsys, text, *args, name="scan.toml"):
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    code = main(["scan", str(path), "--out", str(tmp_path / "out"), "--no-progress", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize("text, key", [
    # Unchecked, each would end in a traceback ('int' object is not iterable; cannot unpack
    # non-iterable int object; must be real number, not str; Partition index must be integer;
    # 'H' is not a preset) instead of one line naming the key and value.
    ('[scan]\npoints = 10\n[design]\npresets = 5\n', "[design]: presets = 5"),
    (SCAN_CONFIG.replace('high = 100_000 }', 'high = 100_000, truncate = 5 }'),
     "[parameters.illuminance_lux]: truncate = 5"),
    (SCAN_CONFIG + '[reductions.h]\nkind = "histogram"\nlow = "a"\nhigh = 1e7\n',
     "[reductions.h]: low = 'a'"),
    (SCAN_CONFIG + '[reductions.best]\nkind = "top_k"\nk = 2.5\n', "[reductions.best]: k = 2.5"),
    ('[scan]\npoints = 10\n[design]\npresets = "HIGH_TIER"\n',
     "[design]: presets = 'HIGH_TIER': expected a list of preset names"),
    (SCAN_CONFIG.encode() + b"# caf\xe9\n", "is not UTF-8 text"),
])
def test_a_scan_config_error_is_one_line_naming_the_key_with_exit_code_2(tmp_path, capsys, text,
                                                                          key):
    code, out, err = _scan(tmp_path, capsys, text)
    assert code == 2 and out == ""
    assert err.startswith("epc-fast scan: error: scan config") and key in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "out").exists()


CUSTOM_ONLY = SCAN_CONFIG.replace('[design]\npresets = ["HIGH_TIER"]\n', "")


@pytest.mark.parametrize("text, message", [
    (SCAN_CONFIG + "pixel_pitch_um = -0.56\n", "[parameters]: pixel_pitch_um = -0.56: expected "
                                               "a value in (0, 1e+30) (um: pixel pitch)"),
    (SCAN_CONFIG + "f_number = -2\n", "[parameters]: f_number = -2: expected a value in "
                                      "(1e-30, inf) (1: working f-number)"),
    (SCAN_CONFIG + 'f_number = { distribution = "uniform", low = -1, high = 3 }\n',
     "reaches -1: expected its bounds in (1e-30, inf) (1: working f-number)"),
    (SCAN_CONFIG + "reflectance = { grid = [0.5, 2.0] }\n",
     "[parameters]: reflectance = grid value 2: expected every value in [0, 1]"),
    (CUSTOM_ONLY + CUSTOM_DESIGN.format(name='"A"').replace("f_number = 2.8", "f_number = -2"),
     "[design.custom[0]] 'A': f_number = -2: expected a value in (1e-30, inf)"),
    (CUSTOM_ONLY + CUSTOM_DESIGN.format(name='"A"').replace(
        "sensor_area_mm2 = 15.6751", "sensor_width_mm = -4.6\nsensor_height_mm = -3.5"),
     "[design.custom[0]] 'A': sensor_width_mm=-4.6: expected a length in (0, 1e+30) mm"),
])
def test_a_value_outside_its_domain_is_refused_before_the_first_point_with_exit_code_2(
        tmp_path, capsys, text, message):
    # Unchecked, the first ran every point and printed "ok 0, invalid 100,000, mean nan, min
    # inf, max -inf" with exit code 0.
    code, out, err = _scan(tmp_path, capsys, text + '[reductions.s]\nkind = "summary"\n')
    assert code == 2 and out == ""
    assert err.startswith("epc-fast scan: error: scan config") and message in err, err
    assert err.count("\n") == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("names, message", [
    (['"A"', '"A"'], "[design.custom[1]]: name = 'A': expected a name no other design has "
                     "([design.custom[0]] is named 'A')"),
    (['""'], "[design.custom[0]]: name = '': expected a name with a letter or digit"),
    (['"--"'], "[design.custom[0]]: name = '--': expected a name with a letter or digit"),
])
def test_designs_named_alike_or_unnamed_are_refused_with_exit_code_2(tmp_path, capsys, names,
                                                                     message):
    # Unchecked, two designs named "A" made two summary rows both labelled "A", and points the
    # Parquet design column could not tell apart.
    text = CUSTOM_ONLY + "".join(CUSTOM_DESIGN.format(name=n) for n in names)
    code, out, err = _scan(tmp_path, capsys, text + '[reductions.s]\nkind = "summary"\n')
    assert code == 2 and out == ""
    assert err == f"epc-fast scan: error: scan config {message}\n"
    assert not (tmp_path / "out").exists()


def test_a_preset_given_twice_is_refused_naming_it(tmp_path, capsys):
    text = SCAN_CONFIG.replace('presets = ["HIGH_TIER"]', 'presets = ["HIGH_TIER", "HIGH_TIER"]')
    code, _, err = _scan(tmp_path, capsys, text + '[reductions.s]\nkind = "summary"\n')
    assert code == 2
    assert err.startswith("epc-fast scan: error: scan config [design]: presets: 'HIGH_TIER' "
                          "gives the design '1/3.2\" 2.8 um' a second time"), err


HISTOGRAM = '[reductions.h]\nkind = "histogram"\nlow = 1e3\nhigh = 1e7\n'
SUMMARY = '[reductions.s]\nkind = "summary"\n'


@pytest.mark.parametrize("modules, more, args, message", [
    (("matplotlib", "matplotlib.figure"), SUMMARY + HISTOGRAM, (),
     "matplotlib is needed for the scan's plots and is not installed: pip install "
     "'epc-fast[plot]' (or --no-plots)"),
    (("pyarrow", "pyarrow.parquet"), SUMMARY + '[output]\nparquet = "points"\n', (),
     "pyarrow is needed for the Parquet points ([output] parquet) and is not installed: pip "
     "install 'epc-fast[parquet]' (or no [output] parquet)"),
    (("distributed",), SUMMARY, ("--scheduler", "tcp://127.0.0.1:9"),
     "dask.distributed is needed for a scan on a cluster (--scheduler) and is not installed: "
     "pip install 'epc-fast[dask]'"),
    (("SALib", "SALib.sample.sobol", "SALib.analyze.sobol"), SUMMARY + "[sobol]\npoints = 64\n",
     (), "SALib is needed for the [sobol] table's Sobol' indices and is not installed: pip "
         "install 'epc-fast[sensitivity]'"),
])
def test_a_missing_optional_dependency_stops_the_scan_before_the_first_point(
        tmp_path, capsys, monkeypatch, modules, more, args, message):
    # Unchecked, a scan without matplotlib computed every point, then failed on the plot.
    import epc_fast.scan.running.runner

    for module in modules:
        monkeypatch.setitem(sys.modules, module, None)
    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", None)  # no point is computed
    code, out, err = _scan(tmp_path, capsys, SCAN_CONFIG + more, *args)
    assert (code, out, err) == (2, "", f"epc-fast scan: error: {message}\n")
    assert not (tmp_path / "out").exists()


def test_without_matplotlib_a_scan_runs_with_no_plots_or_with_no_plot_to_draw(tmp_path, capsys,
                                                                             monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    code, _, err = _scan(tmp_path, capsys, SCAN_CONFIG + SUMMARY + HISTOGRAM, "--no-plots")
    assert (code, err) == (0, "")
    code, _, err = _scan(tmp_path, capsys, SCAN_CONFIG + SUMMARY, "--overwrite")
    assert (code, err) == (0, "")


def test_debug_shows_the_traceback(tmp_path, capsys):
    from epc_fast.jobs.errors import ConfigError

    with pytest.raises(ConfigError, match="presets = 5"):
        _scan(tmp_path, capsys, '[scan]\npoints = 10\n[design]\npresets = 5\n', "--debug")


def test_an_error_that_is_not_the_users_is_one_line_with_exit_code_1(tmp_path, capsys,
                                                                     monkeypatch):
    import epc_fast.scan.running.runner

    def broken(*args, **kwargs):
        raise RuntimeError()

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", broken)
    code, _, err = _scan(tmp_path, capsys, SCAN_CONFIG + '[reductions.s]\nkind = "summary"\n')
    assert code == 1 and err == ("epc-fast scan: error: RuntimeError; the 0 points merged "
                                 "before it are written, marked partial\n")
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert manifest["state"] == "failed" and manifest["stopped_by"] == "RuntimeError: "
    assert manifest["files"] == ["summary_by_all.csv", "summary_by_all.md"]


@pytest.mark.parametrize("option, value", [("--points", "70000.9"), ("--points", "1e30"),
                                           ("--points", "nan"), ("--seed", "-1"),
                                           ("--threads", "0"), ("--chunk-points", "1000")])
def test_a_bad_command_line_number_is_refused_with_exit_code_2(tmp_path, capsys, option, value):
    with pytest.raises(SystemExit) as exit_:
        main(["scan", "--out", str(tmp_path / "out"), option, value])
    assert exit_.value.code == 2
    assert f"{option} {value!r}: expected an integer between" in capsys.readouterr().err


def test_points_written_as_a_float_that_is_whole_are_accepted(tmp_path, capsys):
    code, out, _ = _scan(tmp_path, capsys, SCAN_CONFIG + '[reductions.s]\nkind = "summary"\n',
                         "--points", "1.31072e5")
    assert code == 0 and "scan of 131,072 points" in out


def test_a_histogram_writes_its_counts_as_a_table_with_or_without_plots(tmp_path, capsys):
    # Its plot was all it wrote: with --no-plots beside a summary it was silently dropped, and
    # alone it was refused as a scan that writes nothing.
    histogram = HISTOGRAM + "bins = 4\n"
    code, out, err = _scan(tmp_path, capsys, SCAN_CONFIG + SUMMARY + histogram, "--no-plots")
    assert (code, err) == (0, "")
    with open(tmp_path / "out" / "h.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert [row["bin"] for row in rows] == ["below", "1", "2", "3", "4", "above", "not finite"]
    assert sum(int(row["points"]) for row in rows) == 100_000
    assert float(rows[1]["epc low"]) == pytest.approx(1e3) and float(rows[4]["epc high"]) == \
        pytest.approx(1e7)
    assert "| bin | epc low | epc high | points |" in (tmp_path / "out" / "h.md").read_text()
    assert "\nby h (epc in pixels):\n| bin | epc low | epc high | points |" in out
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert {"h.csv", "h.md"} <= set(manifest["files"]) and "h.png" not in manifest["files"]
    code, _, err = _scan(tmp_path, capsys, SCAN_CONFIG + histogram, "--no-plots", "--overwrite")
    assert (code, err) == (0, "")
    assert (tmp_path / "out" / "h.csv").exists()


BAYER_SOBOL = """\
[scan]
points = 65_536
seed = 1
sampling = "sobol"

[design]
presets = ["HIGH_TIER"]

[evaluate]
cfa = "bayer"

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }

[reductions.s]
kind = "summary"
by = "design"

[reductions.h]
kind = "histogram"
low = 1e3
high = 1e7
bins = 5
by = "design"
"""
LOG_BANDS = """
[reductions.bands]
kind = "quantiles"
q = [0.05, 0.5, 0.95]
by = ["design", { parameter = "illuminance_lux", log_bins = [10, 100_000, 4] }]

[output]
log_y = true
"""


def test_a_sobol_scan_of_a_bayer_sensor_histograms_every_point_per_design(tmp_path, capsys):
    # The histogram read the summary's group indices, replicate and design in one (16 x 4
    # groups), and failed at 0 points with "cannot reshape array".
    code, out, err = _scan(tmp_path, capsys, BAYER_SOBOL, "--no-plots")
    assert (code, err) == (0, "")
    assert out.startswith("scan of 65,536 points")
    with open(tmp_path / "out" / "h.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    for design in ('1/3.2" 2.8 um', '1/3.2" 1.4 um'):
        assert sum(int(row["points"]) for row in rows if row["design"] == design) == 16_384


def test_an_error_in_a_chunk_is_the_headline_and_the_error_line_even_with_plots(
        tmp_path, capsys, monkeypatch):
    # The headline said "INTERRUPTED", and the plots of 0 points on a log axis failed with
    # matplotlib's "Data cannot be log-scaled", which took the error line's place.
    import epc_fast.scan.running.runner

    def broken(*args, **kwargs):
        raise ValueError("cannot reshape array of size 190 into shape (4,12)")

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", broken)
    code, out, err = _scan(tmp_path, capsys, BAYER_SOBOL + LOG_BANDS)
    assert code == 1
    headline = out.splitlines()[0]
    assert "INTERRUPTED" not in headline
    assert headline.endswith("-- FAILED: ValueError: cannot reshape array of size 190 into "
                             "shape (4,12); partial results"), headline
    assert err == ("epc-fast scan: error: ValueError: cannot reshape array of size 190 into "
                   "shape (4,12); the 0 points merged before it are written, marked partial\n")
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert manifest["state"] == "failed" and "cannot reshape" in manifest["stopped_by"]
    assert "bands.png" in manifest["files"]


def test_design_names_are_safe_in_plots_csv_and_markdown(tmp_path, capsys):
    names = ['"$\\\\frac{1"', '"=HYPERLINK(\\"http://x\\")"', '"two\\nlines | piped"',
             '"@SUM(A1)"']
    text = SCAN_CONFIG.replace('[design]\npresets = ["HIGH_TIER"]\n', "")
    text += "".join(CUSTOM_DESIGN.format(name=n) for n in names) + """
[reductions.summary]
kind = "summary"
by = "design"

[reductions.bands]
kind = "quantiles"
q = [0.1, 0.5, 0.9]
by = ["design", { parameter = "illuminance_lux", log_bins = [10, 100_000, 4] }]

[reductions.distribution]
kind = "histogram"
low = 1e3
high = 1e7
by = "design"
"""
    code, _, err = _scan(tmp_path, capsys, text)
    assert code == 0, err
    out = tmp_path / "out"
    assert (out / "bands.png").stat().st_size > 0 and (out / "distribution.png").exists()
    with open(out / "summary_by_design.csv", newline="") as handle:
        designs = [row["design"] for row in csv.DictReader(handle)]
    assert designs == ["$\\frac{1", "'=HYPERLINK(\"http://x\")", "two\nlines | piped",
                       "'@SUM(A1)"]
    table = (out / "summary_by_design.md").read_text().splitlines()
    assert len(table) == 2 + 4
    assert "| two lines \\| piped |" in table[4]


def test_an_omp_num_threads_beyond_the_bound_is_an_error_not_a_crash(tmp_path):
    env = dict(os.environ, OMP_NUM_THREADS="100000")
    proc = subprocess.run([sys.executable, "-m", "epc_fast", "scan", "--points", "1e5", "--out",
                           str(tmp_path / "out"), "--no-progress"], env=env, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr == ("epc-fast scan: error: ValueError: OMP_NUM_THREADS='100000': "
                           "expected a thread count between 1 and 1024 (as threads=), or "
                           "comma-separated counts\n")
    assert not (tmp_path / "out").exists()


# --- issue #39: binning, bursts and readout modes in a config ---------------------------------

PHONE_DESIGN = """
[[design.custom]]
name = "200 MP"
pixel_pitch_um = 0.56
f_number = 1.8
focal_length_mm = 6.0
sensor_diagonal_mm = 12.0
aspect = "4:3"
read_noise_e = 1.5
"""


@pytest.mark.parametrize("extra, parameters, message", [
    ("modes = []", "", "[design.custom[0]] '200 MP': modes: at least one readout mode"),
    ("modes = [{binnig = 2}]", "",
     "[design.custom[0]] '200 MP': modes[0]: 'binnig' is not a readout mode's key"),
    ("modes = [{binning = 1}, {binning = 4}, {binning = 1}]", "",
     "[design.custom[0]] '200 MP': modes[2] repeats modes[0]"),
    ("modes = [{binning = 2.5}]", "", "[design.custom[0]] '200 MP': modes[0]: binning = 2.5: "
                                      "expected a value in [1, 1e+30) integers"),
    ('modes = [{binning = 4, binning_readout = "analog"}]', "",
     "[design.custom[0].modes[0]]: binning_readout = 'analog': expected one of"),
    ("modes = 4", "", "[design.custom[0]] '200 MP': modes = 4: expected a list of readout modes"),
    ('binning_readout = "analog"', "",
     "[design.custom[0]]: binning_readout = 'analog': expected one of \"digital\", \"charge\""),
    ("modes = [{binning = 1}, {binning = 4}]", "binning = { grid = [1, 2] }\n",
     "design '200 MP': modes[0]: binning: the space's parameters set binning too"),
    ("", 'binning = { distribution = "uniform", low = 1, high = 4 }\n',
     "[parameters]: binning = Uniform(low=1.0, high=4.0): expected whole numbers in [1, 1e+30) "
     "integers"),
    ("", 'frames = { distribution = "log_uniform", low = 1, high = 16 }\n',
     "[parameters]: frames = LogUniform(low=1.0, high=16.0): expected whole numbers"),
    ("", "frames = { choice = [1, 0.5] }\n", "[parameters]: frames = choice value 0.5: expected "
                                            "every value in [1, 1e+30) integers"),
])
def test_a_bad_readout_or_burst_is_one_line_naming_the_design_and_mode_with_exit_code_2(
        tmp_path, capsys, extra, parameters, message):
    text = (CUSTOM_ONLY + parameters + PHONE_DESIGN + extra + "\n"
            + '[reductions.s]\nkind = "summary"\n')
    code, out, err = _scan(tmp_path, capsys, text)
    assert code == 2 and out == ""
    assert err.startswith("epc-fast scan: error: scan config") and message in err, err
    assert err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_a_scan_with_readout_modes_writes_each_modes_share_per_design(tmp_path, capsys):
    text = (CUSTOM_ONLY.replace("100_000", "65_536") + "alignment_error_um = 0.3\n"
            + PHONE_DESIGN + "modes = [{binning = 1}, {binning = 4}, {binning = 4, frames = 8}]\n"
            + CUSTOM_DESIGN.format(name='"1.4 um"') + 'binning_readout = "charge"\n'
            + '[reductions.s]\nkind = "summary"\nby = "design"\n')
    code, out, _ = _scan(tmp_path, capsys, text, "--no-plots")
    assert code == 0
    with open(tmp_path / "out" / "summary_by_design.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert [row["design"] for row in rows] == ["200 MP", "1.4 um"]
    shares = [[float(row[f"mode {i}"]) for i in range(3)] for row in rows]
    assert abs(sum(shares[0]) - 1.0) < 1e-12 and min(shares[0]) > 0.0
    assert shares[1] == [1.0, 0.0, 0.0]  # one mode, its own readout
    assert "| mode 0 | mode 1 | mode 2 |" in out


@pytest.mark.parametrize("make, kind", [(os.mkfifo, "a FIFO"), (os.mkdir, "a directory")])
def test_a_lock_path_that_is_not_a_file_is_a_usage_error_naming_it(tmp_path, capsys, make, kind):
    # A FIFO there ended the scan with "OSError: [Errno 22] Invalid argument", exit code 1.
    out = tmp_path / "out"
    out.mkdir()
    make(out / ".epc-fast.lock")
    code = main(["scan", "--points", "65536", "--out", str(out), "--no-progress", "--no-plots"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err == (f"epc-fast scan: error: --out {str(out)!r}: its lock file "
                   f"{out / '.epc-fast.lock'} is {kind}, not a file: remove it, or choose "
                   "another --out\n")
    assert sorted(p.name for p in out.iterdir()) == [".epc-fast.lock"]


def test_a_design_error_names_the_scan_config(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(SCAN_CONFIG.replace('"HIGH_TIER"', '"NOPE"'))
    assert main(["scan", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    assert capsys.readouterr().err.startswith(
        "epc-fast scan: error: scan config [design]: presets: 'NOPE' is not a preset")
