"""A histogram beside the reductions folded per replicate, and its counts as a table.

A chunk's group indices are cached by key: a summary's key with the replicate as its first
part and a histogram's key of the same ``by`` without it are two keys, each with its indices.
"""

import math

import numpy as np
import pytest

from epc_fast import evaluate
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import BLOCK_POINTS, Histogram, LogUniform, Space, Summary, run, tables

SPACE = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5))
LOW, HIGH, BINS = 1e3, 1e7, 8


def _scan(sampling, replicates, backend):
    reductions = {"summary": Summary(by="design"),
                  "histogram": Histogram(LOW, HIGH, BINS, by="design")}
    return run(SPACE, BLOCK_POINTS, seed=5, reductions=reductions, progress=False,
               backend=backend, sampling=sampling, replicates=replicates)


def _epc_by_design(result):
    points = result.space.points(result.seed, 0, result.points)
    epc = evaluate(**points.parameters).epc
    return [epc[points.indices["design"] == g] for g in range(len(HIGH_TIER))]


@pytest.mark.parametrize("sampling, replicates", [("sobol", 4), ("monte_carlo", 2)])
def test_a_histogram_after_a_summary_in_replicates_counts_every_point_per_design(
        sampling, replicates):
    result = _scan(sampling, replicates, "numpy")
    histogram = result["histogram"]
    assert result.points == BLOCK_POINTS and not result.partial
    edges = np.linspace(math.log10(LOW), math.log10(HIGH), BINS + 1)
    for g, epc in enumerate(_epc_by_design(result)):
        finite = epc[np.isfinite(epc)]
        expected, _ = np.histogram(np.log10(finite), edges)
        assert histogram.counts[g].tolist() == expected.tolist()
        assert histogram.below[g] == np.count_nonzero(finite < LOW)
        assert histogram.above[g] == np.count_nonzero(finite >= HIGH)
    assert result["summary"].count.sum() == BLOCK_POINTS


def test_the_histogram_table_has_a_row_per_design_and_bin_whose_counts_sum_to_the_points():
    result = _scan("sobol", 4, "core")
    table = tables.histogram_tables(result)["histogram"]
    assert list(table) == ["design", tables.SNR_TARGET_COLUMN, "bin", "epc low", "epc high",
                           "points"]
    rows = BINS + 3  # below, the bins, above, not finite
    assert len(table["design"]) == len(HIGH_TIER) * rows
    assert sum(table["points"]) == result.points
    assert table["bin"][:rows] == ["below", *map(str, range(1, BINS + 1)), "above",
                                   "not finite"]
    edges = np.geomspace(LOW, HIGH, BINS + 1)
    np.testing.assert_allclose(table["epc low"][1:BINS + 1], edges[:-1], rtol=1e-12)
    np.testing.assert_allclose(table["epc high"][1:BINS + 1], edges[1:], rtol=1e-12)
    for g, epc in enumerate(_epc_by_design(result)):
        counts = table["points"][g * rows:(g + 1) * rows]
        finite = epc[np.isfinite(epc)]
        expected, _ = np.histogram(np.log10(finite), np.log10(edges))
        assert counts[1:BINS + 1] == expected.tolist()
        assert counts[0] == np.count_nonzero(finite < LOW)
        assert counts[BINS + 1] == np.count_nonzero(finite >= HIGH)
        assert counts[-1] == np.count_nonzero(~np.isfinite(epc))
        assert set(table["design"][g * rows:(g + 1) * rows]) == {HIGH_TIER[g].name}
