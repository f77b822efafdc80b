"""Figures of `uvms-pin compare-controllers`: force tracking and the metrics, per controller."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.results.figures.standard import new_figure, save_figure
from uvms_pin.results.rollout import Rollout

__all__ = ["force_figure", "metrics_figure", "write_comparison_figures"]


def write_comparison_figures(
    rows: list[dict[str, Any]], rollouts: dict[str, Rollout], out: Path, after_s: float
) -> list[Path]:
    """``controllers_force.png`` (`force_figure`) and ``controllers_metrics.png``
    (`metrics_figure`), each written whole or not at all; none when no controller ran."""
    if not rollouts:
        return []
    scenario = next(iter(rollouts.values())).metadata.get("scenario", "")
    return [
        save_figure(force_figure(rollouts, after_s), out / "controllers_force.png"),
        save_figure(metrics_figure(rows, scenario), out / "controllers_metrics.png"),
    ]


def force_figure(rollouts: dict[str, Rollout], after_s: float) -> Figure:
    """f_x and |f_e - f_d| over time, one curve per controller, the after-transient window's
    start marked and named."""
    fig, (ax_f, ax_e) = new_figure(2, 1, figsize=(8, 6), sharex=True)
    for name, rollout in rollouts.items():
        desired = rollout.signals["force_desired_world_N"]
        ax_f.plot(rollout.time_s, rollout.wrench_contact_world[:, 0], label=name)
        error = np.linalg.norm(rollout.wrench_contact_world[:, :3] - desired, axis=1)
        ax_e.plot(rollout.time_s, error, label=name)
    first = next(iter(rollouts.values()))
    ax_f.plot(first.time_s, first.signals["force_desired_world_N"][:, 0], "k--", label="f_d")
    ax_f.set_ylabel("f_x [N]")
    ax_e.set_ylabel("|f_e - f_d| [N]")
    window = ax_e.axvline(
        after_s, color="grey", lw=0.8, ls="--",
        label=f"after-transient window from t = {after_s:g} s (errors measured there)",
    )  # fmt: skip
    ax_e.set_xlabel("t [s]")
    ax_f.legend(fontsize=8)
    ax_e.legend(handles=[window], fontsize=8, loc="upper right")  # the colours: above
    for ax in (ax_f, ax_e):
        ax.grid(True, alpha=0.3)
    scenario = first.metadata.get("scenario", "")
    fig.suptitle(f"{scenario}: contact force f_x and force error, per controller")
    return fig


def metrics_figure(rows: list[dict[str, Any]], scenario: str) -> Figure:
    """Bars of the main metrics, one per controller (red: it fails the task)."""
    columns = (
        ("force_error_rms_N", "force error RMS [N]"),
        ("force_error_peak_N", "force error peak [N]"),
        ("orientation_error_peak_rad", "orientation error peak [rad]"),
        ("vehicle_force_rms_N", "vehicle force RMS [N]"),
        ("saturated_fraction", "saturated fraction"),
    )
    fig, axes = new_figure(1, len(columns), figsize=(3 * len(columns), 3.2))
    names = [r["controller"] for r in rows]
    for ax, (key, label) in zip(axes, columns, strict=True):
        ax.bar(names, [r[key] for r in rows], color=["C0" if r["success"] else "C3" for r in rows])
        ax.set_title(label, fontsize=9)
        ax.tick_params(axis="x", labelrotation=45, labelsize=8)
    fig.suptitle(f"{scenario}: metrics per controller (red: fails the task)", fontsize=10)
    return fig
