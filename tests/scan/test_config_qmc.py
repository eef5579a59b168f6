"""A scan config's sampling, replicates and targets ([scan] sampling, replicates;
[reductions.NAME] target), and what ``epc-fast scan`` says and records about them."""

import json

import pytest

from epc_fast.__main__ import main
from epc_fast.scan import FractionBelow, Summary
from epc_fast.scan.config import parse_config
from epc_fast.jobs.errors import ConfigError
from epc_fast.scan.reductions.targets import Target

BASE = """
[scan]
points = {points}
seed = 3
{scan}
[design]
presets = ["HIGH_TIER"]
sampling = "grid"
[parameters]
illuminance_lux = {{ distribution = "log_uniform", low = 10, high = 100_000 }}
shake_deg_per_s = {{ distribution = "lognormal", median = 4.39, sigma = 0.5 }}
[reductions.summary]
kind = "summary"
by = "design"
{target}
[reductions.below]
kind = "fraction_below"
threshold = 2e6
"""


def _config(points=1 << 20, scan='sampling = "sobol"', target=""):
    return BASE.format(points=points, scan=scan, target=target)


def test_sampling_replicates_and_a_target_read_as_the_runs_arguments():
    config = parse_config(_config(scan='sampling = "sobol"\nreplicates = 8',
                                  target="target = { relative = 1e-3 }"))
    kwargs = config.run_kwargs()
    assert (kwargs["sampling"], kwargs["replicates"]) == ("sobol", 8)
    assert config.reductions["summary"] == Summary(by="design", target=Target(relative=1e-3))
    assert config.reductions["below"] == FractionBelow(2e6)


@pytest.mark.parametrize("scan, target, match", [
    ('sampling = "halton"', "", r"\[scan\]: sampling = 'halton': expected one of "
                                r'"monte_carlo", "sobol"'),
    ('replicates = 0', "", r"\[scan\]: replicates = 0: expected an integer between 1 and 1,024"),
    ('sampling = "sobol"', "target = { relative = 0 }",
     r"reductions.summary.*relative must be a finite number > 0"),
    ('sampling = "sobol"', "target = 1e-3", r"reductions.summary.*target = 0.001: expected"),
    ('sampling = "sobol"\nreplicates = 1', "target = { relative = 1e-3 }",
     r"\[scan\].*a target needs replicates >= 2"),
])
def test_a_bad_sampling_replicates_or_target_is_refused_naming_its_table(scan, target, match):
    with pytest.raises(ConfigError, match=match):
        parse_config(_config(scan=scan, target=target))


def test_sobol_points_that_do_not_balance_are_refused_before_the_first_point():
    with pytest.raises(ConfigError, match=r"\[scan\].*2\^m x replicates x grid cells "
                                          r"\(16 x 4\): got 1000000; 524288 or 1048576"):
        parse_config(_config(points=1_000_000))


def test_the_command_says_where_a_targeted_scan_stopped_and_records_it(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(_config(target="target = { relative = 1e-3 }"))
    assert main(["scan", str(path), "--out", str(tmp_path / "out"), "--no-progress",
                 "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert "seed 3, Sobol in 16 replicates" in out
    assert "every target held at 65,536 of at most 1,048,576 points" in out
    assert "| mean error |" in out
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert (manifest["sampling"], manifest["replicates"], manifest["unmet_targets"],
            manifest["points_done"]) == ("sobol", 16, [], 65_536)


def test_the_command_names_a_target_that_did_not_hold(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(_config(points=1 << 17, target="target = { standard_error = 1e-6 }"))
    assert main(["scan", str(path), "--out", str(tmp_path / "out"), "--no-progress",
                 "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert "NOT every target held at 131,072 points:" in out
    assert "  summary: mean (design=1/3.2\" 2.8 um) has standard error" in out
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert len(manifest["unmet_targets"]) == 1


def test_replicates_count_in_the_bounds_of_a_reductions_groups():
    from epc_fast.jobs.errors import TooLargeError

    # 4 designs' streamed quantiles: ~70,000 histogram bins, 70 million in 1024 replicates,
    # beyond the 20 million cells a reduction may hold
    config = _config(points=1024 * 4 * 2**10,
                     scan='sampling = "sobol"\nreplicates = REPLICATES').replace(
        'kind = "summary"', 'kind = "quantiles"\nexact_up_to = 0')
    parse_config(config.replace("REPLICATES", "16"))
    with pytest.raises(TooLargeError, match="reductions.summary"):
        parse_config(config.replace("REPLICATES", "1024"))


def test_points_given_on_the_command_line_are_checked_against_the_sampling(tmp_path, capsys):
    path = tmp_path / "scan.toml"
    path.write_text(_config())
    code = main(["scan", str(path), "--out", str(tmp_path / "out"), "--no-progress",
                 "--points", "1000000"])
    assert code == 2 and not (tmp_path / "out").exists()
    assert ("--points 1000000: sampling='sobol' takes points = 2^m x replicates x grid cells"
            in capsys.readouterr().err)
