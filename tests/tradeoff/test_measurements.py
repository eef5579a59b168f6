"""Speed against accuracy (epc_fast.tradeoff): the Pareto front, the settings and their knobs,
the error measure, the timing, and the reference against mpmath."""

import inspect
import math
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast.tradeoff import (Setting, default_settings, evaluate_parameters, f50_accuracy,
                               front_of, knob_value, pareto_front, split_by_knobs)
from helpers.tradeoff import measurement

# --- The Pareto front ----------------------------------------------------------------------------


def test_pareto_front_of_hand_made_points():
    #          0     1     2     3     4     5     6
    errors = [1e-6, 1e-14, 1e-10, 1e-10, 1e-8, 0.0, 1e-6]
    speeds = [9.0, 2.0, 5.0, 4.0, 5.0, 1.0, 8.0]
    # 3 loses to 2 (same error, slower), 4 to 2 (more error, as fast), 6 to 0 (same error,
    # slower); 5 (exact) and 1 (slow but accurate) stay; 0 is the fastest.
    assert pareto_front(errors, speeds) == [5, 1, 2, 0]


def test_pareto_front_keeps_equal_points_and_drops_nan():
    errors = [1e-12, 1e-12, math.nan, 1e-9, 1e-12]
    speeds = [3.0, 3.0, 100.0, 2.0, math.nan]
    assert pareto_front(errors, speeds) == [0, 1]


def test_pareto_front_of_a_single_point_and_of_none():
    assert pareto_front([1e-15], [1.0]) == [0]
    assert pareto_front([], []) == []
    with pytest.raises(ValueError, match="length"):
        pareto_front([1.0, 2.0], [1.0])


def test_front_of_measurements_leaves_out_the_polychromatic_settings():
    rows = [measurement("default", 5e-15, 2e6), measurement("fast", 1e-7, 4e6),
            measurement("poly 4", 4e-15, 1e6, spectrum_samples=4)]
    # "poly 4" has the smallest error, but solves another model.
    assert front_of(rows) == [0, 1]


# --- Settings and knobs --------------------------------------------------------------------------


def test_default_settings_cover_every_knob_once():
    settings = default_settings()
    names = [s.name for s in settings]
    assert len(names) == len(set(names))
    assert names[0] == "default" and settings[0].knobs() == set()
    solvers = {(s.kwargs["f50_solver"], s.kwargs["f50_rtol"]) for s in settings
               if "f50_solver" in s.kwargs}
    assert solvers == {(solver, rtol) for solver in ("halley", "newton", "bisection", "brent")
                       for rtol in (1e-14, 1e-10, 1e-6)}
    assert {s.spectrum_samples for s in settings} >= {None, 4, 16, 64}
    assert sum(s.kwargs.get("precision") == "float32" for s in settings) == 2
    assert any(s.kwargs == {"t_mpe_solver": "brent"} for s in settings)


def test_settings_with_unknown_knobs_are_skipped():
    settings = default_settings() + [Setting("warp", {"warp_drive": 9})]
    old_build = set(evaluate_parameters()) - {"f50_solver", "precision"}
    kept, skipped = split_by_knobs(settings, old_build)
    missing = {s.name: knobs for s, knobs in skipped}
    assert missing["warp"] == ["warp_drive"]
    assert missing["halley rtol=1e-14"] == ["f50_solver"]
    assert missing["float32 rtol=1e-6"] == ["precision"]
    assert {s.name for s in kept} >= {"default", "T_MPE brent", "poly 16"}
    assert not any(s.knobs() - old_build for s in kept)
    # The installed evaluate: only the made-up knob is always skipped.
    kept, skipped = split_by_knobs(settings, evaluate_parameters())
    assert "warp" in {s.name for s, _ in skipped}
    assert {s.name for s in kept} >= {"default", "T_MPE brent"}


def test_knob_values_come_from_the_setting_then_the_signature_then_the_old_build():
    parameters = evaluate_parameters()
    assert knob_value(Setting("x", {"f50_rtol": 1e-6}), "f50_rtol", parameters) == 1e-6
    assert knob_value(Setting("x"), "f50_rtol", parameters) == \
        inspect.signature(epc_fast.evaluate).parameters["f50_rtol"].default
    without = {k: v for k, v in parameters.items() if k not in ("f50_solver", "precision")}
    assert knob_value(Setting("x"), "f50_solver", without) == "bisection"
    assert knob_value(Setting("x"), "precision", without) == "float64"


# --- The error measure ---------------------------------------------------------------------------


def test_f50_accuracy_compares_only_points_ok_in_both():
    ok, unreachable = Status.OK, Status.UNREACHABLE
    result = SimpleNamespace(status=np.array([ok, ok, ok, unreachable, ok], dtype=np.uint8),
                             f50_cyc_per_mm=np.array([100.0, 201.0, 300.03, np.nan, 7.0]))
    reference = SimpleNamespace(status=np.array([ok, ok, ok, unreachable, unreachable],
                                                dtype=np.uint8),
                                f50_cyc_per_mm=np.array([100.0, 200.0, 300.0, np.nan, np.nan]))
    accuracy = f50_accuracy(result, reference)
    assert accuracy.points_compared == 3
    assert accuracy.status_mismatches == 1
    assert accuracy.max_rel_error == pytest.approx(5e-3)
    assert accuracy.median_rel_error == pytest.approx(1e-4)


def test_f50_accuracy_of_the_core_on_random_designs():
    from epc_fast.selfcheck import random_designs

    points = random_designs(2000, seed=3)
    accuracy = f50_accuracy(epc_fast.evaluate(**points),
                            epc_fast.evaluate(**points, backend="reference"))
    assert accuracy.status_mismatches == 0
    assert accuracy.points_compared > 1500
    assert accuracy.max_rel_error <= 1e-12


def test_points_per_s_times_every_setting_on_every_thread_count():
    from epc_fast.selfcheck import random_designs
    from epc_fast.tradeoff import points_per_s

    lines = []
    speeds = points_per_s(random_designs(1000), [{}, {"t_mpe_solver": "brent"}], (1, 2),
                          rounds=2, progress=lines.append)
    assert len(speeds) == 2 and all(set(s) == {1, 2} for s in speeds)
    assert all(v > 0 for s in speeds for v in s.values())
    assert lines[-2:] == ["timing round 1 of 2", "timing round 2 of 2"]


def test_points_per_s_writes_every_timed_call_into_the_same_arrays(monkeypatch):
    from epc_fast.tradeoff import measurements as tradeoff
    from epc_fast.selfcheck import random_designs

    seen = []
    real = tradeoff.evaluate

    def recording(*args, out=None, **kwargs):
        seen.append(out)
        return real(*args, out=out, **kwargs)

    monkeypatch.setattr(tradeoff, "evaluate", recording)
    tradeoff.points_per_s(random_designs(500), [{}, {"precision": "float32"}], (1, 2), rounds=2)
    first = seen[0]
    assert first is None and len(seen) == 4 + 8  # the first warm-up call makes the arrays
    assert all(out is not None and out.epc is seen[1].epc for out in seen[1:])


# --- What measuring imports, and the mpmath check ------------------------------------------------


def test_measuring_imports_no_matplotlib_and_keeps_the_plot_name():
    code = ("import sys, epc_fast.tradeoff as t;"
            "assert 'matplotlib' not in sys.modules;"
            "import epc_fast.tradeoff.plot as p, epc_fast.tradeoff.tables as tt;"
            "assert t.plot_tradeoff is p.plot_tradeoff and t.csv_columns is tt.csv_columns;"
            "assert 'matplotlib' not in sys.modules")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
