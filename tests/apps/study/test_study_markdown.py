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
