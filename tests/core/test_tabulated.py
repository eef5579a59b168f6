"""The core's table lookup (cpp/include/epc_fast/tabulated.h): the grid finds the segment
std::upper_bound finds at every frequency (on the knots, between them, past the end, on
clustered knots that need several steps), and the vectorised lane passes (table_lanes) give the
lane-by-lane interpolant bit for bit."""

import numpy as np
import pytest

from epc_fast._validation import compiled_core
from epc_fast.core_call import core_tables
from epc_fast.mtf_table import mtf_table

UNIFORM = ([0.0, 50.0, 100.0, 150.0, 200.0, 250.0, 300.0], [1.0, 0.88, 0.74, 0.60, 0.47, 0.36, 0.27])
_FINE = np.linspace(0.0, 400.0, 64)
FINE = (_FINE, np.exp(-_FINE / 250.0))
# knots 1e-6 apart below 1e-4, then one far: the grid's 4096 cells each hold many knots
_CLUSTER = np.concatenate([np.arange(0.0, 1e-4, 1e-6), [1.0, 2.0]])
CLUSTERED = (_CLUSTER, np.linspace(1.0, 0.2, _CLUSTER.size))
_RANDOM = np.concatenate([[0.0], np.cumsum(np.random.default_rng(7).exponential(1.0, 40) ** 3)])
RANDOM = (_RANDOM, np.linspace(1.0, 0.0, _RANDOM.size) ** 2)
# 5,000 knots of random spacing: more knots than the grid's 4,096 cells
_MANY = np.concatenate([[0.0], np.cumsum(np.random.default_rng(11).uniform(0.1, 2.0, 4999))])
MANY = (_MANY, np.linspace(1.0, 0.05, _MANY.size))
TABLES = {"uniform": UNIFORM, "fine": FINE, "clustered": CLUSTERED, "random spacing": RANDOM,
          "5,000 knots": MANY}


def _lookup(table, f):
    (triple,) = core_tables([mtf_table("lens_mtf", table)])
    return compiled_core().testing.table_lookup(triple, np.asarray(f, dtype=np.float64))


def _frequencies(knots):
    """Every knot, its neighbouring doubles, midpoints, points across and past the table, 0, a
    negative, inf and NaN."""
    knots = np.asarray(knots, dtype=np.float64)
    end = knots[-1]
    rng = np.random.default_rng(3)
    return np.concatenate([knots, np.nextafter(knots, -np.inf), np.nextafter(knots, np.inf),
                           0.5 * (knots[1:] + knots[:-1]), rng.uniform(0.0, 1.1 * end, 5000),
                           rng.uniform(0.0, end, 5000) ** 3 / end ** 2,
                           [0.0, -1.0, 2.0 * end, np.inf, np.nan]])


@pytest.mark.parametrize("name", TABLES)
def test_the_grid_finds_the_segment_of_a_binary_search(name):
    knots = TABLES[name][0]
    f = _frequencies(knots)
    grid, bound, _, _, cells, steps = _lookup(TABLES[name], f)
    finite = ~np.isnan(f)  # NaN: any segment (its interpolant is NaN)
    np.testing.assert_array_equal(grid[finite], bound[finite])
    assert 1 <= cells <= 4096
    if name in ("uniform", "fine"):  # twice as many cells as the narrowest segment fits: 1 step
        assert steps == 1, steps
    if name == "clustered":  # 4096 cells over [0, 2]: the 100 knots below 1e-4 share one cell
        assert steps >= 99, steps


@pytest.mark.parametrize("name", TABLES)
def test_the_lane_passes_give_the_lane_by_lane_interpolant_bit_for_bit(name):
    f = _frequencies(TABLES[name][0])
    _, _, lane, lanes, _, _ = _lookup(TABLES[name], f)
    np.testing.assert_array_equal(lanes, lane)


def test_past_the_last_knot_the_table_holds_its_last_value_with_no_slope():
    knots, values = UNIFORM
    _, _, lane, _, _, _ = _lookup(UNIFORM, [300.0, np.nextafter(300.0, np.inf), 1e9, np.inf])
    assert lane[0, 0] == pytest.approx(values[-1], rel=1e-15)  # the last segment's end
    np.testing.assert_array_equal(lane[:, 1:], [[values[-1]] * 3, [0.0] * 3, [0.0] * 3])


def test_on_a_knot_the_interpolant_is_the_tabulated_value():
    knots, values = FINE
    _, _, lane, _, _, _ = _lookup(FINE, knots[:-1])
    np.testing.assert_array_equal(lane[0], values[:-1])  # s = 0: the segment's y_k exactly
