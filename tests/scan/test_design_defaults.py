"""A parameter one design gives and another leaves out takes, in the other, the value evaluate
gives that design alone: the colour filter's defaults in a Bayer scan, not the monochrome
sensor's 1 (the space's design table, its points, a scan, the printed space and the simulator's
designs)."""

import numpy as np
import pytest

import epc_fast
from epc_fast import scan
from epc_fast.cfa import DEFAULT_CFA_TRANSMITTANCE, DEFAULT_COLOR_NOISE_GAIN
from epc_fast.scan import Grid, LogUniform, Summary, run
from epc_fast.scan.sampling.space import BLOCK_POINTS

#: Two 1/3.2" designs: A gives its filters' transmittance and colour noise gain, B neither.
A = {"name": "A", "pixel_pitch_um": 1.4, "f_number": 2.8, "focal_length_mm": 5.6,
     "sensor_area_mm2": 15.6751, "read_noise_e": 2.0, "cfa_transmittance": 0.3,
     "color_noise_gain": 0.95}
B = {"name": "B", "pixel_pitch_um": 1.75, "f_number": 2.8, "focal_length_mm": 5.6,
     "sensor_area_mm2": 15.6751, "read_noise_e": 2.0}
BAYER = {"cfa": "bayer", "demosaic": "bilinear"}
#: (cfa_transmittance, color_noise_gain) that evaluate gives a design that leaves them out.
OWN = {"bayer": (DEFAULT_CFA_TRANSMITTANCE, DEFAULT_COLOR_NOISE_GAIN), "none": (1.0, 1.0)}


def _alone(design, lux, options):
    """EPC of ``design`` evaluated alone, as evaluate gives it."""
    kwargs = {k: v for k, v in design.items() if k != "name"}
    return epc_fast.evaluate(lux, **kwargs, **options).epc


@pytest.mark.parametrize("options", [BAYER, {}], ids=["bayer", "monochrome"])
def test_a_design_that_leaves_out_its_color_terms_takes_its_own_color_filters(options):
    space = scan.Space(design=[A, B], illuminance_lux=100.0, evaluate_options=options)
    own = OWN[options.get("cfa", "none")]
    assert list(space.design_table["cfa_transmittance"]) == [0.3, own[0]]
    assert list(space.design_table["color_noise_gain"]) == [0.95, own[1]]
    # and the other way round: the first design leaves them out
    space = scan.Space(design=[B, A], illuminance_lux=100.0, evaluate_options=options)
    assert list(space.design_table["cfa_transmittance"]) == [own[0], 0.3]


@pytest.mark.parametrize("options", [BAYER, {}], ids=["bayer", "monochrome"])
def test_each_designs_points_are_evaluates_numbers_for_that_design_alone(options):
    # the same inputs give the same bits (a point's result does not depend on its
    # neighbours): equal to the bit
    space = scan.Space(design=[A, B], illuminance_lux=LogUniform(1, 1e5),
                       evaluate_options=options)
    points = space.points(7, 0, 1000)
    got = epc_fast.evaluate(**points.parameters, **options).epc
    design = points.indices["design"]
    lux = points.parameters["illuminance_lux"]
    for index, entry in enumerate((A, B)):
        mine = design == index
        np.testing.assert_array_equal(got[mine], _alone(entry, lux[mine], options))


def test_a_bayer_scan_gives_the_design_that_leaves_them_out_evaluates_numbers():
    # one scene: every point of a design is the same point, so its min and max are
    # evaluate's EPC for the design alone, to the bit
    lux = (10.0, 1000.0)
    space = scan.Space(design=[A, B], illuminance_lux=Grid(lux), evaluate_options=BAYER)
    result = run(space, BLOCK_POINTS, seed=3, progress=False,
                 reductions={"s": Summary(by=["design", "illuminance_lux"])})["s"]
    for row, (design, light) in enumerate(zip(result.labels["design"],
                                              result.labels["illuminance_lux"])):
        expected = _alone({"A": A, "B": B}[design], float(light), BAYER)
        assert result.min[row] == expected and result.max[row] == expected, (design, light)
    assert result.count.sum() == BLOCK_POINTS


def test_the_printed_space_says_the_bayer_values_the_design_takes():
    space = scan.Space(design=[{k: v for k, v in A.items() if k != "color_noise_gain"}, B],
                       illuminance_lux=100.0, evaluate_options=BAYER)
    text = " ".join(space.describe().split())
    assert (f"cfa_transmittance 0.3 (A), {DEFAULT_CFA_TRANSMITTANCE:g} (B)") in text
    assert f"color_noise_gain={DEFAULT_COLOR_NOISE_GAIN:g}" in text
    assert space.defaults()["color_noise_gain"] == DEFAULT_COLOR_NOISE_GAIN
    assert "cfa_transmittance" not in space.defaults()


def test_a_bayer_design_with_its_own_color_noise_gain_beside_one_without_simulates():
    from epc_fast.simulate.config import parse_simulate_config

    design = ("[[design.custom]]\nname = {name!r}\npixel_pitch_um = 1.4\nf_number = 2.8\n"
              "focal_length_mm = 5.6\nsensor_width_mm = 4.57\nsensor_height_mm = 3.43\n")
    text = ('[evaluate]\ncfa = "bayer"\n\n' + design.format(name="A")
            + f"color_noise_gain = {DEFAULT_COLOR_NOISE_GAIN}\n\n" + design.format(name="B"))
    designs = dict(parse_simulate_config(text).designs)
    assert designs["B"]["color_noise_gain"] == DEFAULT_COLOR_NOISE_GAIN


def test_the_optimiser_evaluates_each_design_with_its_own_color_filters_defaults():
    from epc_fast import optimize

    space = scan.Space(design=[A, B], illuminance_lux=30.0, evaluate_options=BAYER)
    problem = optimize.Problem(space, {"denoise_sigma_px": (0.0, 4.0)}, points=2, seed=1)
    got = problem.epc(denoise_sigma_px=1.5)
    expected = [_alone({**entry, "denoise_sigma_px": 1.5}, 30.0, BAYER) for entry in (A, B)]
    np.testing.assert_array_equal(got, expected)
