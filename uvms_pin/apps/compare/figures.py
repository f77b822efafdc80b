"""Figures of `uvms-pin compare-controllers`: force tracking and the metrics, per controller."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.results.rollout import Rollout

__all__ = ["write_comparison_figures"]


def write_comparison_figures(
    rows: list[dict[str, Any]], rollouts: dict[str, Rollout], out: Path, after_s: float
) -> list[Path]:
    """``controllers_force.png`` (|f_e - f_d| and f_x over time) and
    ``controllers_metrics.png`` (bars of the main columns)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_f, ax_e) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for name, rollout in rollouts.items():
        desired = rollout.signals["force_desired_world_N"]
        ax_f.plot(rollout.time_s, rollout.wrench_contact_world[:, 0], label=name)
        error = np.linalg.norm(rollout.wrench_contact_world[:, :3] - desired, axis=1)
        ax_e.plot(rollout.time_s, error, label=name)
    first = next(iter(rollouts.values()))
    ax_f.plot(first.time_s, first.signals["force_desired_world_N"][:, 0], "k--", label="f_d")
    ax_f.set_ylabel("f_x [N]")
    ax_e.set_ylabel("|f_e - f_d| [N]")
    ax_e.axvline(after_s, color="grey", lw=0.8)
    ax_e.set_xlabel("t [s]")
    ax_f.legend(fontsize=8)
    fig.tight_layout()
    force_path = out / "controllers_force.png"
    fig.savefig(force_path, dpi=100)
    plt.close(fig)

    columns = (
        ("force_error_rms_N", "force error RMS [N]"),
        ("force_error_peak_N", "force error peak [N]"),
        ("orientation_error_peak_rad", "orientation error peak [rad]"),
        ("vehicle_force_rms_N", "vehicle force RMS [N]"),
        ("saturated_fraction", "saturated fraction"),
    )
    fig, axes = plt.subplots(1, len(columns), figsize=(3 * len(columns), 3.2))
    names = [r["controller"] for r in rows]
    for ax, (key, label) in zip(axes, columns, strict=True):
        ax.bar(names, [r[key] for r in rows], color=["C0" if r["success"] else "C3" for r in rows])
        ax.set_title(label, fontsize=9)
        ax.tick_params(axis="x", labelrotation=45, labelsize=8)
    fig.tight_layout()
    metrics_path = out / "controllers_metrics.png"
    fig.savefig(metrics_path, dpi=100)
    plt.close(fig)
    return [force_path, metrics_path]
