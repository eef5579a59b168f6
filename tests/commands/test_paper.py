"""``epc-fast paper``: the figures, their companions and the statements it writes, end to end
(seconds); with ``--simulate`` the statements also checked on simulated captures (heavy);
without matplotlib, the statements still."""

from __future__ import annotations

import csv
import math
import subprocess
import sys

import pytest

from epc_fast.__main__ import main
from epc_fast.commands.paper import SKIPPED
from epc_fast.paper import CLAIMS, FIGURES

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size_px(data: bytes) -> tuple[int, int]:
    """(width, height) of a PNG, from its header chunk (IHDR), which follows the signature."""
    assert data.startswith(PNG_SIGNATURE) and data[12:16] == b"IHDR"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def read_statements(out) -> list:
    with open(out / "statements.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_paper_command_writes_three_pngs_their_limits_and_the_statements(tmp_path, capsys):
    out = tmp_path / "figures"
    assert main(["paper", "--out", str(out), "--threads", "2"]) == 0
    printed = capsys.readouterr().out
    for figure in FIGURES:
        data = (out / f"{figure.name}.png").read_bytes()
        assert len(data) > 10_000 and png_size_px(data) == (770, 572), figure.name
        # The companion: 7.0 x 6.2 inches (two rows of panels) at the 110 dpi of save_figure.
        limits = out / f"{figure.limits_name}.png"
        assert limits.name == f"{figure.name}_limits.png"
        data = limits.read_bytes()
        assert len(data) > 10_000 and png_size_px(data) == (770, 682), limits.name
        assert f"{limits}\n" in printed
    rows = read_statements(out)
    assert [row["id"] for row in rows] == [c.id for c in CLAIMS]
    assert all(float(row["preset_value"]) > 0 for row in rows)
    assert "does not hold: fraction_2.8_100klux" in printed
    # Without --simulate no capture is simulated, and the output says how to simulate them.
    assert all(math.isnan(float(row["simulated_value"])) for row in rows)
    assert all(row["simulated_holds"] == "" for row in rows)
    assert f"{SKIPPED}\n" in printed and "--simulate" in SKIPPED
    md = (out / "statements.md").read_text(encoding="utf-8")
    assert md.startswith("| id |") and "| simulated captures |" not in md
    assert "`epc-fast paper --simulate`" in md


@pytest.mark.heavy
def test_paper_command_with_simulate_checks_the_statements_on_simulated_captures(tmp_path,
                                                                                 capsys):
    out = tmp_path / "figures"
    assert main(["paper", "--out", str(out), "--threads", "2", "--simulate"]) == 0
    printed = capsys.readouterr().out
    assert SKIPPED not in printed
    rows = read_statements(out)
    assert [row["id"] for row in rows] == [c.id for c in CLAIMS]
    assert all((out / f"{figure.name}.png").exists() for figure in FIGURES)
    # The statements checked on simulated captures, as the paper checked them.
    simulated = {row["id"]: float(row["simulated_value"]) for row in rows}
    model = {row["id"]: float(row["preset_value"]) for row in rows}
    # The first dark ring of the PSF from the pupil: 1.21967 lambda F (the first zero of J1 over
    # pi), found on a grid of 1e-3 lambda F and refined by a parabola.
    assert abs(simulated["rayleigh_f2.8"] / (1.21967 * 0.55 * 2.8) - 1) < 1e-4
    # EPC goes as f50^2: twice the simulated MTF50's agreement (tests/simulate/test_agreement.py)
    # with the pooled captures' scatter, 3% in all.
    for sid in ("fraction_1.4_100klux", "fraction_2.8_100klux"):
        assert abs(simulated[sid] / model[sid] - 1) < 0.03, sid
    # 4x IS with 4x less light is the same capture: the same exposure times shake.
    assert abs(simulated["is_4x_light"] - 4.0) < 1e-6
    assert all(simulated[sid] != simulated[sid] for sid in ("fov_normal", "fov_zoom"))
    held = [row["simulated_holds"] == "true" for row in rows if row["simulated_holds"]]
    assert f"  on simulated captures: {sum(held)} of {len(held)} with a paper value hold\n" \
        in printed
    md = (out / "statements.md").read_text(encoding="utf-8")
    assert "Checked on simulated captures" in md and "| simulated captures |" in md


def test_python_dash_m_knows_the_paper_command():
    proc = subprocess.run([sys.executable, "-m", "epc_fast", "paper", "--help"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and "--out" in proc.stdout, proc.stderr


def test_paper_command_without_matplotlib_still_writes_the_table(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    assert main(["paper", "--out", str(tmp_path), "--no-simulate"]) == 1
    assert (tmp_path / "statements.csv").stat().st_size > 0
    assert not (tmp_path / "fig1.png").exists()
    assert not (tmp_path / "fig1_limits.png").exists()
    assert "epc-fast[plot]" in capsys.readouterr().err
