"""The paper's figures and the ``epc-fast paper`` command, end to end."""

from __future__ import annotations

import csv
import subprocess
import sys

import numpy as np
import pytest

from epc_fast.__main__ import main
from epc_fast.paper import CLAIMS, FIGURES
from epc_fast.plotting import plot_epc_over_illuminance
from epc_fast.presets import HIGH_TIER, evaluate_over_illuminance

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_paper_command_writes_three_pngs_and_the_statements(tmp_path, capsys):
    out = tmp_path / "figures"
    assert main(["paper", "--out", str(out), "--threads", "2"]) == 0
    for figure in FIGURES:
        data = (out / f"{figure.name}.png").read_bytes()
        assert data.startswith(PNG_SIGNATURE) and len(data) > 10_000, figure.name
    with open(out / "statements.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert [row["id"] for row in rows] == [c.id for c in CLAIMS]
    assert all(float(row["preset_value"]) > 0 for row in rows)
    assert (out / "statements.md").read_text(encoding="utf-8").startswith("| id |")
    assert "does not hold: fraction_2.8_100klux" in capsys.readouterr().out


def test_python_dash_m_knows_the_paper_command():
    proc = subprocess.run([sys.executable, "-m", "epc_fast", "paper", "--help"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and "--out" in proc.stdout, proc.stderr


def test_a_figure_draws_the_model_and_marks_each_pixel_count():
    figure = plot_epc_over_illuminance(HIGH_TIER, title="Figure 1")
    ax = figure.axes[0]
    curves = [line for line in ax.lines if line.get_linestyle() == "-"]
    marks = {line.get_ydata()[0] for line in ax.lines if line.get_linestyle() == ":"
             and len(line.get_ydata())}
    lux = curves[0].get_xdata()
    assert lux[0] == pytest.approx(100.0) and lux[-1] == pytest.approx(1e5)
    expected = evaluate_over_illuminance(HIGH_TIER, lux).epc / 1e6
    np.testing.assert_array_equal(np.array([c.get_ydata() for c in curves]), expected)
    assert marks == {d.pixel_count / 1e6 for d in HIGH_TIER}
    assert ax.get_xscale() == "log"


def test_plotting_without_matplotlib_names_the_plot_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(ImportError, match=r"epc-fast\[plot\]"):
        plot_epc_over_illuminance(HIGH_TIER)


def test_paper_command_without_matplotlib_still_writes_the_table(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    assert main(["paper", "--out", str(tmp_path)]) == 1
    assert (tmp_path / "statements.csv").stat().st_size > 0
    assert not (tmp_path / "fig1.png").exists()
    assert "epc-fast[plot]" in capsys.readouterr().err


def test_the_cli_and_the_plotting_module_import_without_matplotlib():
    code = ("import sys, epc_fast.__main__, epc_fast.plotting, epc_fast.paper;"
            "sys.exit('matplotlib' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
