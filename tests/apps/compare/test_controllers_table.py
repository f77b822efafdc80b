"""The controllers' comparison tables (uvms_pin.apps.compare.table, .robustness): Markdown whose
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


def test_the_robustness_table_puts_each_run_in_its_controllers_row_and_its_cases_column():
    """Two controllers by two cases: each cell the force error RMS and whether the run
    held (its ``success``), or its status when it stopped or failed; a delimiter per
    column."""
    from uvms_pin.apps.compare.robustness import robustness_table

    rows = [
        {"controller": "ppc", "case": "nominal", "status": "ok", "success": True,
         "force_error_rms_N": 0.0123},
        {"controller": "ppc", "case": "heavy", "status": "ok", "success": False,
         "force_error_rms_N": 0.5},
        {"controller": "pi_force", "case": "nominal", "status": "stopped", "success": False,
         "force_error_rms_N": math.nan},
        {"controller": "pi_force", "case": "heavy", "status": "ok", "success": True,
         "force_error_rms_N": 0.25},
    ]  # fmt: skip
    lines = robustness_table(rows).splitlines()
    assert _cells(lines[0]) == ["controller", "nominal", "heavy"]
    assert _cells(lines[1]) == ["---"] * 3
    assert _cells(lines[2]) == ["ppc", "0.0123 N, holds", "0.5 N, fails"]
    assert _cells(lines[3]) == ["pi_force", "stopped", "0.25 N, holds"]
    assert len(lines) == 4
