"""A small design review (epc_fast.simulate.review) for the tests of its captures and figures:
two of the paper's designs at a light level with no image, one whose long blur is not measured
and one measured, on charts small enough for a few seconds."""

from functools import lru_cache

from epc_fast.presets import HIGH_TIER

#: lux: 0.1 (the camera turns 90 degrees during T_MPE: no image), 100 (the 2.2 um design's
#: 20-pixel blur needs 174 edge columns, more than SETTINGS allow; the 2.8 um design's 10-pixel
#: blur 154), 1000 (every cell measured).
LUX = (0.1, 100.0, 1000.0)
DESIGNS = HIGH_TIER[:2]
#: Tiny charts: a 67.2 um star (24 pixels at 2.8 um, 31 at 2.2 um), 64-row edges and 32-pixel
#: flat patches.
SETTINGS = {"seed": 11, "star_width_um": 67.2, "spokes": 12, "edge_rows": 64,
            "max_edge_columns": 160, "flat_px": 32}


@lru_cache(maxsize=None)
def small_review():
    """The review of DESIGNS at LUX with SETTINGS, computed once a test session."""
    from epc_fast.simulate.review import review

    return review([(d.name, d.evaluate_kwargs()) for d in DESIGNS], LUX,
                  snr_target=[f"30 dB at {d.snr_at_text}" for d in DESIGNS], **SETTINGS)
