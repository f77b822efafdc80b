"""The study report's Markdown (``report.md``), one function per section.

Sections: the header (study, base scenario, runs), the outcome (the share of runs ok, run
to their end with every funnel held, and its Wilson interval; where and when the funnels
broke; the first errors), the parameters (rank correlations, failure rate per bin), the heatmaps, the
metrics and the figures. Numbers come from `statistics`; this module only writes them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from uvms_pin.apps.study.figures import Heatmap
from uvms_pin.apps.study.statistics import (
    bin_failure_rates,
    correlation_rows,
    metric_rows,
    status_rows,
    wilson_interval,
)

#: Where the metrics section says which runs were left out (`exclusion_note`).
EXCLUSION_MARK = "<!-- excluded runs -->"


def md_table(frame: pd.DataFrame, floatfmt: str = "{:.3g}") -> str:
    """``frame`` as a Markdown table: floats with ``floatfmt`` ("n/a" for NaN), anything
    else as ``str``."""
    cols = [str(c) for c in frame.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, row in frame.iterrows():
        cells = [
            ("n/a" if math.isnan(x) else floatfmt.format(x)) if isinstance(x, float) else str(x)
            for x in row
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def report_markdown(
    table: pd.DataFrame,
    head: dict[str, Any],
    params: list[dict[str, Any]],
    metrics: list[str],
    heatmaps: list[Heatmap],
    figures: list[Path],
    directory: Path,
) -> str:
    """The whole report; `EXCLUSION_MARK` stands where `exclusion_note` goes.

    ``head``: the study file's [study] table; figure paths are written relative to
    ``directory``.
    """
    lines = _header(table, head, directory)
    lines += _outcome(table)
    lines += _violations(table)
    lines += _errors(table)
    lines += _parameters(table, params, metrics)
    lines += _heatmaps(heatmaps, directory)
    lines += _metrics(table, metrics)
    lines += _wall_time_and_figures(table, figures, directory)
    return "\n".join(lines)


def exclusion_note(excluded: int, transient_end_s: float) -> str:
    """The sentence saying how many runs stopped before the transient ended ("" if none)."""
    if not excluded:
        return ""
    when = (
        f"before the force funnel's transient ended (t = {transient_end_s:.3g} s, the median "
        "over the finished runs)"
        if math.isfinite(transient_end_s)
        else "and no run finished to say when the transient ends"
    )
    return (
        f"\n{excluded} run(s) stopped {when}: they are excluded from the after-transient "
        "metrics, here and in the figures."
    )


def _header(table: pd.DataFrame, head: dict[str, Any], directory: Path) -> list[str]:
    return [
        f"# Study report: {head.get('name', directory.name)}",
        "",
        head.get("description", ""),
        "",
        f"- base scenario: `{head.get('base', '?')}`; master seed {head.get('seed', '?')}",
        f"- runs recorded: {len(table)}",
        f"- base scenario file hash(es): {', '.join(sorted(set(table.get('base_sha256', pd.Series(['?'])).dropna().astype(str))))}",
        "",
    ]


def _outcome(table: pd.DataFrame) -> list[str]:
    n = len(table)
    ok = int(table["status"].value_counts().get("ok", 0))
    lo, hi = wilson_interval(ok, n)
    return [
        "## Outcome",
        "",
        f"Status ok (the run reached its end; under a prescribed-performance controller, "
        f"with every funnel held) in **{ok} of {n} runs ({ok / n:.1%}; 95 % CI "
        f"{lo:.1%} - {hi:.1%})**.",
        "",
        md_table(pd.DataFrame(status_rows(table))),
        "",
    ]


def _violations(table: pd.DataFrame) -> list[str]:
    """Which funnel broke first and when ([] without funnel violations)."""
    v = table[table["status"] == "FunnelViolation"]
    if not len(v):
        return []
    comp = (v["violation_level"] + ": " + v["violation_component"]).value_counts()
    t = v["violation_time_s"]
    return [
        "### Where the funnels break",
        "",
        f"Time of the violation: median {t.median():.3g} s, 10-90 % {t.quantile(0.1):.3g} - "
        f"{t.quantile(0.9):.3g} s; before 1 s in {(t < 1).mean():.0%} of the violations.",
        "",
        md_table(pd.DataFrame({"first funnel to break": comp.index, "runs": comp.to_numpy()})),
        "",
    ]


def _errors(table: pd.DataFrame) -> list[str]:
    """The first five errors and divergences, with their messages ([] if none)."""
    errors = table[table["status"].isin(["error", "diverged"])]
    if not len(errors):
        return []
    lines = ["### Errors and divergences (first 5)", ""]
    for _, row in errors.head(5).iterrows():
        lines.append(f"- run `{row['run_id']}` ({row['status']}): {row['error']}")
    lines.append("")
    return lines


def _parameters(table: pd.DataFrame, params: list[dict[str, Any]], metrics: list[str]) -> list[str]:
    """Rank correlations and the failure rate per bin ([] without parameters)."""
    if not params:
        return []
    lines = [
        "## Parameters",
        "",
        "Spearman rank correlation of each parameter with failure (1 = not ok) and, over "
        "the runs that finished ok, with the metrics.",
        "",
    ]
    corr_rows = correlation_rows(table, params, metrics)
    if corr_rows:
        lines += [md_table(pd.DataFrame(corr_rows), "{:+.2f}"), ""]
    lines += ["Failure rate per parameter bin (runs in the bin):", ""]
    for p in params:
        order, rates, counts = bin_failure_rates(table, p)
        cells = [f"{b}: {r:.0%} ({n})" for b, r, n in zip(order, rates, counts, strict=True)]
        lines.append(f"- `{p['path']}`: " + "; ".join(cells))
    lines.append("")
    return lines


def _heatmaps(heatmaps: list[Heatmap], directory: Path) -> list[str]:
    lines = []
    for a, b, frame, path in heatmaps:
        lines += [
            f"### Violation rate over `{a}` (columns) x `{b}` (rows)",
            "",
            md_table(frame.reset_index(names=b), "{:.2f}"),
            "",
            f"![heatmap]({path.relative_to(directory)})",
            "",
        ]
    return lines


def _metrics(table: pd.DataFrame, metrics: list[str]) -> list[str]:
    """The metric summaries ([] if none of ``metrics`` is a column)."""
    present = [m for m in metrics if m in table.columns]
    if not present:
        return []
    return [
        "## Metrics",
        "",
        "Over all runs (a stopped run's metrics cover its partial rollout) and over the runs that finished ok.",
        EXCLUSION_MARK,
        "",
        md_table(pd.DataFrame(metric_rows(table, present))),
        "",
    ]


def _wall_time_and_figures(table: pd.DataFrame, figures: list[Path], directory: Path) -> list[str]:
    wall = table["run_wall_time_s"].astype(float)
    lines = [
        f"Wall time per run: median {wall.median():.3g} s, total {wall.sum() / 3600:.3g} CPU-hours.",
        "",
        "## Figures",
        "",
    ]
    for path in figures:
        lines.append(f"![{path.stem}]({path.relative_to(directory)})")
    lines.append("")
    return lines
