"""Text on figures (epc_fast.plotting.text): units as a reader writes them, labels from names."""

from __future__ import annotations

import pytest

from epc_fast.params import PARAMETER_NAMES
from epc_fast.plotting.text import output_scale, quantity_label, quantity_unit, unit_text
from epc_fast.scan.running.chunk import OUTPUTS


@pytest.mark.parametrize("name, label", [
    ("illuminance_lux", "Illuminance (lux)"), ("pixel_pitch_um", "Pixel pitch (µm)"),
    ("shake_deg_per_s", "Hand shake (°/s)"), ("read_noise_e", "Read noise (e⁻)"),
    ("sensor_area_mm2", "Sensor area (mm²)"), ("f_number", "f-number"),
    ("stabilization", "Stabilisation factor"), ("epc", "EPC (Mpixel)"),
    ("f50_cyc_per_mm", "f50 (cycles/mm)"), ("t_mpe_s", "Exposure time T_MPE (s)"),
    ("snr_db", "SNR (dB)"), ("electrons", "Electrons"),
])
def test_quantity_labels_are_words_with_units(name, label):
    assert quantity_label(name) == label


@pytest.mark.parametrize("name", PARAMETER_NAMES + OUTPUTS)
def test_every_name_gives_a_label_without_underscores_or_ascii_units(name):
    label = quantity_label(name)
    assert "_" not in label.replace("T_MPE", "") and "um" not in label.split()
    assert label[0].isupper() or label.startswith(("f-", "f50"))


def test_unit_text_writes_micrometres_and_superscripts_and_leaves_words_alone():
    assert unit_text('1/3.2" 2.8 um') == '1/3.2" 2.8 µm'
    assert unit_text("1.75um, cos^4 falloff, mm^2") == "1.75µm, cos⁴ falloff, mm²"
    assert unit_text("umbrella, maximum, drum") == "umbrella, maximum, drum"


def test_epc_is_drawn_in_megapixels_and_other_outputs_in_their_unit():
    assert output_scale("epc") == 1e6 and quantity_unit("epc") == "Mpixel"
    assert output_scale("t_mpe_s") == 1.0 and quantity_unit("t_mpe_s") == "s"
    assert quantity_unit("reflectance") == ""
