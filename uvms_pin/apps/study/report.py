"""A study's table -> figures (PNG, matplotlib without pyplot) and ``report.md``.

Figures: metric vs parameter scatter plots coloured by status, box plots of each metric
over parameter bins, the funnel-violation rate per parameter bin, heatmaps of the
violation rate over 2-D parameter grids (grid values, or quantile / log bins of random
parameters), and the violations by component and time.
"""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import tomllib
from matplotlib.figure import Figure

from uvms_pin.apps.study.identity import STUDY_COPY
from uvms_pin.apps.study.runner import STATUSES, load_results
from uvms_pin.apps.study.spec import StudyError, column_name
from uvms_pin.results.atomic import atomic_path, write_text_atomic

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"
DEFAULT_METRICS = (
    "force_error_rms_after_transient_N",
    "funnel_margin_min_first",
    "funnel_margin_min_second",
    "commanded_vehicle_force_peak_N",
    "vehicle_saturation_fraction",
    "simulated_time_s",
)
STATUS_COLORS = {
    "ok": "tab:green",
    "FunnelViolation": "tab:red",
    "diverged": "tab:purple",
    "error": "tab:gray",
}
N_BINS = 5


def _study_info(directory: Path) -> dict[str, Any]:
    path = directory / STUDY_COPY
    if not path.is_file():
        return {}
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError:
        return {}


def _parameters(table: pd.DataFrame, info: dict[str, Any]) -> list[dict[str, Any]]:
    """The varied parameters present in the table, with how to bin and scale them."""
    entries = info.get("parameter") or [{"path": c} for c in table.columns if "." in c]
    out = []
    for entry in entries:
        path = column_name(entry.get("path"), entry.get("apply", "set"))
        if path not in table.columns:
            continue
        column = table[path]
        numeric = pd.api.types.is_numeric_dtype(column)
        log = bool(
            entry.get("distribution") == "log-uniform"
            or "logspace" in entry
            or (numeric and column.min() > 0 and column.max() / column.min() > 50)
        )
        grid = "values" in entry or "linspace" in entry or "logspace" in entry
        out.append({"path": path, "numeric": numeric, "log": log, "grid": grid})
    return out


def _bins(values: pd.Series, param: dict[str, Any]) -> pd.Series:
    """Bin labels: the value itself for grids (or few distinct values), else N_BINS
    quantile bins (log-spaced edges for log parameters)."""
    if not param["numeric"] or param["grid"] or values.nunique() <= N_BINS:
        return values.map(_fmt)
    if param["log"]:
        edges = np.geomspace(values.min(), values.max(), N_BINS + 1)
    else:
        edges = np.unique(np.quantile(values, np.linspace(0, 1, N_BINS + 1)))
    labels = [f"{_fmt(a)}-{_fmt(b)}" for a, b in itertools.pairwise(edges)]
    cut = pd.cut(values, edges, labels=labels, include_lowest=True)
    return cut.astype(str)


def _fmt(x: Any) -> str:
    if isinstance(x, float | np.floating):
        return f"{x:.3g}"
    return str(x)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_")


def _failed(table: pd.DataFrame) -> pd.Series:
    return table["status"] != "ok"


def _save(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format=path.suffix[1:])
    return path


def _grid_axes(n: int, width: float = 4.0, height: float = 3.2):
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(width * cols, height * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig, axes[:n]


# ---- figures -------------------------------------------------------------------------------


def scatter_figure(table, params, metric, path: Path) -> Path:
    """``metric`` against every parameter, one point per run, coloured by status."""
    fig, axes = _grid_axes(len(params))
    for ax, p in zip(axes, params, strict=True):
        for status, color in STATUS_COLORS.items():
            rows = table[table["status"] == status]
            if len(rows) and p["numeric"]:
                ax.scatter(rows[p["path"]], rows[metric], s=10, color=color, label=status)
            elif len(rows):
                ax.scatter(rows[p["path"]].astype(str), rows[metric], s=10, color=color)
        if p["log"]:
            ax.set_xscale("log")
        ax.set_xlabel(p["path"])
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="best", fontsize="small")
    fig.suptitle(f"{metric} vs parameters (colour: status)")
    return _save(fig, path)


def box_figure(table, params, metric, path: Path) -> Path:
    """``metric`` over bins of every parameter (runs with a finite value of it)."""
    fig, axes = _grid_axes(len(params))
    finite = table[np.isfinite(table[metric].astype(float))]
    for ax, p in zip(axes, params, strict=True):
        labels = _bins(finite[p["path"]], p)
        order = _ordered_labels(finite[p["path"]], labels)
        data = [finite.loc[labels == b, metric].to_numpy(float) for b in order]
        if any(len(d) for d in data):
            ax.boxplot(data, tick_labels=order, showfliers=True)
        ax.tick_params(axis="x", labelrotation=30, labelsize="small")
        ax.set_xlabel(p["path"])
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{metric} per parameter bin")
    return _save(fig, path)


def _ordered_labels(values: pd.Series, labels: pd.Series) -> list[str]:
    """Bin labels in the order of their smallest parameter value."""
    first = {}
    for value, label in zip(values, labels, strict=True):
        key = value if isinstance(value, int | float) else str(value)
        if label not in first or key < first[label]:
            first[label] = key
    return sorted(first, key=lambda b: first[b])


def violation_rate_figure(table, params, path: Path) -> Path:
    """Fraction of runs that did not finish ok, per parameter bin (n above each bar)."""
    fig, axes = _grid_axes(len(params))
    failed = _failed(table)
    for ax, p in zip(axes, params, strict=True):
        labels = _bins(table[p["path"]], p)
        order = _ordered_labels(table[p["path"]], labels)
        rates = [failed[labels == b].mean() for b in order]
        counts = [int((labels == b).sum()) for b in order]
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


def heatmap_figure(table, px, py, path: Path) -> tuple[Path, pd.DataFrame]:
    """Violation rate over the 2-D grid (px, py): cell colour = rate, text = rate (n)."""
    bx = _bins(table[px["path"]], px)
    by = _bins(table[py["path"]], py)
    ox = _ordered_labels(table[px["path"]], bx)
    oy = _ordered_labels(table[py["path"]], by)
    failed = _failed(table)
    rate = np.full((len(oy), len(ox)), np.nan)
    count = np.zeros((len(oy), len(ox)), dtype=int)
    for i, b_y in enumerate(oy):
        for j, b_x in enumerate(ox):
            cell = (bx == b_x) & (by == b_y)
            count[i, j] = int(cell.sum())
            if count[i, j]:
                rate[i, j] = failed[cell].mean()
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
    frame = pd.DataFrame(rate, index=oy, columns=ox)
    return _save(fig, path), frame


def violations_figure(table, path: Path) -> Path | None:
    """Which component broke its funnel, and when."""
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


# ---- the Markdown summary ------------------------------------------------------------------


def wilson_interval(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion k / n."""
    if n == 0:
        return math.nan, math.nan
    p = k / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def _md_table(frame: pd.DataFrame, floatfmt: str = "{:.3g}") -> str:
    cols = [str(c) for c in frame.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, row in frame.iterrows():
        cells = [
            ("n/a" if math.isnan(x) else floatfmt.format(x)) if isinstance(x, float) else str(x)
            for x in row
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _rank_correlation(x: pd.Series, y: pd.Series) -> float:
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


def write_report(directory: str | Path) -> list[Path]:
    """Write ``report.md`` and its figures (``figures/*.png``) into a study directory.

    Returns the paths, ``report.md`` first. Raises `StudyError` if the directory holds no
    study table.
    """
    directory = Path(directory)
    table = load_results(directory)
    if not len(table):
        raise StudyError(f"{directory}: the study table is empty (no run finished yet)")
    table, excluded, transient_end = exclude_unfinished_transients(table)
    info = _study_info(directory)
    head = info.get("study", {})
    options = info.get("report", {})
    params = _parameters(table, info)
    metrics = [m for m in (options.get("metrics") or DEFAULT_METRICS) if m in table.columns]
    figures_dir = directory / FIGURES_DIR
    figures_dir.mkdir(exist_ok=True)
    figures: list[Path] = []
    heatmaps: list[tuple[str, str, pd.DataFrame, Path]] = []
    if params:
        for metric in metrics:
            figures.append(
                scatter_figure(table, params, metric, figures_dir / f"scatter_{metric}.png")
            )
            figures.append(box_figure(table, params, metric, figures_dir / f"box_{metric}.png"))
        figures.append(violation_rate_figure(table, params, figures_dir / "violation_rate.png"))
        by_path = {p["path"]: p for p in params}
        for a, b in _heatmap_pairs(table, params, options):
            name = f"heatmap_{_slug(a)}__{_slug(b)}.png"
            path, frame = heatmap_figure(table, by_path[a], by_path[b], figures_dir / name)
            figures.append(path)
            heatmaps.append((a, b, frame, path))
    violations = violations_figure(table, figures_dir / "violations.png")
    if violations is not None:
        figures.append(violations)

    text = _markdown(table, head, params, metrics, heatmaps, figures, directory)
    text = text.replace(_EXCLUSION_MARK, _exclusion_note(excluded, transient_end))
    report = directory / REPORT_FILE
    write_text_atomic(report, text)
    return [report, *figures]


_EXCLUSION_MARK = "<!-- excluded runs -->"


def _exclusion_note(excluded: int, transient_end_s: float) -> str:
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


def _heatmap_pairs(table, params, options) -> list[tuple[str, str]]:
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
    failed = _failed(table).astype(float)
    score = {p: abs(_rank_correlation(table[p], failed)) for p in numeric}
    ranked = sorted(numeric, key=lambda p: -(score[p] if np.isfinite(score[p]) else -1))
    return [(ranked[0], ranked[1])]


def _markdown(table, head, params, metrics, heatmaps, figures, directory) -> str:
    n = len(table)
    counts = table["status"].value_counts()
    ok = int(counts.get("ok", 0))
    lo, hi = wilson_interval(ok, n)
    lines = [
        f"# Study report: {head.get('name', directory.name)}",
        "",
        head.get("description", ""),
        "",
        f"- base scenario: `{head.get('base', '?')}`; master seed {head.get('seed', '?')}",
        f"- runs recorded: {n}",
        f"- base scenario file hash(es): {', '.join(sorted(set(table.get('base_sha256', pd.Series(['?'])).dropna().astype(str))))}",
        "",
        "## Outcome",
        "",
        f"The funnels held (status ok) in **{ok} of {n} runs ({ok / n:.1%}; 95 % CI "
        f"{lo:.1%} - {hi:.1%})**.",
        "",
    ]
    status_rows = [
        {"status": s, "runs": int(counts.get(s, 0)), "fraction": counts.get(s, 0) / n}
        for s in STATUSES
    ]
    lines += [_md_table(pd.DataFrame(status_rows)), ""]

    v = table[table["status"] == "FunnelViolation"]
    if len(v):
        comp = (v["violation_level"] + ": " + v["violation_component"]).value_counts()
        t = v["violation_time_s"]
        lines += [
            "### Where the funnels break",
            "",
            f"Time of the violation: median {t.median():.3g} s, 10-90 % {t.quantile(0.1):.3g} - "
            f"{t.quantile(0.9):.3g} s; before 1 s in {(t < 1).mean():.0%} of the violations.",
            "",
            _md_table(pd.DataFrame({"first funnel to break": comp.index, "runs": comp.to_numpy()})),
            "",
        ]
    errors = table[table["status"].isin(["error", "diverged"])]
    if len(errors):
        lines += ["### Errors and divergences (first 5)", ""]
        for _, row in errors.head(5).iterrows():
            lines.append(f"- run `{row['run_id']}` ({row['status']}): {row['error']}")
        lines.append("")

    if params:
        failed = _failed(table).astype(float)
        lines += [
            "## Parameters",
            "",
            "Spearman rank correlation of each parameter with failure (1 = not ok) and, over "
            "the runs that finished ok, with the metrics.",
            "",
        ]
        ok_rows = table[table["status"] == "ok"]
        corr_rows = []
        for p in params:
            if not p["numeric"]:
                continue
            row = {"parameter": p["path"], "failure": _rank_correlation(table[p["path"]], failed)}
            for m in metrics:
                row[m] = (
                    _rank_correlation(ok_rows[p["path"]], ok_rows[m]) if len(ok_rows) else math.nan
                )
            corr_rows.append(row)
        if corr_rows:
            lines += [_md_table(pd.DataFrame(corr_rows), "{:+.2f}"), ""]
        lines += ["Failure rate per parameter bin (runs in the bin):", ""]
        for p in params:
            labels = _bins(table[p["path"]], p)
            order = _ordered_labels(table[p["path"]], labels)
            cells = [
                f"{b}: {failed[labels == b].mean():.0%} ({int((labels == b).sum())})" for b in order
            ]
            lines.append(f"- `{p['path']}`: " + "; ".join(cells))
        lines.append("")
    for a, b, frame, path in heatmaps:
        lines += [
            f"### Violation rate over `{a}` (columns) x `{b}` (rows)",
            "",
            _md_table(frame.reset_index(names=b), "{:.2f}"),
            "",
            f"![heatmap]({path.relative_to(directory)})",
            "",
        ]

    present = [m for m in metrics if m in table.columns]
    if present:
        lines += [
            "## Metrics",
            "",
            "Over all runs (a stopped run's metrics cover its partial rollout) and over the runs that finished ok.",
            _EXCLUSION_MARK,
            "",
        ]
        rows = []
        for m in present:
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
        lines += [_md_table(pd.DataFrame(rows)), ""]
    wall = table["run_wall_time_s"].astype(float)
    lines += [
        f"Wall time per run: median {wall.median():.3g} s, total {wall.sum() / 3600:.3g} CPU-hours.",
        "",
        "## Figures",
        "",
    ]
    for path in figures:
        lines.append(f"![{path.stem}]({path.relative_to(directory)})")
    lines.append("")
    return "\n".join(lines)
