"""The optimiser's curve figure (epc_fast.optimize.plot): it carries its conditions (the
scene, the SNR target, the draws, the seed, the version and the build) under its panels,
clear of every other text."""

from __future__ import annotations

import numpy as np
import pytest

from epc_fast import optimize
from epc_fast.plotting.common import space_conditions
from helpers.optimize import PITCH, shaky_scene

pytest.importorskip("matplotlib")

from epc_fast.optimize.plot import curve_figure  # noqa: E402


@pytest.fixture(scope="module")
def searched():
    problem = optimize.Problem(shaky_scene(), PITCH, optimize.Quantile(0.5), points=2_000,
                               seed=5)
    optimum = problem.maximize()
    curve = problem.curve("pixel_pitch_um", np.linspace(0.8, 4.0, 9), at=optimum.x)
    return problem, optimum, [curve]


def test_the_curve_says_its_draws_seed_version_and_build_by_default(searched):
    import epc_fast
    from epc_fast import _core
    from helpers.figures import figure_text

    _, optimum, curves = searched
    text = figure_text(curve_figure(curves, optimum))
    assert "2,000 points, seed 5" in text
    assert f"epc_fast {epc_fast.__version__}, core {_core.isa}" in text


def test_the_curve_carries_the_scene_and_snr_target_it_is_given(searched):
    from helpers.figures import figure_text

    problem, optimum, curves = searched
    conditions = space_conditions(problem.space, points=optimum.points, seed=optimum.seed,
                                  skip=tuple(PITCH))
    text = figure_text(curve_figure(curves, optimum, conditions=conditions))
    assert "Designs: 1/3.2\" 1.75 µm" in text
    assert "SNR target: 30 dB at corner (27.03 deg, default)" in text
    assert ("Scene: illuminance_lux LogUniform(low=10, high=100000.0); "
            "shake_deg_per_s LogNormal(median=4.39, sigma=0.5)") in text
    assert "pixel_pitch_um" not in text.split("Scene:")[1].splitlines()[0]


def test_no_text_of_the_curve_overlaps_another_or_leaves_the_figure(searched):
    from helpers.figures import boxes_outside, overlapping_pairs, text_boxes

    problem, optimum, curves = searched
    figure = curve_figure(curves, optimum, conditions=space_conditions(
        problem.space, points=optimum.points, seed=optimum.seed, skip=tuple(PITCH)))
    boxes = text_boxes(figure)
    assert "figure text 0" in boxes
    assert overlapping_pairs(boxes) == []
    assert boxes_outside(boxes, figure) == []
    renderer = figure.canvas.get_renderer()
    assert boxes["figure text 0"].y1 < figure.axes[0].get_tightbbox(renderer).y0
