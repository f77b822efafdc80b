"""``comparison.png``: six bar charts of the arms side by side.

The task's two (a contact task's force error RMS and minimum funnel margins, 1st / 2nd
level; a tracking task's position and orientation error RMS), peak vehicle force, peak
joint torque, net buoyancy before / after trim, system mass. Bars are green for a completed
task, gray for an unreachable start point, red for a failure; the buoyancy panel's are blue
(before trim) and orange (after).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from uvms_pin.apps.arms.row import has_values

#: (row key, title) of the panels, row by row; a tracking task's first two `TRACKING_PANELS`
PANELS = (
    ("force_error_rms_N", "force error RMS [N]"),
    ("funnel_margin_min_first", "min funnel margin (1st / 2nd level)"),
    ("vehicle_force_peak_N", "peak vehicle force [N]"),
    ("joint_torque_peak_Nm", "peak joint torque [N m]"),
    ("net_buoyancy_before_N", "net buoyancy before / after trim [N]"),
    ("system_mass_kg", "system mass [kg]"),
)
TRACKING_PANELS = (
    ("task_position_error_rms_m", "tracking position error RMS [m]"),
    ("task_orientation_error_rms_rad", "tracking orientation error RMS [rad]"),
)


def panels(rows: list[dict]) -> tuple[tuple[str, str], ...]:
    """`PANELS`, the first two a tracking task's when no arm has a force error and some
    has a tracking error."""
    tracking = not has_values(rows, "force_error_rms_N") and any(
        has_values(rows, key) for key, _ in TRACKING_PANELS
    )
    return (*TRACKING_PANELS, *PANELS[2:]) if tracking else PANELS


def _status_color(status: str) -> str:
    if status == "ok":
        return "tab:green"
    return "tab:gray" if status == "unreachable" else "tab:red"


def _values(rows: list[dict], key: str) -> np.ndarray:
    return np.array([float(r.get(key, math.nan)) for r in rows])


def _bars(ax, rows: list[dict], key: str, colors: list[str]) -> None:
    """One panel's bars: two per arm for the funnel margins and the buoyancy, else one."""
    x = np.arange(len(rows))
    if key == "funnel_margin_min_first":
        ax.bar(x - 0.2, _values(rows, key), 0.4, color=colors, label="1st")
        second = _values(rows, "funnel_margin_min_second")
        ax.bar(x + 0.2, second, 0.4, color=colors, alpha=0.5, label="2nd")
        ax.axhline(0.0, color="k", lw=0.8)
        ax.legend(fontsize=8)
    elif key == "net_buoyancy_before_N":
        ax.bar(x - 0.2, _values(rows, key), 0.4, color="tab:blue", label="before")
        after = _values(rows, "net_buoyancy_after_N")
        ax.bar(x + 0.2, after, 0.4, color="tab:orange", label="after")
        ax.axhline(0.0, color="k", lw=0.8)
        ax.legend(fontsize=8)
    else:
        ax.bar(x, _values(rows, key), color=colors)


def comparison_figure(rows: list[dict], out: Path) -> Path:
    """Draw `PANELS` for ``rows`` into ``out/comparison.png`` (atomically); its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from uvms_pin.results.figures.standard import save_figure

    names = [r["arm"] for r in rows]
    colors = [_status_color(r["status"]) for r in rows]
    x = np.arange(len(rows))
    fig, axes = plt.subplots(2, 3, figsize=(14, 7.5))
    for ax, (key, title) in zip(axes.flat, panels(rows), strict=True):
        _bars(ax, rows, key, colors)
        ax.set_title(title, fontsize=10)
        ax.set_xticks(x, names, rotation=30, ha="right", fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle("Arms compared (green: task completed, red: failed, gray: unreachable)")
    path = save_figure(fig, out / "comparison.png", dpi=110)
    plt.close(fig)
    return path
