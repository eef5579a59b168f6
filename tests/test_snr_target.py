"""Where evaluate met the SNR target is part of its result and its printout: evaluate meets it
on the optical axis by default, the presets and scans at the image corner, and for a lens with
strong vignetting that moves EPC several-fold (docs/model.md)."""

import numpy as np
import pytest

import epc_fast
from epc_fast.presets import HIGH_TIER

SENSOR = {"sensor_width_mm": 4.57, "sensor_height_mm": 3.43}


def test_the_default_result_says_the_target_was_met_on_the_axis_by_default():
    r = epc_fast.evaluate(1000, 1.4, 2.8, 5.6, pixel_count=3200 * 2400)
    assert r.snr_target == "30 dB at axis (default)"
    assert repr(r).endswith(", snr_target='30 dB at axis (default)')")


@pytest.mark.parametrize("keywords, text", [
    ({"snr_at": "corner"}, "30 dB at corner (27.03 deg)"),
    ({"snr_at": "axis", "snr_db": 33.0}, "33 dB at axis"),
    ({"field_angle_deg": 12.5}, "30 dB at field angle 12.5 deg"),
    ({"field_angle_deg": np.array([0.0, 10.0]), "snr_db": np.array([[20.0], [30.0]])},
     "20 to 30 dB at field angles 0 to 10 deg"),
    ({"snr_at": "corner", "focal_length_mm": np.array([5.6, 16.8])},
     "30 dB at corner (9.65 to 27.03 deg)"),
])
def test_the_result_says_where_the_target_was_met(keywords, text):
    options = {"focal_length_mm": 5.6, **keywords}
    r = epc_fast.evaluate(1000, 1.4, 2.8, **SENSOR, **options)
    assert r.snr_target == text


def test_the_corner_and_the_axis_differ_and_each_result_says_which_it_is():
    design = HIGH_TIER[3]
    corner = epc_fast.evaluate(10.0, design.pixel_pitch_um, design.f_number,
                               design.focal_length_mm, **SENSOR, snr_at="corner")
    axis = epc_fast.evaluate(10.0, design.pixel_pitch_um, design.f_number,
                             design.focal_length_mm, **SENSOR)
    assert axis.epc > 1.5 * corner.epc
    assert (axis.snr_target, corner.snr_target) == ("30 dB at axis (default)",
                                                    "30 dB at corner (27.03 deg)")


def test_a_result_with_readout_modes_says_where_the_target_was_met_too():
    r = epc_fast.evaluate(100, 1.4, 2.8, 5.6, **SENSOR, snr_at="corner",
                          modes=[{"binning": 1}, {"binning": 2}])
    assert r.snr_target == "30 dB at corner (27.03 deg)"
