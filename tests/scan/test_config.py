"""Scan configs in TOML, and ``epc-fast scan``: the shipped example, the built-in default, the
tables and plots it writes, and the main job's default scan."""

import csv
import re

import numpy as np
import pytest

import epc_fast.scan.running.runner
from epc_fast.__main__ import main
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (Binned, Choice, FractionBelow, Grid, LogNormal, LogUniform, Quantiles,
                           Summary, TopK, Truncated, run)
from epc_fast.jobs import table_formats
from epc_fast.scan import tables
from epc_fast.scan.config import DEFAULT_CONFIG, default_config, load_config, parse_config
from epc_fast.jobs.errors import ConfigError, TooLargeError
from epc_fast.terms import terms_on
from helpers.scripts import ROOT

EXAMPLE = ROOT / "examples" / "scan_designs.toml"
NAMES = [d.name for d in HIGH_TIER]


def test_the_example_config_reads_as_the_space_it_describes():
    config = load_config(EXAMPLE)
    space = config.space
    assert (config.points, config.seed) == (1_000_000, 2009)
    assert space.design_names == tuple(NAMES)
    assert space.axes["illuminance_lux"] == LogUniform(10, 100_000)
    assert space.axes["shake_deg_per_s"] == Truncated(LogNormal(4.39, 0.5), 0.2, 40)
    assert space.axes["stabilization"] == Choice((1, 4), (0.5, 0.5))
    assert space.axes["read_noise_e"] == Grid((0, 2))
    reductions = config.reductions
    assert reductions["summary"] == Summary(by="design")
    assert reductions["stabilised"] == FractionBelow(2e6, by=("design", "stabilization"))
    assert reductions["best"] == TopK(10)
    bands = reductions["bands"]
    assert isinstance(bands, Quantiles) and bands.by[0] == "design"
    assert bands.by[1] == Binned("illuminance_lux", tuple(np.geomspace(10, 1e5, 17)))


def test_the_default_config_is_the_paper_designs_over_light_and_shake():
    config = default_config()
    assert config.space.design_names == tuple(NAMES)
    assert config.space.axes["shake_deg_per_s"] == LogNormal(4.39, 0.5)
    assert config.points == 10**6 and config.source == "built-in default"


@pytest.mark.parametrize("text, message", [
    ("[scan]\npoints = 10\n[scan2]\n", r"unknown key\(s\) scan2"),
    ("[design]\npresets = ['HIGH_TIER']\n", r"missing scan"),
    ("[scan]\npoints = 1.5\n", r"\[scan\]: points = 1.5: expected an integer"),
    ("[scan]\npoints = 10\n[design]\npresets = ['NOPE']\n", "'NOPE' is not a preset"),
    ("[scan]\npoints = 10\n[parameters]\nshake_deg_per_s = {distribution = 'lognormal', "
     "median = 4, sigam = 1}\n", r"\[parameters.shake_deg_per_s\]: unknown key\(s\) sigam"),
    ("[scan]\npoints = 10\n[parameters]\nx = {distribution = 'cauchy'}\n",
     r"\[parameters.x\]: distribution = 'cauchy': expected one of"),
    ("[scan]\npoints = 10\n[reductions.a]\nkind = 'median'\n", r"\[reductions.a\]: kind"),
    ("[scan]\npoints = 10\n[reductions.a]\nkind = 'summary'\nby = [{parameter = 'x'}]\n",
     "log_bins"),
])
def test_a_config_error_names_its_section_and_key(text, message):
    with pytest.raises(ValueError, match=message):
        parse_config(text)


def test_empirical_samples_can_come_from_a_file_beside_the_config(tmp_path):
    (tmp_path / "shake.txt").write_text("1.0\n2.0\n8.0\n")
    (tmp_path / "scan.toml").write_text(
        "[scan]\npoints = 1000\n[design]\npresets = ['HIGH_TIER']\n[parameters]\n"
        "illuminance_lux = 1000\nshake_deg_per_s = {distribution = 'empirical', "
        "file = 'shake.txt'}\n")
    config = load_config(tmp_path / "scan.toml")
    drawn = config.space.points(0, 0, 1000).parameters["shake_deg_per_s"]
    assert set(np.unique(drawn)) == {1.0, 2.0, 8.0}


def _read_csv(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_cli_scan_writes_the_tables_and_plots_of_the_example(tmp_path, capsys):
    assert main(["scan", str(EXAMPLE), "--out", str(tmp_path), "--points", "2e5",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "scan of 200,000 points" in out and "by design (epc in pixels):" in out
    names = {p.name for p in tmp_path.iterdir()}
    assert {"summary_by_design.csv", "summary_by_design.md", "summary_by_pixel_pitch_um.csv",
            "best.csv", "distribution.png", "bands.png"} <= names
    rows = _read_csv(tmp_path / "summary_by_design.csv")
    assert [r["design"] for r in rows] == NAMES
    assert [r["SNR target"] for r in rows] == ["30 dB at corner (27.03 deg, default)"] * 4
    config = load_config(EXAMPLE)
    expected = run(config.space, 200_000, seed=config.seed, reductions=config.reductions,
                   progress=False)
    # The CSV holds floats at full precision (repr).
    assert [float(r["mean"]) for r in rows] == list(expected["summary"].mean)
    assert [int(r["points"]) for r in rows] == [50_000] * 4
    assert len(_read_csv(tmp_path / "best.csv")) == 10


def test_cli_scan_without_a_config_runs_the_built_in_default(tmp_path, capsys):
    assert main(["scan", "--out", str(tmp_path), "--points", "1e5", "--no-plots",
                 "--no-progress"]) == 0
    assert "(built-in default), seed 2009" in capsys.readouterr().out
    assert (tmp_path / "summary_by_design.csv").exists()
    assert not list(tmp_path.glob("*.png"))


def test_cli_scan_interrupted_writes_the_partial_tables_and_exits_130(tmp_path, capsys,
                                                                     monkeypatch):
    calls = []
    reduce_chunk = epc_fast.scan.running.runner.reduce_chunk

    def reduce_then_interrupt(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return reduce_chunk(*args, **kwargs)

    monkeypatch.setattr(epc_fast.scan.running.runner, "reduce_chunk", reduce_then_interrupt)
    assert main(["scan", "--out", str(tmp_path), "--no-plots", "--no-progress",
                 "--chunk-points", "65536"]) == 130
    assert "scan of 65,536 of 1,000,000 points" in capsys.readouterr().out
    rows = _read_csv(tmp_path / "summary_by_design.csv")
    assert sum(int(r["points"]) for r in rows) == 65_536


def test_cli_show_config_prints_the_built_in_toml(capsys):
    assert main(["scan", "--show-config"]) == 0
    assert capsys.readouterr().out == DEFAULT_CONFIG


def test_main_job_ends_with_the_default_scan_per_design(capsys):
    assert main(["--check-points", "500"]) == 0
    out = capsys.readouterr().out
    scan_part = out[out.index("Default scan"):]
    assert "scan of 200,000 points (built-in default)" in scan_part
    assert sum(line.startswith('| 1/3.2"') for line in scan_part.splitlines()) == 4


def test_tables_join_the_results_on_each_grouping_and_prefix_a_taken_column():
    space = load_config(EXAMPLE).space
    result = run(space, 1000, progress=False, reductions={
        "exact": Quantiles((0.5,), by="design"), "streamed": Quantiles((0.5,), by="design",
                                                                       exact_up_to=0),
        "all": Summary(), "best": TopK(2)})
    grouped = tables.grouped_tables(result)
    assert list(grouped) == ["design", "all"]
    assert list(grouped["design"]) == ["design", "SNR target", "q50", "q50 error",
                                       "streamed q50", "streamed q50 error"]
    assert grouped["all"]["points"] == [1000]
    assert tables.grouping_units(result) == {"design": "epc in pixels", "all": "epc in pixels"}


@pytest.mark.parametrize("grouping, stem", [
    ("design", "summary_by_design"),
    ("all", "summary_by_all"),
    ("design, illuminance_lux low, illuminance_lux high",
     "summary_by_design_and_illuminance_lux_band"),
    ("design, stabilization", "summary_by_design_and_stabilization"),
    ("design (2)", "summary_by_design_2"),
])
def test_table_files_are_named_by_their_grouping_in_short_words(grouping, stem):
    assert tables.file_stem(grouping) == stem


# --- the config as a schema: strict types, bounded sizes, errors naming table, key, value ----

SCHEMA_BASE = ("[scan]\npoints = 1000\n[design]\npresets = ['HIGH_TIER']\n[parameters]\n"
               "illuminance_lux = { distribution = 'log_uniform', low = 10, high = 1e5 }\n"
               "shake_deg_per_s = { distribution = 'lognormal', median = 4.39, sigma = 0.5 }\n")


@pytest.mark.parametrize("extra, message", [
    # Each, unchecked, would be accepted and change the answer.
    ("[reductions.b]\nkind = 'top_k'\nlargest = 'false'\n",
     r"\[reductions.b\]: largest = 'false': expected true or false"),
    ("[reductions.h]\nkind = 'histogram'\nlow = 1e3\nhigh = 1e7\nlog = 'no'\n",
     r"\[reductions.h\]: log = 'no': expected true or false"),
    ("[reductions.h]\nkind = 'histogram'\nlow = 1e3\nhigh = 1e7\nbins = 10.7\n",
     r"\[reductions.h\]: bins = 10.7: expected an integer"),
    ("[reductions.f]\nkind = 'fraction_below'\nthreshold = nan\n",
     r"\[reductions.f\]: threshold = nan: expected a finite number"),
    ("[reductions.q]\nkind = 'quantiles'\nq = [0.5, inf]\n", r"\[reductions.q\]: q = "),
    # Each, unchecked, would be a traceback naming neither key nor value.
    ("[reductions.b]\nkind = 'top_k'\nk = 2.5\n", r"\[reductions.b\]: k = 2.5: expected an int"),
    ("[reductions.h]\nkind = 'histogram'\nlow = 'a'\nhigh = 1e7\n",
     r"\[reductions.h\]: low = 'a': expected a finite number"),
    ("[reductions.s]\nkind = 'summary'\nby = 5\n", r"\[reductions.s\]: by: 5: expected a name"),
    ("[reductions.s]\nkind = 'summary'\nby = [{parameter = 'illuminance_lux', log_bins = 5}]\n",
     r"\[reductions.s\]: log_bins = 5: expected \[low, high, n\]"),
    ("[reductions.s]\nkind = 'summary'\nby = 'illuminance_lux'\n",
     r"\[reductions.s\]: cannot group by 'illuminance_lux'"),
    ("[reductions.s]\nkind = 'summary'\nof = 5\n", r"\[reductions.s\]: of = 5: expected one of"),
])
def test_a_reduction_key_of_the_wrong_type_or_range_is_refused(extra, message):
    with pytest.raises(ConfigError, match=message):
        parse_config(SCHEMA_BASE + extra)


@pytest.mark.parametrize("text, message", [
    ("[scan]\npoints = 10\n[design]\npresets = 'HIGH_TIER'\n",
     r"\[design\]: presets = 'HIGH_TIER': expected a list of preset names"),
    ("[scan]\npoints = 10\n[design]\npresets = 5\n", r"\[design\]: presets = 5: expected a list"),
    ("[scan]\npoints = true\n", r"\[scan\]: points = True: expected an integer"),
    ("[scan]\npoints = 10\nseed = -1\n", r"\[scan\]: seed = -1: expected an integer between 0"),
    ("[scan]\npoints = 10\nchunk_points = 1000\n", r"chunk_points = 1000: expected an integer"),
    ("[scan]\npoints = 10\nthreads = 100000\n", r"threads = 100000: expected an integer between"),
    ("[scan]\npoints = 10\n[parameters]\nf_number = 'two'\n",
     r"\[parameters\]: f_number = 'two': expected a finite number or a table"),
    ("[scan]\npoints = 10\n[parameters]\nf_number = { grid = [1, 'x'] }\n",
     r"\[parameters.f_number\]: grid = \[1, 'x'\]: expected a list of finite numbers"),
    ("[scan]\npoints = 10\n[parameters]\nshake_deg_per_s = { distribution = 'lognormal', "
     "median = 4, sigma = 1, truncate = 5 }\n",
     r"\[parameters.shake_deg_per_s\]: truncate = 5: expected a list"),
    ("[scan]\npoints = 10\n[parameters]\nshake_deg_per_s = { distribution = 'uniform', "
     "low = 2, high = 1 }\n", r"\[parameters.shake_deg_per_s\]: Uniform needs low < high"),
    ("[scan]\npoints = 10\n[evaluate]\nt_mpe_solver = 'newton'\n",
     r"\[evaluate\]: t_mpe_solver = 'newton': expected one of"),
    ("[scan]\npoints = 10\n[output]\nparquet = 5\n", r"\[output\]: parquet = 5: expected a name"),
    ("[scan]\npoints = 10\n[design]\npresets = ['HIGH_TIER']\n[parameters]\nbogus = 1\n",
     r"\[parameters\]: unknown parameter\(s\) bogus"),
    ("[scan]\npoints = 10\nscan = 1\n[scan.x]\n", r"\[scan\]: unknown key\(s\) scan, x"),
    ("[scan\npoints = 10\n", r"not valid TOML"),
])
def test_a_scan_or_space_key_of_the_wrong_type_or_range_is_refused(text, message):
    with pytest.raises(ConfigError, match=message):
        parse_config(text)


@pytest.mark.parametrize("extra, message", [
    ("", None),  # the base itself: points below
    ("[reductions.b]\nkind = 'top_k'\nk = 1e9\n", r"\[reductions.b\]: k = 1000000000"),
    ("[reductions.s]\nkind = 'summary'\nby = [{parameter = 'illuminance_lux', "
     "log_bins = [10, 1e5, 1e8]}]\n", r"log_bins count of 100,000,000 would need"),
    ("[reductions.s]\nkind = 'summary'\nby = ['design', {parameter = 'illuminance_lux', "
     "log_bins = [10, 1e5, 10000]}, {parameter = 'shake_deg_per_s', edges = "
     + str([float(x) for x in range(1, 2502)]) + "}]\n",
     r"groups \(the cells of its by parts crossed\) of 100,000,000 would need"),
    ("[reductions.h]\nkind = 'histogram'\nlow = 1\nhigh = 10\nbins = 1e7\nby = 'design'\n",
     r"groups x bins of 40,000,008 would need"),
    ("[reductions.q]\nkind = 'quantiles'\nbins_per_decade = 1e7\n",
     r"groups x streamed histogram bins of"),
])
def test_every_size_a_config_controls_is_bounded_before_allocating(extra, message):
    if message is None:
        with pytest.raises(TooLargeError, match=r"\[scan\]: points = 1000000000000000019884624"
                                                r"838656: expected an integer between 1 and"):
            parse_config(SCHEMA_BASE.replace("points = 1000", "points = 1e30"))
        return
    with pytest.raises(TooLargeError, match=message) as error:
        parse_config(SCHEMA_BASE + extra)
    assert isinstance(error.value, MemoryError) and "\n" not in str(error.value)


def test_an_empirical_sample_file_must_be_a_bounded_regular_text_file(tmp_path):
    def config(file):
        return (SCHEMA_BASE.replace("shake_deg_per_s = { distribution = 'lognormal', median = "
                                    "4.39, sigma = 0.5 }", f"shake_deg_per_s = {{ distribution "
                                    f"= 'empirical', file = '{file}' }}"))

    with pytest.raises(ConfigError, match=r"'/dev/zero' is not a regular file"):
        parse_config(config("/dev/zero"), tmp_path)
    (tmp_path / "big.txt").write_bytes(b"1.0\n" * (17 * 2**20))
    with pytest.raises(TooLargeError, match=r"big.txt' holds 71,303,168 bytes"):
        parse_config(config("big.txt"), tmp_path)
    (tmp_path / "bad.txt").write_text("1.0\n2.0\nfast\n")
    with pytest.raises(ConfigError, match=r"bad.txt' line 3: 'fast': expected one finite"):
        parse_config(config("bad.txt"), tmp_path)
    (tmp_path / "latin.txt").write_bytes(b"1.0\n\xe9\n")
    with pytest.raises(ConfigError, match=r"latin.txt' is not UTF-8 text"):
        parse_config(config("latin.txt"), tmp_path)
    (tmp_path / "ok.txt").write_text("# measured\n1.5\n\n2.5  # a comment\n")
    drawn = parse_config(config("ok.txt"), tmp_path).space.axes["shake_deg_per_s"]
    assert list(drawn.samples) == [1.5, 2.5]


@pytest.mark.parametrize("value, accepted", [(0.0, True), (1e-12, True), (0.99, True),
                                             (1.0, False), (-1e-9, False), ("'1e-9'", False)])
def test_an_evaluate_tolerance_takes_what_evaluate_takes(value, accepted):
    text = SCHEMA_BASE + f"[evaluate]\nf50_rtol = {value}\n"
    if accepted:
        assert parse_config(text).space.evaluate_options == {"f50_rtol": value}
    else:
        with pytest.raises(ConfigError, match=r"\[evaluate\]: f50_rtol = .*: expected a finite "
                                              r"number in \[0, 1\)"):
            parse_config(text)


@pytest.mark.parametrize("text, message", [
    (SCHEMA_BASE + "read_noise_e = { choice = [1, 2], weights = [1] }\n",
     r"\[parameters.read_noise_e\]: Choice needs 2 non-negative weights"),
    (SCHEMA_BASE.replace("presets = ['HIGH_TIER']", "presets = ['HIGH_TIER']\n"
                         "sampling = 'choice'\nweights = [1, 2]"),
     r"\[design\]: Choice needs 4 non-negative weights"),
])
def test_a_check_the_scans_classes_make_names_the_table(text, message):
    with pytest.raises(ConfigError, match=message):
        parse_config(text)


def test_a_group_with_no_finite_value_prints_a_dash_not_inf_or_nan():
    from epc_fast.scan import BLOCK_POINTS, Space
    # a PRNU of 10% caps the SNR at 20 dB: the 30 dB target is unreachable at every point of
    # that group, which has no EPC at all
    space = Space(design=[HIGH_TIER[3]], prnu=Choice([0.1, 0.0]), illuminance_lux=1000.0)
    result = run(space, 2 * BLOCK_POINTS, progress=False,
                 reductions={"summary": Summary(by="prnu")})
    columns = tables.grouped_tables(result)["prnu"]
    assert columns["ok"] == [0, columns["points"][1]]
    assert np.isnan(columns["min"][0]) and np.isnan(columns["max"][0])
    assert columns["min"][1] == columns["max"][1] > 0
    unreachable = table_formats.markdown(columns).splitlines()[2]
    cells = [cell.strip() for cell in unreachable.strip("|").split("|")]
    assert cells[-4:] == [table_formats.NO_VALUE] * 4  # mean, std, min, max
    assert "inf" not in unreachable and "nan" not in unreachable


LENS_CONFIG = """
[scan]
points = 65536

[parameters]
illuminance_lux = {distribution = "log_uniform", low = 10, high = 10000}
pixel_pitch_um = 1.4
f_number = 2.0
focal_length_mm = 4.0
pixel_count = 8e6
lens = {choice = [0, 1]}

[evaluate]
lens_mtf = %s
"""


def test_a_config_gives_lens_tables_and_a_lens_per_point():
    two = ("[[[0, 100, 200, 400, 909], [1, 0.8, 0.6, 0.25, 0]], "
           "[[0, 50, 100, 200], [1, 0.7, 0.4, 0]]]")
    space = parse_config(LENS_CONFIG % two).space
    tables = space.evaluate_options["lens_mtf"]
    assert space.lens_count == 2 and tables[1].frequencies.tolist() == [0.0, 50.0, 100.0, 200.0]
    one = "[[0, 50, 100, 200], [1, 0.7, 0.4, 0]]"  # one table: only lens = 0
    with pytest.raises(ConfigError, match=r"lens = choice value 1: expected every value in "
                                          r"\[0, 0\] integers"):
        parse_config(LENS_CONFIG % one).space
    for bad, message in (("[[0, 50], [1, 1.2]]", "lens_mtf's mtf 1.2 at index 1"),
                         ("[[0], [1]]", "lens_mtf has 1 point"), ("3", "lens_mtf = 3")):
        with pytest.raises(ConfigError, match=re.escape(message)):
            parse_config(LENS_CONFIG % bad).space


NIGHT_CONFIG = """
[scan]
points = 1000
[[design.custom]]
name = "phone"
pixel_pitch_um = 1.4
f_number = 2.0
focal_length_mm = 4.0
pixel_count = 8e6
read_noise_e = 2.0
modes = %s
[parameters]
illuminance_lux = {distribution = "log_uniform", low = 1, high = 10000}
[evaluate]
max_exposure_s = %s
"""


def test_a_config_gives_a_frame_cap_and_a_night_mode():
    modes = '[{binning = 1}, {binning = 2, frames = "auto", max_frames = 8}]'
    space = parse_config(NIGHT_CONFIG % (modes, "0.1")).space
    assert space.evaluate_options["max_exposure_s"] == 0.1
    assert space.design_modes[0][1] == {"binning": 2, "frames": "auto", "max_frames": 8}
    terms = terms_on(space)
    assert "frame cap 0.1 s" in terms and "night mode up to 8 frames (every design)" in terms


@pytest.mark.parametrize("modes, cap, message", [
    ("[{binning = 1}]", "0", "[evaluate]: max_exposure_s = 0"),
    ("[{binning = 1}]", '"fast"', "[evaluate]: max_exposure_s = 'fast'"),
    ('[{frames = "auto"}]', "0.1", "modes[0]: frames='auto' (night mode) needs max_frames"),
    ("[{max_frames = 8}]", "0.1", "modes[0]: max_frames=8 is given with frames=1.0"),
    ('[{frames = "night", max_frames = 8}]', "0.1", "modes[0]: frames='night'"),
    ('[{frames = "auto", max_frames = 0}]', "0.1", "modes[0]: max_frames=0: a whole number"),
])
def test_a_bad_frame_cap_or_night_mode_is_a_config_error_naming_it(modes, cap, message):
    with pytest.raises(ConfigError) as error:
        parse_config(NIGHT_CONFIG % (modes, cap)).space
    assert message in str(error.value), str(error.value)
