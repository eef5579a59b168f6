"""The tables of speed against accuracy: the front marked, zero errors written as 0."""

from epc_fast.tradeoff import front_of, markdown_columns
from helpers.tradeoff import measurement


def test_markdown_marks_the_front_and_writes_zero_errors_as_0():
    rows = [measurement("default", 0.0, 2e6), measurement("slow", 1e-9, 1e6)]
    columns = markdown_columns(rows, front_of(rows))
    assert columns["setting"] == ["default *", "slow"]
    assert columns["max rel err"] == ["0", "1.0e-09"]
    assert columns["speed-up vs default"] == ["1.00", "0.50"]
