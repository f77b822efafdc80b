"""A study as a result: sweep, report, and the report's text (figures stay in out/)."""

from __future__ import annotations

import re
import time
from collections.abc import Callable

import pandas as pd
from _common import scratch, uvms_pin, write_result


def produce(
    name: str, study: str, title: str, runs: Callable[[pd.DataFrame], str] | None = None
) -> None:
    """Sweep ``study`` into out/results/<name>/, report it, write its summary; ``runs``: a
    Markdown section made from the results table (one row a run), appended after it."""
    out = scratch(name)
    start = time.perf_counter()
    uvms_pin("sweep", study, "--out", str(out), "--workers", "2", "--quiet")
    sweep_s = time.perf_counter() - start  # the whole command: start-up, runs, table
    uvms_pin("report", str(out))
    report = (out / "report.md").read_text()
    # the summary only: figures are many and large; they stay in out/results/<name>/
    report = report.split("\n## Figures")[0]
    report = re.sub(r"!\[[^\]]*\]\([^)]*\)\n?", "", report)
    report = re.sub(r"^# .*\n", "", report, count=1)
    body = (
        f"`uvms-pin sweep {study} --out out/results/{name} --workers 2` then "
        f"`uvms-pin report out/results/{name}` (figures there). The sweep command took "
        f"{sweep_s:.1f} s of wall time (start-up, runs on 2 workers, table).\n\n{report}"
    )
    if runs is not None:
        body = body.rstrip() + "\n\n" + runs(pd.read_parquet(out / "results.parquet"))
    write_result(name, title, f"python scripts/results/{name}.py", body)
