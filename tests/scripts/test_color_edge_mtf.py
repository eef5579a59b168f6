"""tools/color_edge_mtf.py: its grey edge is the simulator's own Bayer capture, and its table
of grey against blue-yellow MTF50s is the one docs/model.md shows ("The colour filter array")."""

import numpy as np
import pytest

from epc_fast import cfa, simulate
from helpers.scripts import load_script

pytestmark = pytest.mark.heavy

#: cycles/pixel, docs/model.md's table: (design index, demosaicker) -> (grey, blue-yellow).
TABLE = {
    (0, "bilinear"): (0.333, 0.289), (0, "malvar2004"): (0.405, 0.267),
    (0, "menon2007"): (0.825, 0.437),
    (1, "bilinear"): (0.293, 0.262), (1, "malvar2004"): (0.368, 0.243),
    (1, "menon2007"): (0.574, 0.353),
    (2, "bilinear"): (0.221, 0.207), (2, "malvar2004"): (0.282, 0.194),
    (2, "menon2007"): (0.301, 0.241),
}


@pytest.fixture(scope="module")
def tool():
    pytest.importorskip("colour_demosaicing")
    return load_script("tools/color_edge_mtf.py")


@pytest.mark.parametrize("demosaic", cfa.DEMOSAICS)
def test_the_grey_edge_is_the_simulators_bayer_capture(tool, demosaic):
    # the same chart, optics and development: the same MTF50 to rounding (the tool's edge is
    # taken in reflectance and back, the capture's through the filters and back)
    name, design = tool.DESIGNS[0]
    fraction, pitch = tool.edge_fraction(design, 5.0, 96)
    grey = tool.luminance(fraction, tool.GREY[:1] * 3, tool.GREY[1:] * 3, demosaic)
    capture = simulate.capture(simulate.slanted_edge((96, 96), 5.0), cfa="bayer",
                               demosaic=demosaic, illuminance_lux=tool.LUX,
                               exposure_s=tool.EXPOSURE_S, **design)
    assert grey.shape == capture.expected_e.shape
    assert simulate.mtf50(grey, pitch) == pytest.approx(
        simulate.mtf50(capture.expected_e, capture.pitch_um), rel=1e-9)


def test_the_table_is_the_docs(tool):
    rows = tool.measure()
    names = [name for name, _ in tool.DESIGNS]
    measured = {(names.index(name), d): (grey, colour) for name, d, grey, colour in rows}
    assert measured.keys() == TABLE.keys()
    for key, figures in TABLE.items():  # the docs' three decimals
        np.testing.assert_allclose(measured[key], figures, atol=5e-4, err_msg=str(key))
    # the coloured edge is the lower for every demosaicker and design: 6 % to 47 %
    assert all(0.05 < 1 - c / g < 0.48 for g, c in measured.values())
