"""What the study report computes from the table, before any of it is drawn or written.

A run "failed" when its status is not ``ok`` (a funnel violation, a divergence or an
error). The report gives the share of runs that held with its 95 % Wilson interval, the
failure rate per parameter bin and over 2-D grids of bins, Spearman rank correlations of
the parameters with failure and with the metrics, and per-metric summaries (median, 5th
and 95th percentiles, max). Runs stopped before the force funnel's transient ended are
kept out of the "after transient" metrics (`exclude_unfinished_transients`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from uvms_pin.apps.study.bins import bins, ordered_labels
from uvms_pin.apps.study.runner import STATUSES


def failed(table: pd.DataFrame) -> pd.Series:
    """True for the runs that did not finish ok."""
    return table["status"] != "ok"


def wilson_interval(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion k / n."""
    if n == 0:
        return math.nan, math.nan
    p = k / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def rank_correlation(x: pd.Series, y: pd.Series) -> float:
    """Spearman's rank correlation over the rows where both are finite; NaN with fewer
    than 3 such rows or a constant side."""
    ok = np.isfinite(x.astype(float)) & np.isfinite(y.astype(float))
    if ok.sum() < 3 or x[ok].nunique() < 2 or y[ok].nunique() < 2:
        return math.nan
    return float(x[ok].rank().corr(y[ok].astype(float).rank()))


def exclude_unfinished_transients(table: pd.DataFrame) -> tuple[pd.DataFrame, int, float]:
    """The table with the "after transient" metrics blanked (NaN) for runs that stopped
    before the force funnel's transient ended, how many, and that transient end [s].

    A run stopped at t = 0.01 s has no "after the transient": its partial rollout's last
    funnel value is not rho_inf, so its after-transient metrics describe the transient
    itself. The transient end is the median ``transient_end_s`` of the runs that finished
    (their funnel was logged to the end); with no finished run, every stopped run is
    excluded.
    """
    columns = [c for c in table.columns if "after_transient" in c]
    if not columns or "simulated_time_s" not in table.columns:
        return table, 0, math.nan
    finished = table["status"] == "ok"
    ends = table.loc[finished, "transient_end_s"] if "transient_end_s" in table else []
    end = float(np.nanmedian(ends)) if len(ends) and np.isfinite(ends).any() else math.nan
    simulated = table["simulated_time_s"].astype(float)
    excluded = ~finished & ~(simulated >= end)  # NaN end: every stopped run
    out = table.copy()
    out.loc[excluded, columns] = math.nan
    return out, int(excluded.sum()), end


def status_rows(table: pd.DataFrame) -> list[dict[str, Any]]:
    """Runs per status (every status of `STATUSES`, in that order) and their fraction."""
    n = len(table)
    counts = table["status"].value_counts()
    return [
        {"status": s, "runs": int(counts.get(s, 0)), "fraction": counts.get(s, 0) / n}
        for s in STATUSES
    ]


def bin_failure_rates(
    table: pd.DataFrame, param: dict[str, Any]
) -> tuple[list[str], list[float], list[int]]:
    """Per bin of ``param`` (`bins`, in `ordered_labels` order): the labels, the fraction
    of the bin's runs that failed and the bin's run count."""
    labels = bins(table[param["path"]], param)
    order = ordered_labels(table[param["path"]], labels)
    not_ok = failed(table)
    rates = [not_ok[labels == b].mean() for b in order]
    counts = [int((labels == b).sum()) for b in order]
    return order, rates, counts


def violation_rate_grid(
    table: pd.DataFrame, px: dict[str, Any], py: dict[str, Any]
) -> tuple[pd.DataFrame, np.ndarray]:
    """The failure rate over the bins of ``px`` (columns) x ``py`` (rows), NaN for an
    empty cell, and the run count of every cell (an int array of the same shape)."""
    bx = bins(table[px["path"]], px)
    by = bins(table[py["path"]], py)
    ox = ordered_labels(table[px["path"]], bx)
    oy = ordered_labels(table[py["path"]], by)
    not_ok = failed(table)
    rate = np.full((len(oy), len(ox)), np.nan)
    count = np.zeros((len(oy), len(ox)), dtype=int)
    for i, b_y in enumerate(oy):
        for j, b_x in enumerate(ox):
            cell = (bx == b_x) & (by == b_y)
            count[i, j] = int(cell.sum())
            if count[i, j]:
                rate[i, j] = not_ok[cell].mean()
    return pd.DataFrame(rate, index=oy, columns=ox), count


def heatmap_pairs(
    table: pd.DataFrame, params: list[dict[str, Any]], options: dict[str, Any]
) -> list[tuple[str, str]]:
    """The study's [report] heatmaps; else the two grid parameters; else the two
    parameters most rank-correlated with failure."""
    paths = [p["path"] for p in params]
    pairs = [tuple(p) for p in options.get("heatmaps", []) if set(p) <= set(paths)]
    if pairs:
        return pairs
    grid = [p["path"] for p in params if p["grid"]]
    if len(grid) >= 2:
        return [(grid[0], grid[1])]
    numeric = [p["path"] for p in params if p["numeric"]]
    if len(numeric) < 2:
        return []
    not_ok = failed(table).astype(float)
    score = {p: abs(rank_correlation(table[p], not_ok)) for p in numeric}
    ranked = sorted(numeric, key=lambda p: -(score[p] if np.isfinite(score[p]) else -1))
    return [(ranked[0], ranked[1])]


def correlation_rows(
    table: pd.DataFrame, params: list[dict[str, Any]], metrics: list[str]
) -> list[dict[str, Any]]:
    """Per numeric parameter: its rank correlation with failure (1 = not ok) over every
    run and, over the runs that finished ok, with each metric."""
    not_ok = failed(table).astype(float)
    ok_rows = table[table["status"] == "ok"]
    rows = []
    for p in params:
        if not p["numeric"]:
            continue
        row = {"parameter": p["path"], "failure": rank_correlation(table[p["path"]], not_ok)}
        for m in metrics:
            row[m] = rank_correlation(ok_rows[p["path"]], ok_rows[m]) if len(ok_rows) else math.nan
        rows.append(row)
    return rows


def metric_rows(table: pd.DataFrame, metrics: list[str]) -> list[dict[str, Any]]:
    """Per metric, over all runs and over the runs that finished ok (the finite values;
    none: no row): median, 5th and 95th percentiles, max."""
    rows = []
    for m in metrics:
        for label, sub in (("all", table), ("ok", table[table["status"] == "ok"])):
            x = sub[m].astype(float)
            x = x[np.isfinite(x)]
            if not len(x):
                continue
            rows.append(
                {
                    "metric": m,
                    "runs": f"{label} ({len(x)})",
                    "median": float(x.median()),
                    "p5": float(x.quantile(0.05)),
                    "p95": float(x.quantile(0.95)),
                    "max": float(x.max()),
                }
            )
    return rows
