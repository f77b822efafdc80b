"""The report's Markdown: its tables and the sentence on the runs left out."""

from __future__ import annotations

import math

import pandas as pd

from uvms_pin.apps.study.markdown import exclusion_note, md_table


def test_md_table_formats_floats_and_marks_nan():
    frame = pd.DataFrame({"name": ["a", "b"], "x": [0.123456, math.nan], "n": [1, 2]})
    assert md_table(frame).splitlines() == [
        "| name | x | n |",
        "|---|---|---|",
        "| a | 0.123 | 1 |",
        "| b | n/a | 2 |",
    ]
    assert md_table(frame[["x"]], "{:+.2f}").splitlines()[2] == "| +0.12 |"


def test_exclusion_note():
    assert exclusion_note(0, 5.0) == ""
    assert "2 run(s) stopped before the force funnel's transient ended (t = 5.9 s" in (
        exclusion_note(2, 5.9)
    )
    assert "no run finished to say when" in exclusion_note(1, math.nan)


def test_the_report_says_where_the_funnels_broke_and_lists_the_errors(tmp_path):
    """Of eight runs: three ok, three funnel violations (the first level's x twice, the
    second level's joint once, at 0.5, 2 and 4 s), one error and one divergence: the
    report counts the funnels that broke first and when, and lists the error and the
    divergence with their messages, not the violations; without failures neither section."""
    from uvms_pin.apps.study.markdown import report_markdown

    table = pd.DataFrame(
        {
            "run_id": [f"r{k}" for k in range(8)],
            "status": ["ok"] * 3 + ["FunnelViolation"] * 3 + ["error", "diverged"],
            "violation_level": [None] * 3 + ["first", "first", "second"] + [None] * 2,
            "violation_component": [None] * 3 + ["x", "x", "joint_2"] + [None] * 2,
            "violation_time_s": [math.nan] * 3 + [0.5, 2.0, 4.0] + [math.nan] * 2,
            "error": [""] * 6 + ["bad gain", "non-finite state at t = 1 s"],
            "run_wall_time_s": [1.0] * 8,
        }
    )
    head = {"name": "s", "base": "b.toml", "seed": 1}
    text = report_markdown(table, head, [], [], [], [], tmp_path)
    breaks = text[text.index("### Where the funnels break") :]
    assert "median 2 s" in breaks and "before 1 s in 33% of the violations" in breaks
    assert "| first: x | 2 |" in breaks and "| second: joint_2 | 1 |" in breaks
    errors = text[text.index("### Errors and divergences") :].split("\n\n")[1].splitlines()
    assert errors == [
        "- run `r6` (error): bad gain",
        "- run `r7` (diverged): non-finite state at t = 1 s",
    ]
    calm = report_markdown(table.iloc[:3], head, [], [], [], [], tmp_path)
    assert "Where the funnels break" not in calm and "Errors and divergences" not in calm
