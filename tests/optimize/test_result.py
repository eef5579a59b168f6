"""The optimiser's result (epc_fast.optimize.Optimum): the optimum as plain JSON values and a
Markdown table."""

from epc_fast import optimize
from helpers.optimize import PITCH, scene


def test_the_optimum_is_written_as_plain_json_values():
    best = optimize.maximize(scene(), PITCH, optimize.Quantile(0.5), points=2_000, seed=1)
    document = best.as_dict()
    assert document["objective"] == {"kind": "Quantile", "q": 0.5, "label": "median EPC"}
    assert document["x"]["pixel_pitch_um"] == best.x["pixel_pitch_um"]
    assert len(document["batch_x"]["pixel_pitch_um"]) == best.batches == 10
    assert document["bounds"] == {"pixel_pitch_um": [0.8, 4.0]}
    table = best.markdown()
    assert f"| pixel_pitch_um | {best.x['pixel_pitch_um']:.6g} |" in table
    assert "| median EPC (pixels) |" in table
