"""Running a scan: the same numbers for any chunk size or thread count, partial results on
Ctrl-C, progress, Parquet output, and optional dependencies imported only when used."""

import dataclasses
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import epc_fast.scan
import epc_fast.scan.running.tasks
from epc_fast import evaluate
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import BLOCK_POINTS, FractionBelow, Grid, Histogram, Space, Summary, TopK, run
from epc_fast.scan.running.core_plan import CorePlan
from epc_fast.scan.plot import plot_distributions
from helpers.scan import SPACE, assert_same_numbers, every_reduction

POINTS = 10 * BLOCK_POINTS + 12345


def _run(**kwargs):
    options = {"seed": 3, "reductions": every_reduction(), "progress": False, **kwargs}
    return run(SPACE, POINTS, **options)


@pytest.fixture(scope="module")
def reference():
    return _run(chunk_points=BLOCK_POINTS, threads=2)


@pytest.mark.parametrize("chunk_points", [3 * BLOCK_POINTS, 10 * BLOCK_POINTS])
def test_results_are_identical_for_any_chunk_size(reference, chunk_points):
    assert_same_numbers(_run(chunk_points=chunk_points, threads=2), reference)


def test_results_are_identical_for_one_and_two_threads(reference):
    assert_same_numbers(_run(chunk_points=10 * BLOCK_POINTS, threads=1), reference)


def test_results_count_every_point_once(reference):
    assert reference.points == POINTS and not reference.partial
    assert reference["summary"].points.sum() == POINTS
    assert reference["below"].labels["read_noise_e"] == [0.0, 2.0] * 4


def _reductions_independent_of_the_total():
    return {"summary": Summary(by="design"), "histogram": Histogram(1e3, 1e7, 40, by="design"),
            "below": FractionBelow(2e6, by="design")}


def test_an_interrupt_from_the_progress_callback_returns_the_chunks_merged_so_far():
    def interrupt_after_two_chunks(done, total):
        if done >= 2 * BLOCK_POINTS:
            raise KeyboardInterrupt

    partial = run(SPACE, POINTS, seed=3, reductions=_reductions_independent_of_the_total(),
                  chunk_points=BLOCK_POINTS, progress=interrupt_after_two_chunks)
    assert partial.partial and partial.points == 2 * BLOCK_POINTS
    assert partial.points_requested == POINTS
    # The partial result is exactly the scan of its prefix.
    prefix = run(SPACE, 2 * BLOCK_POINTS, seed=3,
                 reductions=_reductions_independent_of_the_total(), chunk_points=BLOCK_POINTS,
                 progress=False)
    assert_same_numbers(dataclasses.replace(partial, partial=False), prefix)


def test_an_interrupt_inside_the_core_keeps_the_chunks_already_merged(monkeypatch):
    calls = []

    def evaluate_then_interrupt(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return evaluate(*args, **kwargs)

    monkeypatch.setattr(epc_fast.scan.running.tasks, "evaluate", evaluate_then_interrupt)
    partial = run(SPACE, POINTS, seed=3, chunk_points=BLOCK_POINTS, progress=False)
    assert partial.partial and partial.points == 2 * BLOCK_POINTS
    assert partial["summary"].points.sum() == 2 * BLOCK_POINTS


CTRL_C_SCRIPT = textwrap.dedent("""
    import signal, sys
    # Python's SIGINT handler even if this test run was started as a background job, whose
    # children inherit SIGINT ignored
    signal.signal(signal.SIGINT, signal.default_int_handler)
    from epc_fast.presets import HIGH_TIER
    from epc_fast.scan import LogUniform, Space, run

    def report(done, total):
        print("chunk", done, flush=True)

    space = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5))
    result = run(space, 10**9, seed=1, chunk_points=65536, threads=1, progress=report)
    print("result", result.partial, result.points, result["summary"].points.sum(), flush=True)
""")


def test_ctrl_c_stops_a_running_scan_with_a_partial_result():
    process = subprocess.Popen([sys.executable, "-c", CTRL_C_SCRIPT], stdout=subprocess.PIPE,
                               text=True)
    try:
        assert process.stdout.readline().startswith("chunk")
        process.send_signal(signal.SIGINT)
        out, _ = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 0
    _, partial, points, summed = out.splitlines()[-1].split()
    assert partial == "True" and 0 < int(points) < 10**9 and int(summed) == int(points)


def test_progress_callback_sees_every_chunk_end():
    seen = []
    run(SPACE, 3 * BLOCK_POINTS + 5, chunk_points=BLOCK_POINTS,
        progress=lambda done, total: seen.append((done, total)))
    total = 3 * BLOCK_POINTS + 5
    assert seen == [(BLOCK_POINTS, total), (2 * BLOCK_POINTS, total), (3 * BLOCK_POINTS, total),
                    (total, total)]


def test_the_progress_bar_is_quiet_off_a_terminal(capfd):
    run(SPACE, BLOCK_POINTS, progress=True)
    assert capfd.readouterr().err == ""


def test_parquet_output_holds_every_point_with_its_parameters_and_outputs(tmp_path):
    import pyarrow.parquet as pq

    points = 2 * BLOCK_POINTS + 77
    run(SPACE, points, seed=5, chunk_points=BLOCK_POINTS, progress=False,
        parquet=tmp_path / "points")
    assert len(list((tmp_path / "points").glob("part-*.parquet"))) == 3
    table = pq.read_table(tmp_path / "points").to_pydict()
    # the points as the core forms them (its fused pass too), and as NumPy draws them
    drawn = CorePlan(SPACE, 5).points(0, points)
    numpy_drawn = SPACE.points(5, 0, points)
    result = evaluate(**drawn.parameters)
    assert np.array_equal(table["point"], np.arange(points))
    assert table["design"] == [HIGH_TIER[i].name for i in drawn.indices["design"]]
    assert np.array_equal(drawn.indices["design"], numpy_drawn.indices["design"])
    for name in ("illuminance_lux", "shake_deg_per_s", "read_noise_e", "pixel_pitch_um"):
        assert np.array_equal(table[name], drawn.parameters[name]), name
        # the same uniforms; exp and the core's fused multiply-adds round differently:
        # log-uniform's exp(a + u b) moves by |a + u b| <= 12 ulp of its argument
        np.testing.assert_allclose(table[name], numpy_drawn.parameters[name], rtol=4e-15,
                                   atol=0, err_msg=name)
    assert np.array_equal(table["epc"], result.epc)
    assert np.array_equal(table["status"], result.status)


def test_parquet_refuses_a_directory_holding_another_scan(tmp_path):
    run(SPACE, 10, progress=False, parquet=tmp_path)
    with pytest.raises(FileExistsError, match="another scan"):
        run(SPACE, 10, progress=False, parquet=tmp_path)


def _plot(tmp_path):
    histogram = run(SPACE, 10, progress=False, reductions={"h": Histogram(1e3, 1e7)})["h"]
    plot_distributions(histogram, tmp_path / "h.png")


@pytest.mark.parametrize("modules, call, extra", [
    (("tqdm",), lambda tmp: run(SPACE, 10, progress=True), "progress"),
    (("pyarrow",), lambda tmp: run(SPACE, 10, progress=False, parquet=tmp), "parquet"),
    (("distributed",), lambda tmp: run(SPACE, 10, progress=False, client=object()), "dask"),
    (("matplotlib", "matplotlib.figure"), _plot, "plot"),
])
def test_a_missing_optional_dependency_names_its_extra(monkeypatch, tmp_path, modules, call,
                                                        extra):
    for module in modules:
        monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(ImportError, match=rf"epc-fast\[{extra}\]"):
        call(tmp_path)


def test_scanning_imports_no_optional_dependency():
    code = ("import sys; from epc_fast.presets import HIGH_TIER; from epc_fast import scan;"
            "scan.run(scan.Space(design=HIGH_TIER, illuminance_lux=100.0), progress=False);"
            "bad = [m for m in ('tqdm', 'pyarrow', 'dask', 'distributed', 'matplotlib')"
            " if m in sys.modules]; print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_a_grid_space_scans_its_grid_once_by_default():
    space = Space(design=HIGH_TIER, illuminance_lux=Grid((100.0, 1000.0, 10000.0)))
    assert run(space, progress=False).points == 12


@pytest.mark.parametrize("kwargs, error, message", [
    ({"chunk_points": 1000}, ValueError, "multiple of 65536"),
    ({"points": 0}, ValueError, "points must be >= 1"),
    ({"points": None}, TypeError, "needs points="),
])
def test_bad_run_arguments_are_refused(kwargs, error, message):
    with pytest.raises(error, match=message):
        run(SPACE, **{"points": 10, **kwargs})


def test_a_chunk_computes_only_the_outputs_its_reductions_use(reference, monkeypatch):
    # chunk_outputs: the reductions' outputs and the status; the same numbers as a scan that
    # computes every field (all outputs of one point come from one evaluation, bit for bit).
    asked = []
    real = epc_fast.scan.running.tasks.evaluate

    def recording(*args, **kwargs):
        asked.append(kwargs.get("outputs"))
        return real(*args, **kwargs)

    monkeypatch.setattr(epc_fast.scan.running.tasks, "evaluate", recording)
    lean = _run(chunk_points=BLOCK_POINTS, threads=2)
    assert set(asked) == {("status", "epc")}
    assert_same_numbers(lean, reference)
    asked.clear()  # T_MPE alone: f50 is not solved, and the summary counts every point
    only_t = _run(reductions={"t": Summary(of="t_mpe_s")}, chunk_points=BLOCK_POINTS,
                  backend="numpy")
    assert set(asked) == {("status", "t_mpe_s")} and only_t["t"].points.sum() == POINTS
    asked.clear()  # the core's fused pass makes no per-point arrays: evaluate is not called
    fused = _run(reductions={"t": Summary(of="t_mpe_s")}, chunk_points=BLOCK_POINTS)
    assert asked == [] and np.array_equal(fused["t"].status_counts, only_t["t"].status_counts)
    # the same draws to a few ulp, summed in another order (docs/scan.md)
    np.testing.assert_allclose(fused["t"].mean, only_t["t"].mean, rtol=1e-13)
    monkeypatch.setattr(epc_fast.scan.running.tasks, "chunk_outputs", lambda plan, parquet: None)
    asked.clear()
    assert_same_numbers(_run(chunk_points=BLOCK_POINTS, threads=2), reference)
    assert set(asked) == {None}


def test_a_chunk_asks_for_each_output_its_reductions_summarise():
    plan = tuple(epc_fast.scan.running.tasks.PlanItem(name, r, None) for name, r in {
        "a": Summary(of="t_mpe_s"), "b": Histogram(1e-3, 1.0, 10, of="blur_mm"),
        "c": TopK(3)}.items())
    assert epc_fast.scan.running.tasks.chunk_outputs(plan, parquet=False) == (
        "status", "blur_mm", "epc", "t_mpe_s")
    assert epc_fast.scan.running.tasks.chunk_outputs(plan, parquet=True) == tuple(
        epc_fast.api.OUTPUT_DTYPES)
    shares = tuple(epc_fast.scan.running.tasks.PlanItem(name, Summary(of=name), None)
                   for name in ("share_pixel", "epc"))
    assert epc_fast.scan.running.tasks.chunk_outputs(shares, parquet=True) == tuple(
        epc_fast.api.OUTPUT_DTYPES) + ("share_pixel",)


def test_a_scan_over_lens_tables_is_evaluate_on_its_points_per_lens():
    from epc_fast import Status, evaluate
    from epc_fast.scan import Choice, LogUniform, Space, Summary

    tables = [(np.array([0.0, 100.0, 200.0, 400.0, 909.0]),
               np.array([1.0, 0.8, 0.6, 0.25, 0.0])),
              (np.array([0.0, 50.0, 100.0, 200.0]), np.array([1.0, 0.7, 0.4, 0.0]))]
    space = Space(illuminance_lux=LogUniform(10, 1e4), pixel_pitch_um=1.4, f_number=2.0,
                  focal_length_mm=4.0, pixel_count=8e6, lens=Choice((0.0, 1.0)),
                  evaluate_options={"lens_mtf": tables})
    n = 1 << 14
    points = space.points(5, 0, n)
    for backend in ("core", "reference"):  # the core's scan evaluates a lens space as arrays
        result = epc_fast.scan.run(space, n, seed=5, backend=backend,
                                   reductions={"s": Summary(by="lens", of="epc")})["s"]
        direct = evaluate(**points.parameters, lens_mtf=tables, backend=backend)
        assert np.all(direct.status == Status.OK)
        for lens in (0, 1):
            picked = points.parameters["lens"] == lens
            assert result.status_counts[lens, Status.OK] == picked.sum()
            # the summary's blockwise mean against NumPy's: rounding only
            assert result.mean[lens] == pytest.approx(direct.epc[picked].mean(), rel=1e-12)
        assert result.mean[1] < result.mean[0]  # the softer lens
