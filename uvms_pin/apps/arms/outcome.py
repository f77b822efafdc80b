"""One arm's run: simulate its scenario, put the metrics and the outcome in its row.

The status is "ok", the exception that stopped the run (FunnelViolation,
SimulationError), "error" (the controller raised) or "joint limits" if a joint left its
limits during an otherwise complete run; the reason says what happened (the joint, its
limits, when).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from uvms_pin.errors import FunnelViolation, SimulationError
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.metrics import compute_metrics
from uvms_pin.sim.run import Scenario, simulate

#: The rollout metrics a row keeps (NaN for one the rollout does not have).
METRICS = (
    "force_error_rms_N",
    "force_error_rms_after_transient_N",
    "funnel_margin_min_first",
    "funnel_margin_min_second",
    "task_position_error_rms_m",
    "task_orientation_error_rms_rad",
    "vehicle_force_peak_N",
    "vehicle_torque_peak_Nm",
    "joint_torque_peak_Nm",
    "simulated_time_s",
)


def joint_limit_violation(rollout, uvms: UVMS) -> str:
    """The first arm joint past its limits (1e-6 rad tolerance) and when; "" if none."""
    if len(rollout) == 0:
        return ""
    arm = uvms.arm_joints  # a continuous joint has no limits: never past them
    q = arm.positions(rollout.q)
    lo, hi = arm.lower, arm.upper
    bad = (q < lo - 1e-6) | (q > hi + 1e-6)
    if not np.any(bad):
        return ""
    k, j = np.argwhere(bad)[0]
    return (
        f"joint '{uvms.arm_joint_names[j]}' left its limits [{lo[j]:.3g}, {hi[j]:.3g}] "
        f"at t = {rollout.time_s[k]:.3f} s (q = {q[k, j]:.3g})"
    )


def run_scenario(
    scenario: Scenario, row: dict, keep_dir: Path | None = None, progress=None
) -> None:
    """Simulate, fill the metrics and the status into ``row``; keep the outputs if asked
    (``keep_dir``: rollout, metrics and figures, as ``uvms-pin run`` writes them)."""
    try:
        rollout = simulate(scenario, progress=progress)
        status, reason = "ok", ""
    except FunnelViolation as exc:
        rollout, status, reason = exc.rollout, "FunnelViolation", str(exc)
    except SimulationError as exc:  # a divergence, or "error": the controller raised
        rollout, reason = exc.rollout, str(exc)
        status = rollout.status.kind
    limits = joint_limit_violation(rollout, scenario.uvms)
    if limits:
        reason = f"{limits}; {reason}" if reason else limits
        if status == "ok":
            status = "joint limits"
    # the row's columns are built-in metrics: a metric of your own that fails does not
    # make the arm a model error (nor is it computed for nothing)
    metrics = compute_metrics(rollout, extra=False)
    for key in METRICS:
        row[key] = float(metrics.get(key, math.nan))
    row["status"], row["reason"] = status, reason
    if keep_dir is not None:
        from uvms_pin.apps.outputs import write_figures, write_results

        failure = write_results(rollout, keep_dir)
        write_figures(rollout, keep_dir)
        if failure is not None:  # its metrics.json says so too
            row["reason"] = f"{row['reason']}; {failure}".lstrip("; ")
