"""The main job, ``epc-fast`` without a command: build info, the self-check and the paper's
design table; the version, the usage text, ``python -m epc_fast``."""

import subprocess
import sys

import pytest

import epc_fast
from epc_fast.__main__ import main
from epc_fast.presets import HIGH_TIER
from epc_fast.selfcheck import self_check
from helpers.scripts import ROOT


def test_main_job_prints_build_self_check_and_design_table(capsys):
    assert main(["--check-points", "2000"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0] == str(epc_fast.build_info())
    assert "self-check passed" in out
    # The four 1/3.2" designs, one line each, EPC in pixels as in the scan's tables: the
    # 1.4 um design's physical pixel count, its area over its pitch squared (not its 3200 x
    # 2400 array, 7,680,000), then its EPC at 1000 lux (the preset, evaluated).
    lines = out.splitlines()
    assert sum(line.startswith('1/3.2"') for line in lines) == 4
    assert "EPC in pixels of the paper's 1/3.2\" designs (30 dB met at the image corner, " \
        "27.03 deg)" in out
    row = next(line for line in lines if line.startswith('1/3.2" 1.4 um')).split()
    epc = epc_fast.evaluate(1000.0, **HIGH_TIER[3].evaluate_kwargs()).epc
    assert row[3] == "7,997,500" and row[6] == f"{epc:,.0f}"
    assert "| mean (pixels) | q5 (pixels) | q50 (pixels) | q95 (pixels) |" in out
    assert " 0.0 s" not in out


def test_the_version_is_pyprojects():
    tomllib = pytest.importorskip("tomllib")
    pyproject = ROOT / "pyproject.toml"
    assert epc_fast.__version__ == tomllib.loads(pyproject.read_text())["project"]["version"]


def test_the_version_option_prints_the_version_and_the_loaded_build(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    info = epc_fast.build_info()
    assert capsys.readouterr().out.splitlines() == [
        f"epc_fast {epc_fast.__version__}",
        f"core {info.isa} (built: {', '.join(info.built_levels)}; CPU: "
        f"{', '.join(info.cpu_levels)}), OpenMP {'on' if info.openmp else 'off'}, "
        f"{info.default_threads} threads by default"]


def test_usage_is_plain_text(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    assert "``" not in out and "The effective pixel count (EPC) of camera designs." in out


def test_self_check_finds_the_core_and_reference_in_agreement():
    report = self_check(3000, seed=7)
    assert report.statuses_equal
    # Both backends bisect f50 to ~1e-14 relative; 1e-12 is the stated agreement.
    assert report.max_rel_error <= 1e-12
    assert report.passed


def test_python_dash_m_runs_the_main_job():
    proc = subprocess.run([sys.executable, "-m", "epc_fast", "--check-points", "500"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "self-check passed" in proc.stdout


def test_docs_cli_md_names_every_command_and_option_in_plain_markdown():
    # The page reads as a reference where Sphinx directives do not run (the repository's web
    # page): every sub-command has a section and every option is named outside the directive.
    import argparse

    from epc_fast.__main__ import build_parser
    from epc_fast.commands import discover

    page = (ROOT / "docs" / "cli.md").read_text()
    written = page.split("```{epc-fast-help}")[0]
    parser = build_parser(discover())
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    parsers = {"": parser, **sub.choices}
    assert set(sub.choices) == set(discover())
    missing = [f"epc-fast {name}".strip() for name in sub.choices
               if f"## `epc-fast {name}`" not in written
               or f"| `epc-fast {name}" not in written]
    missing += [f"epc-fast {name} {option}".replace("  ", " ")
                for name, command in parsers.items() for action in command._actions
                for option in action.option_strings
                if option.startswith("--") and option != "--help" and f"`{option}" not in written]
    assert missing == []
    assert "```{epc-fast-help}\n```" in page  # the Sphinx build still prints every --help
