"""A design space: grids in mixed radix, designs, and draws that depend only on seed and point."""

import numpy as np
import pytest

from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (BLOCK_POINTS, Choice, Empirical, Grid, LogNormal, LogUniform, Normal,
                           Space, Truncated, Uniform)
from epc_fast.scan.sampling import streams


def _space(**extra):
    return Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
                 shake_deg_per_s=LogNormal(4.39, 0.5), **extra)


def test_grid_points_visit_every_combination_with_the_last_axis_fastest():
    space = Space(design=HIGH_TIER, illuminance_lux=Grid((100.0, 1000.0, 10000.0)),
                  read_noise_e=Grid((0.0, 2.0)))
    assert space.grid_size == 4 * 3 * 2
    points = space.points(0, 0, 2 * space.grid_size)
    cell = np.arange(2 * space.grid_size) % space.grid_size
    assert np.array_equal(points.indices["design"], cell // 6)
    assert np.array_equal(points.indices["illuminance_lux"], cell // 2 % 3)
    assert np.array_equal(points.parameters["read_noise_e"], np.tile([0.0, 2.0], 24))
    pitches = [d.pixel_pitch_um for d in HIGH_TIER]
    assert np.array_equal(points.parameters["pixel_pitch_um"], np.take(pitches, cell // 6))


def test_a_grid_of_a_billion_cells_is_never_materialised():
    axis = Grid(tuple(np.linspace(1.0, 2.0, 1000)))
    space = Space(illuminance_lux=axis, pixel_pitch_um=axis, f_number=axis, focal_length_mm=5.6,
                  sensor_area_mm2=15.0)
    assert space.grid_size == 10**9
    start = 7654 * BLOCK_POINTS
    points = space.points(0, start, start + 10)
    cell = np.arange(start, start + 10)
    assert np.array_equal(points.indices["illuminance_lux"], cell // 10**6)
    assert np.array_equal(points.indices["pixel_pitch_um"], cell // 1000 % 1000)
    assert np.array_equal(points.indices["f_number"], cell % 1000)


def test_designs_give_their_parameters_and_constant_ones_as_numbers():
    points = _space().points(0, 0, 8)
    assert np.array_equal(points.parameters["pixel_pitch_um"], [2.8, 2.2, 1.75, 1.4] * 2)
    assert points.parameters["f_number"] == 2.8
    assert points.parameters["sensor_area_mm2"] == HIGH_TIER[0].sensor_area_mm2


def test_a_parameter_given_by_the_space_replaces_the_designs_value():
    space = _space(stabilization=Grid((1.0, 4.0)))
    assert "stabilization" not in space.design_table
    points = space.points(0, 0, 8)
    assert np.array_equal(points.parameters["stabilization"], [1.0, 4.0] * 4)


def test_draws_do_not_depend_on_the_range_of_points_asked_for():
    space = _space(read_noise_e=Choice((0.0, 1.0, 2.0)))
    whole = space.points(5, 0, 10 * BLOCK_POINTS)
    part = space.points(5, 3 * BLOCK_POINTS, 7 * BLOCK_POINTS + 123)
    for name in ("illuminance_lux", "shake_deg_per_s", "read_noise_e", "pixel_pitch_um"):
        assert np.array_equal(part.parameters[name],
                              whole.parameters[name][3 * BLOCK_POINTS:7 * BLOCK_POINTS + 123])


def test_points_at_any_indices_are_the_points_of_the_range_holding_them():
    space = _space(read_noise_e=Choice((0.0, 1.0, 2.0), weights=(1, 2, 3)),
                   stabilization=Grid((1.0, 4.0)))
    whole = space.points(5, 0, 3 * BLOCK_POINTS)
    # Repeats, in any order.
    index = np.random.default_rng(0).integers(0, 3 * BLOCK_POINTS, 5000)
    at = space.points_at(5, index)
    assert at.start is None and at.stop is None and len(at) == index.size
    assert np.array_equal(at.index, index)
    assert at.parameters.keys() == whole.parameters.keys()
    for name, values in whole.parameters.items():
        expected = values if np.ndim(values) == 0 else values[index]
        assert np.array_equal(at.parameters[name], expected), name
    for name, values in whole.indices.items():
        assert np.array_equal(at.indices[name], values[index]), name
    # Beyond 2^32 points, where the counter's second word is used.
    far = 2**40 + 7 * BLOCK_POINTS
    ranged = space.points(5, far, far + 100)
    at = space.points_at(5, np.arange(far, far + 100))
    for name in ("illuminance_lux", "shake_deg_per_s", "read_noise_e", "stabilization",
                 "pixel_pitch_um"):
        assert np.array_equal(at.parameters[name], ranged.parameters[name]), name


def test_points_at_refuses_negative_indices():
    with pytest.raises(ValueError, match="point indices"):
        _space().points_at(0, [1, -2])


def test_a_random_parameter_is_its_distribution_at_the_uniforms_of_its_name():
    space = _space(read_noise_e=Choice((0.0, 1.0, 2.0)))
    points = space.points(9, 0, 1000)
    index = np.arange(1000)
    u = streams.uniforms(9, streams.stream_id("shake_deg_per_s"), index)
    assert np.array_equal(points.parameters["shake_deg_per_s"], LogNormal(4.39, 0.5)
                          .from_uniform(u))
    u = streams.uniforms(9, streams.stream_id("read_noise_e"), index)
    assert np.array_equal(points.indices["read_noise_e"], np.minimum(np.floor(u * 3), 2))


def test_a_choice_of_designs_draws_from_the_design_stream():
    space = Space(design=Choice(HIGH_TIER), illuminance_lux=100.0)
    u = streams.uniforms(4, streams.stream_id("design"), np.arange(1000))
    assert np.array_equal(space.points(4, 0, 1000).indices["design"],
                          np.minimum(np.floor(u * 4), 3))


def test_adding_a_random_parameter_leaves_the_others_draws_unchanged():
    before = _space().points(5, 0, 1000)
    after = _space(read_noise_e=Uniform(0.0, 3.0)).points(5, 0, 1000)
    assert np.array_equal(before.parameters["illuminance_lux"], after.parameters["illuminance_lux"])
    assert np.array_equal(before.parameters["shake_deg_per_s"], after.parameters["shake_deg_per_s"])


def test_different_seeds_draw_different_points():
    a, b = (_space().points(seed, 0, 1000).parameters["illuminance_lux"] for seed in (1, 2))
    assert not np.any(a == b)


def test_a_choice_of_designs_draws_each_design_and_its_parameters():
    space = Space(design=Choice(HIGH_TIER, weights=(1, 0, 0, 1)),
                  illuminance_lux=LogUniform(10, 1e5))
    points = space.points(0, 0, 1000)
    assert set(np.unique(points.indices["design"])) == {0, 3}
    pitches = np.array([d.pixel_pitch_um for d in HIGH_TIER])
    assert np.array_equal(points.parameters["pixel_pitch_um"], pitches[points.indices["design"]])


@pytest.mark.parametrize("make, error, message", [
    (lambda: Space(pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6, sensor_area_mm2=15.0),
     TypeError, "does not give illuminance_lux"),
    (lambda: Space(design=HIGH_TIER, illuminance_lux=100.0, pixel_count=1e6),
     TypeError, "exactly one of pixel_count and sensor_area_mm2"),
    (lambda: Space(design=HIGH_TIER, illuminance_lux=100.0, shake=1.0),
     TypeError, "unknown parameter"),
    (lambda: Space(design=[{"pixel_pitch_um": 1.4}, {"f_number": 2.8}], illuminance_lux=1.0),
     ValueError, "same parameters"),
    (lambda: Space(design=HIGH_TIER, illuminance_lux="bright"), TypeError, "must be a number"),
    (lambda: Space(design=HIGH_TIER, illuminance_lux=1.0, evaluate_options={"threads": 2}),
     TypeError, "unknown evaluate option"),
])
def test_an_incomplete_or_unknown_space_is_refused(make, error, message):
    with pytest.raises(error, match=message):
        make()


def test_a_range_of_points_starts_at_a_block():
    with pytest.raises(ValueError, match="starts at a block"):
        _space().points(0, 100, 200)


# --- every value against its parameter's domain, before the first point -----------------------

@pytest.mark.parametrize("parameters, message", [
    ({"pixel_pitch_um": -0.56},
     "pixel_pitch_um = -0.56: expected a value in (0, 1e+30) (um: pixel pitch)"),
    ({"f_number": -2.0}, "f_number = -2: expected a value in (1e-30, inf) (1: working f-number)"),
    ({"reflectance": 2.0}, "reflectance = 2: expected a value in [0, 1] (1: reflectance"),
    ({"reflectance": Grid((0.2, 1.5))}, "reflectance = grid value 1.5: expected every value in "
                                        "[0, 1]"),
    ({"read_noise_e": Choice((1.0, -1.0))}, "read_noise_e = choice value -1: expected every "
                                            "value in [0, 1e+30)"),
    ({"f_number": Uniform(-1, 3)}, "f_number = Uniform(low=-1, high=3) reaches -1: expected "
                                   "its bounds in (1e-30, inf)"),
    ({"mtf_threshold": LogUniform(0.1, 2)}, "reaches 2: expected its bounds in (0, 1)"),
    ({"reflectance": Truncated(Normal(0.4, 1), -1, 0.9)}, "reaches -1: expected its bounds in "
                                                          "[0, 1]"),
    ({"reflectance": Empirical([0.1, 3.0])}, "reflectance = empirical sample 3: expected every "
                                             "sample in [0, 1]"),
    ({"f_number": Normal(-2, 0.1)}, "f_number = Normal(mean=-2, std=0.1) draws in the domain "
                                    "with a probability of 2.8e-89: expected draws in"),
    ({"pixel_count": -1e6}, "pixel_count = -1e+06: expected a value in (0, 1e+30) (pixels"),
])
def test_a_value_outside_its_parameters_domain_is_refused_naming_it(parameters, message):
    with pytest.raises(ValueError) as error:
        Space(design=[{"name": "A", "pixel_pitch_um": 1.4, "f_number": 2.8,
                       "focal_length_mm": 5.6}], illuminance_lux=100.0,
              **({"sensor_area_mm2": 15.0} if "pixel_count" not in parameters else {}),
              **parameters)
    assert message in str(error.value), str(error.value)


def test_a_designs_value_outside_its_domain_is_refused_naming_the_design():
    with pytest.raises(ValueError) as error:
        Space(design=[{"name": "A", "pixel_pitch_um": 1.4, "f_number": -2.0,
                       "focal_length_mm": 5.6, "sensor_area_mm2": 15.0}], illuminance_lux=100.0)
    assert str(error.value) == ("design 'A': f_number = -2: expected a value in (1e-30, inf) "
                                "(1: working f-number)")


def test_a_sensor_of_negative_lengths_is_refused_not_made_a_positive_area():
    with pytest.raises(ValueError, match=r"design 'A': sensor_width_mm=-4.6: expected a length "
                                         r"in \(0, 1e\+30\) mm"):
        Space(design=[{"name": "A", "pixel_pitch_um": 1.4, "f_number": 2.8,
                       "focal_length_mm": 5.6, "sensor_width_mm": -4.6,
                       "sensor_height_mm": -3.5}], illuminance_lux=100.0)


@pytest.mark.parametrize("axis", [Normal(2.0, 1.0), Truncated(Normal(0.4, 1), 0, 1),
                                  Uniform(0.0, 2.0)])
def test_a_distribution_inside_its_domain_but_for_a_tail_or_an_open_end_is_kept(axis):
    name = "reflectance" if isinstance(axis, Truncated) else \
        "f_number" if isinstance(axis, Normal) else "pixel_pitch_um"
    space = Space(design=HIGH_TIER, illuminance_lux=100.0, **{name: axis})
    assert space.axes[name] == axis


def test_a_normal_tail_outside_the_domain_gives_invalid_points_counted_as_such():
    from epc_fast.scan import Summary, run

    space = Space(design=HIGH_TIER[:1], illuminance_lux=100.0, f_number=Normal(2.0, 1.0))
    summary = run(space, points=BLOCK_POINTS, seed=1, reductions={"s": Summary()},
                  progress=False).results["s"]
    from epc_fast import Status

    invalid = int(summary.status_counts[:, Status.INVALID].sum())
    # P(F <= 0) of Normal(2, 1) is 2.3%: about 1490 of 65,536 draws
    assert 1300 < invalid < 1700


@pytest.mark.parametrize("names, message", [
    (("A", "A"), "design names must differ: 'A' is the name of designs 0 and 1"),
    (("A", ""), "design 1's name is '': expected a name with a letter or digit"),
])
def test_designs_named_alike_or_unnamed_are_refused(names, message):
    design = [{"name": n, "pixel_pitch_um": 1.4, "f_number": 2.8, "focal_length_mm": 5.6,
               "sensor_area_mm2": 15.0} for n in names]
    with pytest.raises(ValueError) as error:
        Space(design=design, illuminance_lux=100.0)
    assert str(error.value) == message


def test_the_space_says_which_share_of_a_distributions_draws_falls_outside_the_domain():
    space = Space(design=HIGH_TIER, illuminance_lux=100.0, f_number=Normal(2.0, 1.0),
                  shake_deg_per_s=LogNormal(4.39, 0.5))
    lines = space.describe().splitlines()
    assert "f_number: Normal(mean=2.0, std=1.0): 2.3% of the draws fall outside the domain " \
           "(1e-30, inf) and are INVALID points" in lines
    assert "shake_deg_per_s: LogNormal(median=4.39, sigma=0.5)" in lines


# --- Lens tables (evaluate_options lens_mtf, lens per point) ---------------------------------

LENS_TABLES = [(np.array([0.0, 100.0, 200.0, 400.0, 909.0]), np.array([1.0, 0.8, 0.6, 0.25, 0.0])),
               (np.array([0.0, 50.0, 100.0, 200.0]), np.array([1.0, 0.7, 0.4, 0.0]))]
LENS_SPACE = dict(illuminance_lux=LogUniform(10, 1e4), pixel_pitch_um=1.4, f_number=2.0,
                  focal_length_mm=4.0, pixel_count=8e6)


def test_a_lens_index_is_checked_against_the_spaces_tables():
    space = Space(**LENS_SPACE, lens=Choice((0.0, 1.0)), evaluate_options={"lens_mtf": LENS_TABLES})
    assert space.lens_count == 2
    with pytest.raises(ValueError, match=r"lens = choice value 2: expected every value in "
                                         r"\[0, 1\] integers"):
        Space(**LENS_SPACE, lens=Choice((0.0, 2.0)), evaluate_options={"lens_mtf": LENS_TABLES})
    with pytest.raises(ValueError, match=r"lens = 1: expected a value in \[0, 0\] integers"):
        Space(**LENS_SPACE, lens=1.0)  # without tables only 0
    with pytest.raises(ValueError, match="lens_mtf\\[1\\] rises"):
        Space(**LENS_SPACE, evaluate_options={"lens_mtf": [LENS_TABLES[0], ([0, 1], [0.5, 0.6])]})
    with pytest.raises(ValueError, match="give lens_mtf or wavefront_rms_waves, not both"):
        Space(**LENS_SPACE, wavefront_rms_waves=0.05, evaluate_options={"lens_mtf": LENS_TABLES})


@pytest.mark.parametrize("binning, message", [
    (Choice((1.0, 2.0)), "binning takes one value per call"),
    (Grid((2.0, 3.0)), "got binning 3"),
    (4.0, "got binning 4"),
])
def test_a_quad_bayer_space_reads_one_binning_of_1_or_2(binning, message):
    # one call reads one layout (epc_fast.cfa.quad_bayer_binning): refused before any point
    with pytest.raises(ValueError, match=rf"^cfa='quad_bayer': .*{message}"):
        _space(binning=binning, evaluate_options={"cfa": "quad_bayer"})
    designs = [{**HIGH_TIER[0].evaluate_kwargs(), "name": "A", "binning": 1.0},
               {**HIGH_TIER[0].evaluate_kwargs(), "name": "B", "binning": 2.0}]
    with pytest.raises(ValueError, match="binning takes one value per call"):
        Space(design=designs, illuminance_lux=100.0, evaluate_options={"cfa": "quad_bayer"})


def test_a_quad_bayer_design_with_modes_scans_as_evaluate_picks_its_modes():
    import epc_fast
    from epc_fast.scan import Summary, run

    modes = [{"binning": 1}, {"binning": 2}]
    space = Space(design=[{**HIGH_TIER[3].evaluate_kwargs(), "name": "Q", "modes": modes}],
                  illuminance_lux=LogUniform(1.0, 1e4), evaluate_options={"cfa": "quad_bayer"})
    summary = run(space, 256, seed=5, reductions={"s": Summary()}).results["s"]
    points = space.points(5, 0, 256).parameters
    alone = epc_fast.evaluate(**points, cfa="quad_bayer", modes=modes)
    assert summary.mean[0] == pytest.approx(np.mean(alone.epc), rel=1e-12)
    np.testing.assert_array_equal(summary.mode_counts[0][1:], np.bincount(alone.mode, minlength=2))
    assert np.all(summary.mode_counts[0][1:] > 0)  # dim points binned, bright ones full size
