"""The speed/accuracy measurements (:mod:`epc_fast.tradeoff`) as table columns: text for
Markdown, full-precision values for CSV."""

from __future__ import annotations

import math
from collections.abc import Sequence

from .measurements import THREADS, Measurement, rtol_text, speedups

__all__ = ["markdown_columns", "csv_columns"]


def _error_text(value: float) -> str:
    if math.isnan(value):
        return "n/a"
    return "0" if value == 0 else f"{value:.1e}"


def markdown_columns(measurements: Sequence[Measurement], front: Sequence[int] = ()) -> dict:
    """{column: [text]} for the markdown table; settings on ``front`` are marked ``*``."""
    ratios = speedups(measurements)
    return {
        "setting": [m.setting.name + (" *" if i in front else "")
                    for i, m in enumerate(measurements)],
        "f50 solver": [str(m.f50_solver) for m in measurements],
        "rtol": [rtol_text(m.f50_rtol) for m in measurements],
        "precision": [str(m.precision) for m in measurements],
        "max rel err": [_error_text(m.accuracy.max_rel_error) for m in measurements],
        "median rel err": [_error_text(m.accuracy.median_rel_error) for m in measurements],
        **{f"M points/s ({t} thread{'s' if t > 1 else ''})":
           [f"{m.points_per_s[t] / 1e6:.3g}" for m in measurements] for t in THREADS},
        "speed-up vs default": ["n/a" if math.isnan(r) else f"{r:.2f}" for r in ratios],
    }


def csv_columns(measurements: Sequence[Measurement], front: Sequence[int] = ()) -> dict:
    """{column: [value]} for the CSV table, every number at full precision."""
    ratios = speedups(measurements)
    return {
        "setting": [m.setting.name for m in measurements],
        "f50_solver": [m.f50_solver for m in measurements],
        "f50_rtol": [float(m.f50_rtol) for m in measurements],
        "precision": [m.precision for m in measurements],
        "spectrum_samples": [m.setting.spectrum_samples or "" for m in measurements],
        "extra_kwargs": [" ".join(f"{k}={v!r}" for k, v in m.setting.kwargs.items())
                         for m in measurements],
        "max_rel_error": [m.accuracy.max_rel_error for m in measurements],
        "median_rel_error": [m.accuracy.median_rel_error for m in measurements],
        "points_compared": [m.accuracy.points_compared for m in measurements],
        "status_mismatches": [m.accuracy.status_mismatches for m in measurements],
        **{f"points_per_s_{t}_thread{'s' if t > 1 else ''}":
           [m.points_per_s[t] for m in measurements] for t in THREADS},
        "speedup_vs_default": ratios,
        "pareto": [str(i in front).lower() for i in range(len(measurements))],
    }
