"""The table written from the paper's statements (epc_fast.paper.table): the CSV at full
precision, and the Markdown table that docs/paper.md shows, both backends'."""

from __future__ import annotations

import csv

from epc_fast.paper.table import CSV_COLUMNS, markdown_table, write_csv
from helpers.scripts import ROOT

DOCS = ROOT / "docs" / "paper.md"


def test_the_csv_holds_every_value_at_full_precision(table, tmp_path):
    path = tmp_path / "statements.csv"
    write_csv(table.values(), path)
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == CSV_COLUMNS
    for row in rows:
        s = table[row["id"]]
        for name in ("preset_value", "on_axis_30db_value", "on_axis_33db_value"):
            assert float(row[name]) == getattr(s, name)  # repr round-trips a float exactly


def test_the_table_in_the_docs_is_the_current_one(table):
    # Values are printed to 4 digits and deviations to 0.01%: the two backends print the same.
    assert markdown_table(table.values()) in DOCS.read_text(encoding="utf-8")
