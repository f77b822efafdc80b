"""`compare-controllers` on a tracking task (a scenario with a ``[task]``): the row of one
controller from its rollout's task metrics (`uvms_pin.results.task_metrics`), the table and
the figure of the errors over time.

Success: the run reached its end, every arm joint stayed inside its limits, and the
position error was within the task's ``settle_tolerance_m`` at the end (``task_settled``).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.results.metrics import PAST_LIMIT_RAD, compute_metrics
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.actuation import Actuation

__all__ = ["TRACKING_COLUMNS", "tracking_row", "write_tracking_figure"]

TRACKING_COLUMNS = (
    "controller",
    "status",
    "success",
    "reason",
    "task_position_error_rms_m",
    "task_position_error_max_m",
    "task_orientation_error_rms_rad",
    "task_orientation_error_max_rad",
    "task_settling_time_s",
    "task_path_length_m",
    "task_actuation_energy_J",
    "saturated_fraction",
    "joint_limit_excess_max_rad",
)


def tracking_row(
    name: str, rollout: Rollout, actuation: Actuation, stopped: str = ""
) -> dict[str, Any]:
    """The table row of controller ``name`` on a tracking task."""
    # the row's columns are built-in metrics: a metric of your own that fails stops nothing
    metrics = compute_metrics(rollout, extra=False)
    commanded = rollout.signals.get("tau_commanded", rollout.tau)
    row = {
        "controller": name,
        "status": rollout.metadata.get("status", "ok") if not stopped else "stopped",
        **{key: metrics.get(key, math.nan) for key in TRACKING_COLUMNS[4:-2]},
        "saturated_fraction": float(np.mean([actuation.saturated(tau) for tau in commanded])),
        "joint_limit_excess_max_rad": metrics.get("joint_limit_excess_max_rad", 0.0),
    }
    if stopped:
        reason = stopped
    elif not math.isfinite(row["task_position_error_rms_m"]):
        transient_s = (rollout.metadata.get("task") or {}).get("transient_s", math.nan)
        end_s = float(rollout.time_s[-1]) if len(rollout) else 0.0
        reason = (
            f"no samples after the task's transient (t = {transient_s:g} s; the run ends at "
            f"{end_s:g} s)"
        )
    elif row["joint_limit_excess_max_rad"] > PAST_LIMIT_RAD:  # rounding at a limit is not past it
        reason = f"an arm joint went {row['joint_limit_excess_max_rad']:.3f} rad past its limit"
    elif not metrics.get("task_settled", 0.0):
        final = metrics.get("task_position_error_final_m", math.nan)
        tolerance = (rollout.metadata.get("task") or {}).get("settle_tolerance_m", math.nan)
        reason = f"position error {final:.4f} m at the end > {tolerance:g} m"
    else:
        reason = ""
    row["reason"], row["success"] = reason, not reason
    return row


def write_tracking_figure(rollouts: dict[str, Rollout], out: Path) -> Path:
    """``controllers_tracking.png``: each controller's position and orientation errors."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from uvms_pin.results.figures.standard import save_figure

    fig, (ax_p, ax_o) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for name, rollout in rollouts.items():
        signals = rollout.signals
        error = signals["task_reference_position"] - signals["task_position"]
        ax_p.plot(rollout.time_s, 100.0 * np.linalg.norm(error, axis=1), label=name)
        rotation = np.linalg.norm(signals["task_rotation_error"], axis=1)
        ax_o.plot(rollout.time_s, np.degrees(rotation), label=name)
    ax_p.set_ylabel("position error [cm]")
    ax_o.set_ylabel("orientation error [deg]")
    ax_o.set_xlabel("t [s]")
    ax_p.legend(fontsize=8)
    path = save_figure(fig, out / "controllers_tracking.png", dpi=100)
    plt.close(fig)
    return path
