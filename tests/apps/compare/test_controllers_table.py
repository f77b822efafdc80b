"""The controllers' comparison table (uvms_pin.apps.compare.table): a Markdown table whose
every line has the header's columns, and the same rows as CSV."""

from __future__ import annotations

import csv
import math

from uvms_pin.apps.compare.table import markdown_table, write_table


def _cells(line: str) -> list[str]:
    assert line.startswith("|") and line.endswith("|"), line
    return [c.strip() for c in line[1:-1].split("|")]


def test_the_markdown_table_is_well_formed_and_the_csv_holds_the_same_rows(tmp_path):
    columns = ("controller", "rms_N", "note")
    rows = [
        {"controller": "ppc", "rms_N": 0.123456, "note": "a|b"},
        {"controller": "pi_force", "rms_N": math.nan, "note": "ok", "extra": 1},
    ]
    lines = markdown_table(rows, columns).splitlines()
    assert _cells(lines[0]) == list(columns)
    assert _cells(lines[1]) == ["---"] * len(columns)  # a delimiter cell per column
    assert _cells(lines[2]) == ["ppc", "0.1235", "a/b"]  # 4 significant digits; no stray '|'
    assert _cells(lines[3]) == ["pi_force", "-", "ok"]  # NaN shown as '-'
    assert len(lines) == 4
    csv_path, md_path = write_table(rows, tmp_path, "# Controllers", columns)
    text = md_path.read_text()
    assert text.startswith("# Controllers\n\n| controller |") and text.endswith("|\n")
    read = list(csv.DictReader(csv_path.open()))
    assert [r["controller"] for r in read] == ["ppc", "pi_force"]
    assert list(read[0]) == list(columns) and read[0]["note"] == "a|b"
