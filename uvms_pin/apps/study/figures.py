"""The study report's figures (PNG, matplotlib without pyplot).

Metric vs parameter scatter plots coloured by status, box plots of each metric over
parameter bins, the funnel-violation rate per parameter bin, heatmaps of the violation
rate over 2-D parameter grids (grid values, or quantile / log bins of random parameters),
and the violations by component and time.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

from uvms_pin.apps.study.bins import bins, ordered_labels
from uvms_pin.apps.study.statistics import bin_failure_rates, heatmap_pairs, violation_rate_grid
from uvms_pin.results.figures.standard import save_figure

STATUS_COLORS = {
    "ok": "tab:green",
    "FunnelViolation": "tab:red",
    "diverged": "tab:purple",
    "error": "tab:gray",
}


class Heatmap(NamedTuple):
    """A heatmap the report shows: ``x`` (columns) and ``y`` (rows) parameter paths, the
    violation rate per cell (`violation_rate_grid`) and the figure's path."""

    x: str
    y: str
    rate: pd.DataFrame
    path: Path


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_")


def _save(fig: Figure, path: Path) -> Path:
    return save_figure(fig, path, dpi=110)


def _grid_axes(n: int, width: float = 4.0, height: float = 3.2):
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(width * cols, height * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig, axes[:n]


def write_figures(
    table: pd.DataFrame,
    params: list[dict[str, Any]],
    metrics: list[str],
    options: dict[str, Any],
    figures_dir: Path,
) -> tuple[list[Path], list[Heatmap]]:
    """Every figure of the report into ``figures_dir``: the paths, and the heatmaps.

    With parameters: per metric a scatter and a box figure, the violation rate per bin
    and the heatmaps of `heatmap_pairs` (``options``: the study's [report] table); with
    funnel violations, the violations figure.
    """
    figures: list[Path] = []
    heatmaps: list[Heatmap] = []
    if params:
        for metric in metrics:
            figures.append(
                scatter_figure(table, params, metric, figures_dir / f"scatter_{_slug(metric)}.png")
            )
            figures.append(
                box_figure(table, params, metric, figures_dir / f"box_{_slug(metric)}.png")
            )
        figures.append(violation_rate_figure(table, params, figures_dir / "violation_rate.png"))
        by_path = {p["path"]: p for p in params}
        for a, b in heatmap_pairs(table, params, options):
            name = f"heatmap_{_slug(a)}__{_slug(b)}.png"
            path, frame = heatmap_figure(table, by_path[a], by_path[b], figures_dir / name)
            figures.append(path)
            heatmaps.append(Heatmap(a, b, frame, path))
    violations = violations_figure(table, figures_dir / "violations.png")
    if violations is not None:
        figures.append(violations)
    return figures, heatmaps


def scatter_figure(
    table: pd.DataFrame, params: list[dict[str, Any]], metric: str, path: Path
) -> Path:
    """``metric`` against every parameter, one point per run, coloured by status."""
    fig, axes = _grid_axes(len(params))
    for ax, p in zip(axes, params, strict=True):
        for status, color in STATUS_COLORS.items():
            rows = table[table["status"] == status]
            # a text axis cannot take the NaN a stopped run's metric may hold
            rows = rows[np.isfinite(rows[metric].astype(float))]
            if len(rows) and p["numeric"]:
                ax.scatter(rows[p["path"]], rows[metric], s=10, color=color, label=status)
            elif len(rows):
                ax.scatter(
                    rows[p["path"]].astype(str), rows[metric], s=10, color=color, label=status
                )
        if p["log"]:
            ax.set_xscale("log")
            _log_ticks(ax, table[p["path"]])
        ax.set_xlabel(p["path"])
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(loc="best", fontsize="small")
    else:  # every run's value is NaN (each stopped before the metric's window): say so
        axes[0].text(0.5, 0.5, "no run has a value", ha="center", transform=axes[0].transAxes)
    fig.suptitle(f"{metric} vs parameters (colour: status)")
    return _save(fig, path)


def _log_ticks(ax, values: pd.Series) -> None:
    """Readable ticks on a log axis: matplotlib's default minor labels overprint on a
    narrow panel; a range of about a decade gets 2 and 5 times the powers of ten, wider
    ones the powers alone."""
    if values.max() < 30.0 * values.min():
        ax.xaxis.set_minor_locator(LogLocator(base=10.0, subs=(2.0, 5.0)))
        ax.xaxis.set_minor_formatter(FormatStrFormatter("%g"))
    else:
        ax.xaxis.set_minor_formatter(NullFormatter())


def box_figure(table: pd.DataFrame, params: list[dict[str, Any]], metric: str, path: Path) -> Path:
    """``metric`` over bins of every parameter (runs with a finite value of it)."""
    fig, axes = _grid_axes(len(params))
    finite = table[np.isfinite(table[metric].astype(float))]
    for ax, p in zip(axes, params, strict=True):
        labels = bins(finite[p["path"]], p)
        order = ordered_labels(finite[p["path"]], labels)
        data = [finite.loc[labels == b, metric].to_numpy(float) for b in order]
        if any(len(d) for d in data):
            ax.boxplot(data, tick_labels=order, showfliers=True)
        ax.tick_params(axis="x", labelrotation=30, labelsize="small")
        ax.set_xlabel(p["path"])
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{metric} per parameter bin")
    return _save(fig, path)


def violation_rate_figure(table: pd.DataFrame, params: list[dict[str, Any]], path: Path) -> Path:
    """Fraction of runs that did not finish ok, per parameter bin (n above each bar)."""
    fig, axes = _grid_axes(len(params))
    for ax, p in zip(axes, params, strict=True):
        order, rates, counts = bin_failure_rates(table, p)
        x = np.arange(len(order))
        ax.bar(x, rates, color="tab:red", alpha=0.7)
        for xi, r, n in zip(x, rates, counts, strict=True):
            ax.text(xi, r, f"n={n}", ha="center", va="bottom", fontsize="x-small")
        ax.set_xticks(x, order, rotation=30, fontsize="small")
        ax.set_ylim(0, 1.1)
        ax.set_xlabel(p["path"])
        ax.set_ylabel("not ok (fraction)")
        ax.grid(True, axis="y", alpha=0.3)
    fig.suptitle("funnel violation / failure rate per parameter bin")
    return _save(fig, path)


def heatmap_figure(
    table: pd.DataFrame, px: dict[str, Any], py: dict[str, Any], path: Path
) -> tuple[Path, pd.DataFrame]:
    """Violation rate over the 2-D grid (px, py): cell colour = rate, text = rate (n).

    Returns the figure's path and the rate (`violation_rate_grid`)."""
    frame, count = violation_rate_grid(table, px, py)
    rate = frame.to_numpy()
    ox, oy = list(frame.columns), list(frame.index)
    fig = Figure(figsize=(1.3 * len(ox) + 3, 0.9 * len(oy) + 2.5))
    ax = fig.subplots()
    image = ax.imshow(rate, origin="lower", cmap="Reds", vmin=0, vmax=1, aspect="auto")
    for i in range(len(oy)):
        for j in range(len(ox)):
            text = "-" if not count[i, j] else f"{rate[i, j]:.2f}\n({count[i, j]})"
            ax.text(j, i, text, ha="center", va="center", fontsize="small")
    ax.set_xticks(range(len(ox)), ox, rotation=30, fontsize="small")
    ax.set_yticks(range(len(oy)), oy, fontsize="small")
    ax.set_xlabel(px["path"])
    ax.set_ylabel(py["path"])
    fig.colorbar(image, ax=ax, label="funnel violation / failure rate")
    ax.set_title("violation rate (runs per cell)")
    return _save(fig, path), frame


def violations_figure(table: pd.DataFrame, path: Path) -> Path | None:
    """Which component broke its funnel, and when (None: no funnel violation)."""
    v = table[table["status"] == "FunnelViolation"]
    if not len(v):
        return None
    fig = Figure(figsize=(11, 4))
    ax_c, ax_t = fig.subplots(1, 2)
    names = (v["violation_level"] + ": " + v["violation_component"]).value_counts()
    ax_c.barh(names.index[::-1], names.to_numpy()[::-1], color="tab:red", alpha=0.7)
    ax_c.set_xlabel("runs")
    ax_c.set_title("first funnel to break")
    ax_t.hist(v["violation_time_s"], bins=30, color="tab:red", alpha=0.7)
    ax_t.set_xlabel("time of the violation [s]")
    ax_t.set_ylabel("runs")
    ax_t.set_title("when")
    return _save(fig, path)
