"""The comparison's per-controller numbers, from one rollout.

Every controller is judged on the same window and the same quantities (the TRUE contact
force, the sensor's noise excluded):

- force error e_f = f_e - f_d [N]: RMS and peak of |e_f| after ``after_s``;
- overshoot [N]: `force_overshoot_N`, as in a run's metrics: the largest error of the sign
  opposite to the initial error (any component; a component starting at zero error: any error);
- settling time [s]: the last time |e_f| exceeded ``band_N`` (0 if never; NaN if it does not
  settle, i.e. still outside the band at the end);
- orientation error: RMS and peak of |rpy_ee - rpy_d| after ``after_s`` [rad];
- effort: peak and RMS of the applied vehicle force |tau[0:3]| [N] and the peak joint torque
  [N m]; saturated fraction: share of logged samples whose command the actuators could not
  give (`Actuation.saturated`);
- funnel margins min(1 - |xi|) per level, for controllers with funnels (NaN otherwise);
- success: ran to the end with the peak force error after the transient <= ``tolerance_N``
  and every arm joint inside its limits; else the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvms_pin.results.metrics import PAST_LIMIT_RAD, force_overshoot_N, joint_limit_metrics
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.actuation import Actuation

__all__ = ["COLUMNS", "Criteria", "comparison_row"]

COLUMNS = (
    "controller",
    "status",
    "success",
    "reason",
    "force_error_rms_N",
    "force_error_peak_N",
    "overshoot_N",
    "settling_time_s",
    "orientation_error_rms_rad",
    "orientation_error_peak_rad",
    "vehicle_force_peak_N",
    "vehicle_force_rms_N",
    "joint_torque_peak_Nm",
    "saturated_fraction",
    "funnel_margin_first",
    "funnel_margin_second",
)


@dataclass(frozen=True)
class Criteria:
    """after_s: start of the 'after the transient' window [s]; band_N: settling band [N];
    tolerance_N: the largest peak force error after the transient that counts as holding
    the task [N]."""

    after_s: float
    band_N: float = 0.25
    tolerance_N: float = 0.5


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else math.nan


def _peak(x: np.ndarray) -> float:
    return float(np.max(x)) if x.size else math.nan


def comparison_row(
    name: str, rollout: Rollout, actuation: Actuation, criteria: Criteria, stopped: str = ""
) -> dict[str, Any]:
    """The table row of controller ``name`` (``stopped``: why the run ended early, if so)."""
    signals, time_s = rollout.signals, rollout.time_s
    error = rollout.wrench_contact_world[:, :3] - signals["force_desired_world_N"]
    norm = np.linalg.norm(error, axis=1)
    after = time_s >= criteria.after_s
    outside = np.flatnonzero(norm > criteria.band_N)
    settling = 0.0 if outside.size == 0 else float(time_s[outside[-1]])
    if outside.size and outside[-1] == len(norm) - 1:
        settling = math.nan
    orientation = np.linalg.norm(signals["e_x"][:, 3:6], axis=1)
    force = np.linalg.norm(rollout.tau[:, :3], axis=1)
    commanded = signals.get("tau_commanded", rollout.tau)
    saturated = [actuation.saturated(tau) for tau in commanded]
    row = {
        "controller": name,
        "status": rollout.metadata.get("status", "ok") if not stopped else "stopped",
        "force_error_rms_N": _rms(norm[after]),
        "force_error_peak_N": _peak(norm[after]),
        "overshoot_N": force_overshoot_N(error),
        "settling_time_s": settling,
        "orientation_error_rms_rad": _rms(orientation[after]),
        "orientation_error_peak_rad": _peak(orientation[after]),
        "vehicle_force_peak_N": float(force.max()),
        "vehicle_force_rms_N": _rms(force),
        "joint_torque_peak_Nm": float(np.abs(rollout.tau[:, 6:]).max(initial=0.0)),
        "saturated_fraction": float(np.mean(saturated)),
        "funnel_margin_first": _margin(signals, "xi_x"),
        "funnel_margin_second": _margin(signals, "xi_zeta"),
    }
    row["reason"] = _failure(row, rollout, criteria, stopped)
    row["success"] = not row["reason"]
    return row


def _margin(signals: dict[str, np.ndarray], key: str) -> float:
    return float(np.min(1.0 - np.abs(signals[key]))) if key in signals else math.nan


def _failure(row: dict[str, Any], rollout: Rollout, criteria: Criteria, stopped: str) -> str:
    if stopped:
        return stopped
    if not math.isfinite(row["force_error_peak_N"]):
        return "no samples after the transient"
    if row["force_error_peak_N"] > criteria.tolerance_N:
        return (
            f"force error after t = {criteria.after_s:g} s reached "
            f"{row['force_error_peak_N']:.3f} N > {criteria.tolerance_N:g} N"
        )
    excess = joint_limit_metrics(rollout).get("joint_limit_excess_max_rad", 0.0)
    if excess > PAST_LIMIT_RAD:  # a constraint holds a joint at its limit to rounding
        return f"an arm joint went {excess:.3f} rad past its limit"
    return ""
