"""The design review's figures, read back from the renderer: every picture the same patch of
scene drawn pixel by pixel from black to the star's white, captions with the model's EPC and the
measured MTF50 and SNR, a cell without an image saying why, the MTF panels with the simulated
edge against the model's system MTF, and the conditions on both; no panel empty and no text
outside the figure."""

import numpy as np
import pytest

pytest.importorskip("matplotlib")

from epc_fast.plotting.common import build_text  # noqa: E402
from epc_fast.reference.model import mtf_system  # noqa: E402
from epc_fast.simulate.plot import contact_sheet_figure, model_mtf, mtf_figure  # noqa: E402
from helpers.figures import boxes_outside, text_boxes  # noqa: E402
from helpers.reviews import DESIGNS, LUX, small_review  # noqa: E402


@pytest.fixture(scope="module")
def sheet():
    return contact_sheet_figure(small_review())


@pytest.fixture(scope="module")
def curves():
    return mtf_figure(small_review())


@pytest.fixture(scope="module")
def across():
    return mtf_figure(small_review(), direction="across")


def _conditions(figure) -> str:
    return "\n".join(t.get_text() for t in figure.texts)


@pytest.mark.parametrize("name", ["sheet", "curves", "across"])
def test_every_figure_carries_its_conditions(name, request):
    figure = request.getfixturevalue(name)
    text = _conditions(figure)
    assert "Designs: 1/3.2\" 2.8 µm, 1/3.2\" 2.2 µm" in text
    assert "SNR target: 30 dB at corner (27.03 deg" in text
    assert "Scene: 0.1, 100, 1000 lux; Siemens star of 12 sine spokes, 67.2 µm wide" in text
    assert "seed 11" in text and build_text() in text


@pytest.mark.parametrize("name", ["sheet", "curves", "across"])
def test_no_text_leaves_the_figure(name, request):
    figure = request.getfixturevalue(name)
    assert boxes_outside(text_boxes(figure), figure) == []


def test_the_sheet_has_a_row_a_design_and_a_column_a_light_level(sheet):
    axes = np.array(sheet.axes).reshape(len(DESIGNS), len(LUX))
    assert [ax.get_title() for ax in axes[0]] == ["0.1 lux", "100 lux", "1000 lux"]
    assert [ax.get_ylabel() for ax in axes[:, 0]] == ['1/3.2" 2.8 µm', '1/3.2" 2.2 µm']


def test_no_picture_is_empty_and_a_cell_without_an_image_says_why(sheet):
    review = small_review()
    for ax, cell in zip(sheet.axes, (c for row in review.cells for c in row)):
        if cell.why:
            assert not ax.images and "no image:" in ax.texts[0].get_text()
            assert "90 degrees" in ax.texts[0].get_text().replace("\n", " ")
        else:
            (image,) = ax.images
            np.testing.assert_array_equal(image.get_array(), cell.star.image_e)


def test_every_picture_is_the_same_patch_of_scene_pixel_by_pixel_from_black_to_white(sheet):
    review = small_review()
    for ax, cell in zip(sheet.axes, (c for row in review.cells for c in row)):
        assert ax.get_xlim() == (0.0, 67.2) and ax.get_ylim() == (67.2, 0.0)
        assert ax.get_position().width == pytest.approx(sheet.axes[0].get_position().width)
        for image in ax.images:
            left, right, _, _ = image.get_extent()
            assert right - left == pytest.approx(cell.star.image_e.shape[1] * cell.star.pitch_um)
            assert (left + right) / 2 == pytest.approx(33.6)
            assert image.get_clim() == (0.0, cell.white_e)
            assert image.get_interpolation() == "nearest" and image.get_cmap().name == "gray"


def test_each_caption_gives_the_models_epc_and_the_measured_mtf50_and_snr(sheet):
    review = small_review()
    captions = [ax.get_xlabel() for ax in sheet.axes]
    bright = review.cells[0][2]
    assert captions[2] == (f"EPC {bright.epc / 1e6:.3g} Mpx (model)\n"
                           f"MTF50 {bright.mtf50_cyc_per_mm:.3g} cyc/mm = "
                           f"{bright.mtf50_fraction:.2f} f50\nSNR {bright.snr_db:.1f} dB "
                           "(target 30)")
    assert captions[0] == "no image"
    assert "MTF50 not measured" in captions[4]


def test_the_mtf_figure_has_a_panel_a_design_none_empty(curves):
    assert [ax.get_title() for ax in curves.axes] == ['1/3.2" 2.8 µm', '1/3.2" 2.2 µm']
    for ax in curves.axes:
        assert len([line for line in ax.lines if len(line.get_xdata()) > 1]) >= 2


def test_each_panel_runs_to_twice_nyquist_with_the_edges_and_the_models_curves(curves):
    review = small_review()
    for i, ax in enumerate(curves.axes):
        pitch = DESIGNS[i].pixel_pitch_um
        assert ax.get_xlim() == pytest.approx((0.0, 1e3 / pitch))
        cell = review.cells[i][2]  # 1000 lux, measured in both designs
        model = [line for line in ax.lines if line.get_linestyle() == "--"
                 and line.get_color() == "C2"][0]
        f = model.get_xdata()
        np.testing.assert_allclose(model.get_ydata(), model_mtf(f, review.kwargs[i],
                                                                float(cell.result.blur_mm)))
        edge = [line for line in ax.lines if line.get_linestyle() == "-"
                and line.get_color() == "C2" and len(line.get_xdata()) > 1][0]
        assert edge.get_xdata().max() <= 1e3 / pitch
        circles = [line for line in ax.lines if line.get_marker() == "o"
                   and line.get_color() == "C2"]
        assert circles[0].get_xdata()[0] == cell.mtf50_cyc_per_mm
        assert circles[0].get_ydata()[0] == 0.5
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert legend[0] == "0.1 lux: no image"
        assert legend[2].startswith(f"1000 lux: MTF50 {cell.mtf50_cyc_per_mm:.3g} (model ")


def test_the_across_figure_draws_the_edge_across_the_motion_against_the_unblurred_model(across):
    review = small_review()
    text = _conditions(across).replace("\n  ", " ")
    assert "Across the motion: slanted edge 85 deg from the vertical" in text
    assert "x its f50_across" in text
    assert across.get_suptitle().endswith("against the model, across the motion")
    for i, ax in enumerate(across.axes):
        cell = review.cells[i][1]  # 100 lux: a long blur along the motion, none across it
        model = [line for line in ax.lines if line.get_linestyle() == "--"
                 and line.get_color() == "C1"][0]
        f = model.get_xdata()
        np.testing.assert_allclose(model.get_ydata(), model_mtf(f, review.kwargs[i], 0.0))
        cross = [line for line in ax.lines if line.get_marker() == "x"
                 and line.get_color() == "C1"][0]
        assert cross.get_xdata()[0] == cell.f50_across_model_cyc_per_mm
        circle = [line for line in ax.lines if line.get_marker() == "o"
                  and line.get_color() == "C1"][0]
        assert circle.get_xdata()[0] == cell.mtf50_across_cyc_per_mm
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert legend[1] == (f"100 lux: MTF50 {cell.mtf50_across_cyc_per_mm:.3g} "
                             f"(model {cell.f50_across_model_cyc_per_mm:.3g})")
    with pytest.raises(ValueError, match="direction"):
        mtf_figure(review, direction="sideways")


def test_epc_counted_in_both_directions_is_said_in_the_captions_and_conditions():
    from dataclasses import replace

    r = _one_column(small_review(), 2)
    both = replace(r, kwargs=tuple({**k, "epc_axes": "both"} for k in r.kwargs),
                   cells=tuple((replace(row[0], kwargs={**row[0].kwargs, "epc_axes": "both"}),)
                               for row in r.cells))
    figure = contact_sheet_figure(both)
    assert figure.axes[0].get_xlabel().startswith("EPC ") and "(model, both axes)" in (
        figure.axes[0].get_xlabel())
    assert 'epc_axes="both"' in _conditions(figure).replace("\n  ", " ")
    assert "both" not in _conditions(contact_sheet_figure(r))


def test_the_models_mtf_is_the_references_system_mtf():
    kwargs = DESIGNS[0].evaluate_kwargs()
    f = np.linspace(0.0, 400.0, 9)
    np.testing.assert_array_equal(model_mtf(f, kwargs, 0.01), mtf_system(
        f, 2.8, 2.8, 1.0, 0.01, 0.0, np.array([550.0]), np.array([1.0])))


def _one_column(review, light: int):
    """The review with one light level, ``light``: the narrowest contact sheet."""
    from epc_fast.simulate.review import Review

    return Review(review.designs, review.kwargs, review.snr_target,
                  (review.illuminance_lux[light],), tuple((row[light],) for row in review.cells),
                  review.settings)


def test_a_one_column_sheets_title_and_conditions_lie_within_the_figure(tmp_path):
    figure = contact_sheet_figure(_one_column(small_review(), 2))
    boxes = text_boxes(figure)
    assert "suptitle" in boxes and "figure text 0" in boxes
    assert boxes_outside(boxes, figure) == []
    figure.savefig(tmp_path / "sheet.png", dpi=60)


def test_the_terms_a_review_turns_on_are_in_its_conditions():
    from dataclasses import replace

    r = replace(_one_column(small_review(), 2), terms=("colour filter Bayer", "lens MTF table"))
    text = _conditions(contact_sheet_figure(r))
    assert "Terms on: colour filter Bayer; lens MTF table" in text.replace("\n  ", " ")


def test_a_binned_designs_mtf_panel_is_drawn_at_the_binned_pixels_nyquist():
    from epc_fast.presets import HIGH_TIER
    from epc_fast.simulate.review import review

    design = {**HIGH_TIER[3].evaluate_kwargs(), "binning": 2}  # a 2.8 um output pixel
    r = review([("1.4 um 2x2", design)], [1000.0],
               **{"seed": 3, "star_width_um": 67.2, "spokes": 12, "edge_rows": 64,
                  "flat_px": 32})
    (ax,) = mtf_figure(r).axes
    assert ax.get_xlim() == pytest.approx((0.0, 1e3 / 2.8))
    (nyquist,) = [line for line in ax.lines
                  if len(line.get_xdata()) == 2 and line.get_xdata()[0] == line.get_xdata()[1]]
    assert nyquist.get_xdata()[0] == pytest.approx(1e3 / 5.6)
    # the dashed model curve is the binned design's: it crosses 0.5 at evaluate's f50
    (model,) = [line for line in ax.lines if line.get_linestyle() == "--"]
    f, m = model.get_xdata(), model.get_ydata()
    i = int(np.argmax(m < 0.5))  # the first point below 0.5
    crossing = f[i - 1] + (f[i] - f[i - 1]) * (m[i - 1] - 0.5) / (m[i - 1] - m[i])
    assert crossing == pytest.approx(r.cells[0][0].f50_model_cyc_per_mm, rel=2e-3)
