"""A table's columns as markdown and CSV (epc_fast.jobs.table_formats)."""

import csv

from epc_fast.jobs.table_formats import markdown, write_csv


def test_markdown_cells_have_thousands_separators_and_four_digits():
    text = markdown({"n": [1234567], "x": [0.000123456], "name": ["a|b"]})
    assert text.splitlines()[2] == "| 1,234,567 | 0.0001235 | a\\|b |"


def test_a_csv_cell_that_a_spreadsheet_would_run_as_a_formula_is_written_as_text(tmp_path):
    write_csv(tmp_path / "t.csv", {"name": ["=1+1", "plain"], "x": [0.1, 2]})
    with open(tmp_path / "t.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows == [["name", "x"], ["'=1+1", "0.1"], ["plain", "2"]]
