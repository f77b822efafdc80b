"""The comparison's CSV and Markdown: 4 significant digits, NaN as an empty cell, the long
columns as notes per arm."""

from __future__ import annotations

import csv
import math

from uvms_pin.apps.arms.row import COLUMNS, nan_row
from uvms_pin.apps.arms.settings import CompareSettings
from uvms_pin.apps.arms.table import write_comparison


def _rows() -> list[dict]:
    ok = nan_row("reference")
    ok.update(status="ok", n_joints=4, arm_mass_kg=0.99000001, force_error_rms_N=0.123456)
    far = nan_row("so100")
    far.update(status="unreachable", reason="out of reach", dry_links="jaw")
    return [ok, far]


def test_csv_has_every_column_and_blank_nan(tmp_path):
    paths = write_comparison(_rows(), tmp_path)
    assert [p.name for p in paths] == ["comparison.csv", "comparison.md", "comparison.png"]
    with open(paths[0], newline="") as f:
        table = list(csv.DictReader(f))
    assert list(table[0]) == [key for key, _ in COLUMNS]
    assert table[0]["arm_mass_kg"] == "0.99" and table[0]["force_error_rms_N"] == "0.1235"
    assert table[0]["n_joints"] == "4" and table[1]["force_error_rms_N"] == ""
    assert table[1]["reason"] == "out of reach"


def test_markdown_table_and_notes(tmp_path):
    settings = CompareSettings(duration_s=2.0, trim=None, mount_rpy=(math.pi, 0.0, 0.0))
    write_comparison(_rows(), tmp_path, scenario="s.toml", settings=settings)
    lines = (tmp_path / "comparison.md").read_text().splitlines()
    assert lines[0] == "# Arm comparison: s.toml"
    assert lines[3] == "Duration: 2 s; mount rpy (3.1416, 0.0, 0.0) rad; trim: none."
    header = lines[5]
    assert header.startswith("| arm | joints | status |") and "why" not in header
    assert lines[7].startswith("| reference | 4 | ok | 0.99 |")
    assert lines[-2:] == [
        "- **reference** (ok): completed",
        "- **so100** (unreachable): out of reach (links with mass but no geometry, no "
        "buoyancy: jaw)",
    ]


def test_without_settings_no_settings_line(tmp_path):
    write_comparison(_rows(), tmp_path)
    lines = (tmp_path / "comparison.md").read_text().splitlines()
    assert lines[3] == "" and lines[4].startswith("| arm |")


def test_the_mount_orientation_said_is_the_comparisons_or_each_arms_own(tmp_path):
    rows = _rows()
    rows[1]["mount_rpy"] = (math.pi, 0.0, 0.0)
    alpha5 = nan_row("alpha5")
    alpha5.update(status="ok", mount_rpy=(0.0, 0.0, 0.0))
    for given, arms, said in [
        (None, rows, "mount rpy (3.1416, 0.0, 0.0) rad;"),  # one shared: as before
        (None, [*rows, alpha5], "mount rpy each arm's own [rad]: so100 (3.1416, 0.0, 0.0), "
         "alpha5 (0.0, 0.0, 0.0);"),
        ((0.0, 0.5, 0.0), [*rows, alpha5], "mount rpy (0.0, 0.5, 0.0) rad;"),
    ]:  # fmt: skip
        write_comparison(arms, tmp_path, scenario="s", settings=CompareSettings(mount_rpy=given))
        assert said in (tmp_path / "comparison.md").read_text().splitlines()[3]


def test_the_markdown_shows_the_columns_of_the_task_some_arm_has(tmp_path):
    """A contact task's rows (a force error) show the force columns and no tracking one;
    a tracking task's the tracking columns and no force one; the CSV has both."""
    write_comparison(_rows(), tmp_path)
    header = (tmp_path / "comparison.md").read_text().splitlines()[4]
    assert "| force error RMS [N] |" in header and "tracking" not in header
    tracked = nan_row("reference")
    tracked.update(status="ok", task_position_error_rms_m=7e-4, task_orientation_error_rms_rad=2e-4)
    write_comparison([tracked, _rows()[1]], tmp_path)
    header = (tmp_path / "comparison.md").read_text().splitlines()[4]
    assert "| tracking position error RMS [m] | tracking orientation error RMS [rad] |" in header
    assert "force error" not in header and "funnel" not in header
    with open(tmp_path / "comparison.csv", newline="") as f:
        assert list(next(csv.DictReader(f))) == [key for key, _ in COLUMNS]
