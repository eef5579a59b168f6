"""``epc-fast simulate``: a tiny config end to end (the files, their numbers those of
simulate.review, the --out lock and --overwrite, --seed and --no-plots) and its refusals, each
bad config one line naming the table, the key and the value, with exit code 2."""

import csv
import math

import pytest

from epc_fast.__main__ import main
from epc_fast.simulate.review import review

CONFIG = """\
[[design.custom]]
name = "big pixel"
pixel_pitch_um = 2.8
sensor_width_mm = 4.57
sensor_height_mm = 3.43
f_number = 2.8
focal_length_mm = 5.6

[simulate]
seed = 5
star_width_um = 67.2
spokes = 12
edge_rows = 32
flat_px = 32
max_edge_columns = 512
"""
#: The same design through the Python API (the corner's field angle, as the config gives it).
DESIGN = {"pixel_pitch_um": 2.8, "f_number": 2.8, "focal_length_mm": 5.6,
          "sensor_area_mm2": 4.57 * 3.43}
SETTINGS = {"seed": 5, "star_width_um": 67.2, "spokes": 12, "edge_rows": 32, "flat_px": 32,
            "max_edge_columns": 512, "max_blur_px": 1500}
ALL_FILES = ["agreement.csv", "agreement.md", "contact_sheet.png", "mtf.png", "mtf_across.png"]


def _simulate(tmp_path, capsys, text=CONFIG, *args, out="out"):
    path = tmp_path / "simulate.toml"
    path.write_text(text)
    code = main(["simulate", str(path), "--lux", "100", "1000", "--out",
                 str(tmp_path / out), *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def test_the_command_writes_the_pictures_and_the_table(tmp_path, capsys):
    code, out, err = _simulate(tmp_path, capsys)
    assert code == 0 and err == ""
    written = tmp_path / "out"
    assert sorted(p.name for p in written.iterdir()) == ALL_FILES
    for name in ALL_FILES:
        assert f"wrote {written / name}" in out
    assert (written / "contact_sheet.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "| big pixel | 1000 | 1,003,584 | 126.5 |" in (written / "agreement.md").read_text()


def test_the_table_holds_the_numbers_of_the_python_api(tmp_path, capsys):
    from epc_fast.sensor import corner_field_angle_deg

    _simulate(tmp_path, capsys)
    rows = _rows(tmp_path / "out" / "agreement.csv")
    design = {**DESIGN, "field_angle_deg": corner_field_angle_deg(4.57, 3.43, 5.6)}
    cells = review([("big pixel", design)], [100.0, 1000.0], **SETTINGS).cells[0]
    assert [r["design"] for r in rows] == ["big pixel"] * 2
    for row, cell in zip(rows, cells):
        assert float(row["illuminance_lux"]) == cell.illuminance_lux and row["status"] == "OK"
        assert float(row["epc_model"]) == pytest.approx(cell.epc, rel=1e-12)
        assert float(row["f50_model_cyc_per_mm"]) == pytest.approx(cell.f50_model_cyc_per_mm,
                                                                   rel=1e-12)
        assert float(row["mtf50_sim_cyc_per_mm"]) == pytest.approx(cell.mtf50_cyc_per_mm,
                                                                   rel=1e-9)
        assert float(row["snr_sim_db"]) == pytest.approx(cell.snr_db, rel=1e-9)
        assert float(row["snr_target_db"]) == 30.0 and row["note"] == ""
        # across the motion: the model's f50_across (the system MTF without the motion's
        # blur) beside the near-horizontal edge's MTF50
        assert float(row["f50_across_model_cyc_per_mm"]) == pytest.approx(
            cell.f50_across_model_cyc_per_mm, rel=1e-12)
        assert float(row["mtf50_across_sim_cyc_per_mm"]) == pytest.approx(
            cell.mtf50_across_cyc_per_mm, rel=1e-9)
        assert float(row["mtf50_across_over_f50_across"]) == pytest.approx(
            cell.mtf50_across_fraction, rel=1e-9)
    # the motion costs f50 at 100 lux, not f50_across
    assert float(rows[0]["f50_model_cyc_per_mm"]) < 0.2 * float(
        rows[0]["f50_across_model_cyc_per_mm"])
    assert rows[0]["f50_across_model_cyc_per_mm"] == rows[1]["f50_across_model_cyc_per_mm"]


def test_a_full_out_is_refused_unless_overwrite_and_seed_changes_the_captures(tmp_path, capsys):
    _simulate(tmp_path, capsys)
    before = _rows(tmp_path / "out" / "agreement.csv")
    code, out, err = _simulate(tmp_path, capsys)
    assert code == 2 and out == ""
    assert err.startswith("epc-fast simulate: error: --out") and "not empty" in err
    assert err.count("\n") == 1
    code, _, err = _simulate(tmp_path, capsys, CONFIG, "--overwrite", "--seed", "6")
    assert code == 0 and err == ""
    after = _rows(tmp_path / "out" / "agreement.csv")
    assert [r["epc_model"] for r in after] == [r["epc_model"] for r in before]
    assert [r["snr_sim_db"] for r in after] != [r["snr_sim_db"] for r in before]


def test_no_plots_writes_the_table_alone(tmp_path, capsys):
    code, _, _ = _simulate(tmp_path, capsys, CONFIG, "--no-plots")
    assert code == 0
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ALL_FILES[:2]


def test_epc_counted_in_both_directions_is_the_configs_and_said(tmp_path, capsys):
    # [evaluate] epc_axes = "both" reaches the model: its EPC is 4 S f50 f50_across (S the
    # sensor's 4.57 x 3.43 mm), and the table's first line says how EPC counts
    text = CONFIG.replace("[simulate]", '[evaluate]\nepc_axes = "both"\n\n[simulate]')
    code, out, err = _simulate(tmp_path, capsys, text, "--no-plots")
    assert code == 0 and err == ""
    assert 'EPC counts both directions, 4 S f50 f50_across (epc_axes = "both").' in out
    for row in _rows(tmp_path / "out" / "agreement.csv"):
        counted = (4 * 4.57 * 3.43 * float(row["f50_model_cyc_per_mm"])
                   * float(row["f50_across_model_cyc_per_mm"]))
        assert float(row["epc_model"]) == pytest.approx(counted, rel=1e-9)
    _, plain, _ = _simulate(tmp_path, capsys, CONFIG, "--no-plots", out="plain")
    assert "epc_axes" not in plain


def test_a_design_without_an_image_is_a_row_that_says_why(tmp_path, capsys):
    path = tmp_path / "simulate.toml"
    path.write_text(CONFIG)
    code = main(["simulate", str(path), "--lux", "0.1", "--out", str(tmp_path / "out"),
                 "--no-plots"])
    assert code == 0
    (row,) = _rows(tmp_path / "out" / "agreement.csv")
    assert row["status"] == "BLUR_UNBOUNDED" and row["note"].startswith("no image: ")
    assert math.isnan(float(row["mtf50_sim_cyc_per_mm"]))


def test_night_mode_under_a_frame_cap_is_captured_and_a_design_over_it_says_why(tmp_path,
                                                                                   capsys):
    night = CONFIG.replace("focal_length_mm = 5.6\n", "focal_length_mm = 5.6\nread_noise_e = 2.0\n"
                           "modes = [{binning = 1}, {binning = 2, frames = \"auto\", "
                           "max_frames = 16}]\n")
    night = "[evaluate]\nmax_exposure_s = 0.1\n\n" + night
    path = tmp_path / "night.toml"
    path.write_text(night)
    code = main(["simulate", str(path), "--lux", "0.3", "10", "--out", str(tmp_path / "out"),
                 "--no-plots"])
    assert code == 0
    dark, dim = _rows(tmp_path / "out" / "agreement.csv")
    assert dark["status"] == "EXPOSURE_LIMIT" and "max_exposure_s" in dark["note"]
    # 10 lux: night mode's 2 x 2 burst, each frame within 1/10 s, meets the SNR target; one
    # 32 x 32 flat patch estimates it to about 1/sqrt(2 x 1024) = 2.2% (0.19 dB): 1 dB is 5 s.e.
    assert dim["status"] == "OK" and abs(float(dim["snr_sim_db"]) - 30.0) < 1.0


BAD_CONFIGS = [
    (("seed = 5", "seed = -1"), "simulate config [simulate]: seed = -1: expected an integer "
                                "between 0 and"),
    (("spokes = 12", "spokes = 2"), "[simulate]: spokes = 2: expected an integer between 4"),
    (("spokes = 12", "spokes = 12\nstar_px = 3"), "[simulate]: unknown key(s) star_px"),
    (("star_width_um = 67.2", "star_width_um = 0"),
     "[simulate]: star_width_um = 0.0: expected a finite number > 0"),
    (("star_width_um = 67.2", "star_width_um = 14"),
     "[simulate]: star_width_um = 14.0: expected a width of 8 to 4,096 pixels of every design, "
     "got 5 pixels of 'big pixel' (2.8 um)"),
    (("flat_px = 32", "flat_px = 32\nmax_blur_px = -1"),
     "[simulate]: max_blur_px = -1: expected an integer between 0 and 100,000"),
    (("edge_rows = 32", "edge_rows = 8"), "[simulate]: edge_rows = 8: expected an integer "
                                          "between 16"),
    (("[[design.custom]]", "[design]\npresets = [\"NOPE\"]\n[[design.custom]]"),
     "[design]: presets: 'NOPE' is not a preset"),
    (("sensor_width_mm = 4.57\nsensor_height_mm = 3.43\n", ""),
     "[design.custom[0]] 'big pixel': no sensor size"),
    (("f_number = 2.8", "f_number = -2.8"), "[design.custom[0]] 'big pixel': f_number"),
    (("[simulate]", "[scan]\npoints = 3\n[simulate]"), "[top level]: unknown key(s) scan"),
    (("[simulate]", "[simulate"), "not valid TOML"),
]


@pytest.mark.parametrize("change, message", BAD_CONFIGS, ids=[m for _, m in BAD_CONFIGS])
def test_a_bad_config_is_one_line_with_exit_code_2(tmp_path, capsys, change, message):
    code, out, err = _simulate(tmp_path, capsys, CONFIG.replace(*change))
    assert code == 2 and out == ""
    assert err.startswith("epc-fast simulate: error: ") and err.count("\n") == 1
    assert message in err
    assert not (tmp_path / "out").exists()


def test_a_config_without_designs_names_the_design_table(tmp_path, capsys):
    code, _, err = _simulate(tmp_path, capsys, CONFIG.split("[simulate]")[1].join(
        ["[simulate]", ""]))
    assert code == 2 and "[top level]" in err and "design" in err


@pytest.mark.parametrize("lux", ["0", "-5", "nan", "lots"])
def test_a_bad_light_level_is_refused_by_argparse(tmp_path, capsys, lux):
    path = tmp_path / "simulate.toml"
    path.write_text(CONFIG)
    with pytest.raises(SystemExit) as stop:
        main(["simulate", str(path), "--lux", lux, "--out", str(tmp_path / "out")])
    assert stop.value.code == 2
    assert f"--lux {lux!r}: expected an illuminance in lux" in capsys.readouterr().err


def test_more_light_levels_than_a_sheet_holds_are_refused(tmp_path, capsys):
    code, out, err = _simulate(tmp_path, capsys, CONFIG, "--lux", *["100"] * 13)
    assert code == 2 and out == ""
    assert err == "epc-fast simulate: error: --lux: at most 12 light levels, got 13\n"


#: CONFIG's design as a colour camera with two readouts, written as a scan config writes it.
PHONE = CONFIG.replace("[[design.custom]]", '[evaluate]\ncfa = "bayer"\ndemosaic = "bilinear"\n\n'
                       "[[design.custom]]").replace(
    "focal_length_mm = 5.6\n", "focal_length_mm = 5.6\nmodes = [{binning = 1}, {binning = 2}]\n"
).replace("edge_rows = 32", "edge_rows = 64").replace("flat_px = 32", "flat_px = 64")


def test_a_bayer_design_with_modes_is_captured_in_the_picked_mode_and_meets_the_target(
        tmp_path, capsys):
    from epc_fast import evaluate
    from epc_fast.sensor import corner_field_angle_deg

    code, out, err = _simulate(tmp_path, capsys, PHONE, "--no-plots")
    assert code == 0 and err == ""
    rows = _rows(tmp_path / "out" / "agreement.csv")
    model = evaluate([100.0, 1000.0], **DESIGN, cfa="bayer", demosaic="bilinear",
                     field_angle_deg=corner_field_angle_deg(4.57, 3.43, 5.6),
                     modes=[{"binning": 1}, {"binning": 2}])
    assert list(model.mode) == [1, 0]
    assert [r["mode"] for r in rows] == ["binning=2", "binning=1"]
    for row, epc, f50 in zip(rows, model.epc, model.f50_cyc_per_mm):
        assert float(row["epc_model"]) == pytest.approx(epc, rel=1e-12)
        assert float(row["f50_model_cyc_per_mm"]) == pytest.approx(f50, rel=1e-12)
        # one capture of a 64-row edge and a 64 x 64 patch (test_review.py's tolerances)
        assert float(row["mtf50_over_f50"]) == pytest.approx(1.0, abs=0.2)
        assert float(row["snr_sim_db"]) == pytest.approx(30.0, abs=0.6)
    assert "| big pixel (binning=2) | 100 |" in (tmp_path / "out" / "agreement.md").read_text()


def test_a_design_error_names_the_simulate_config(tmp_path, capsys):
    # the designs are read by the scan's parser: its mistakes are the simulate config's
    code, _, err = _simulate(tmp_path, capsys, CONFIG.replace("f_number = 2.8", "f_number = -2"))
    assert code == 2
    assert err.startswith("epc-fast simulate: error: simulate config [design.custom[0]] "
                          "'big pixel': f_number = -2: expected a value in (1e-30, inf)")
