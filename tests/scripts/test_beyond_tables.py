"""tools/beyond_axes_table.py and tools/real_camera_answers.py: the tables docs/beyond.md shows
("Each term counted in both directions", "A 50 MP quad-Bayer phone camera") are the ones the
tools print, and their gains are evaluate's."""

import numpy as np

from epc_fast import evaluate
from epc_fast.presets import HIGH_TIER
from helpers.scripts import ROOT, load_script


def test_docs_beyond_shows_the_table_the_tool_prints():
    table = load_script("tools/beyond_axes_table.py").table()
    assert table in (ROOT / "docs" / "beyond.md").read_text()


def test_the_tools_binning_gain_in_both_directions_is_evaluates():
    tool = load_script("tools/beyond_axes_table.py")
    design = HIGH_TIER[3]
    gain = tool._epc(design, "both", binning=2.0) / tool._epc(design, "both")
    kw = design.evaluate_kwargs()
    lux = np.asarray(tool.LUX)
    expected = (evaluate(lux, **kw, binning=2.0, epc_axes="both").epc
                / evaluate(lux, **kw, epc_axes="both").epc)
    np.testing.assert_array_equal(gain, expected)
    # 2x2 binning of the 1.4 um design in dim light: 2.9x in both directions, not 16.3x
    assert 2.85 < gain[0] < 2.95


def test_docs_beyond_shows_the_phone_table_the_tool_prints():
    table = load_script("tools/real_camera_answers.py").table()
    assert table in (ROOT / "docs" / "beyond.md").read_text()
