"""Metrics of a tracking task, from the signals `uvms_pin.sim.task_record` adds to a rollout
(true poses, task frame): after the task's stated transient t_0 (``transient_s``),

- position error |p_r - p| [m]: RMS and max after t_0, and at the end;
- orientation error |log3(R_r R^T)| [rad]: RMS and max after t_0;
- settling time [s]: the first logged time from which the position error stays within
  ``settle_tolerance_m`` to the end (NaN, with ``task_settled`` = 0, if it never does);
- path length of the tracked frame and of its reference [m] (sum of |Delta p| between
  samples);
- actuation energy [J]: sum over samples of |tau_i zeta_i| summed over every velocity i,
  times the logged period (the work the thrusters and joints do, positive or negative
  counted alike; a lower bound of what they spend).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from uvms_pin.results.rollout_data import RolloutData

__all__ = ["task_metrics"]


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else math.nan


def _path_length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum()) if len(points) > 1 else 0.0


def settling_time(time_s: np.ndarray, error: np.ndarray, tolerance: float) -> float:
    """The first time from which ``error <= tolerance`` to the end (NaN if never)."""
    outside = np.flatnonzero(error > tolerance)
    if outside.size == 0:
        return float(time_s[0])
    if outside[-1] == len(error) - 1:
        return math.nan
    return float(time_s[outside[-1] + 1])


def task_metrics(rollout: RolloutData) -> dict[str, float]:
    """The tracking metrics of the module docstring ({} without a task)."""
    task = rollout.metadata.get("task")
    signals = rollout.signals
    if not task or "task_position" not in signals or len(rollout) == 0:
        return {}
    time_s = rollout.time_s
    position_error = np.linalg.norm(
        signals["task_reference_position"] - signals["task_position"], axis=1
    )
    rotation_error = np.linalg.norm(signals["task_rotation_error"], axis=1)
    after = time_s >= float(task.get("transient_s", 0.0))
    settled = settling_time(time_s, position_error, float(task.get("settle_tolerance_m", 0.01)))
    period = float(np.median(np.diff(time_s))) if len(time_s) > 1 else 0.0
    power = np.abs(rollout.tau * rollout.v).sum(axis=1)
    return {
        "task_position_error_rms_m": _rms(position_error[after]),
        "task_position_error_max_m": float(position_error[after].max())
        if after.any()
        else math.nan,
        "task_position_error_final_m": float(position_error[-1]),
        "task_orientation_error_rms_rad": _rms(rotation_error[after]),
        "task_orientation_error_max_rad": float(rotation_error[after].max())
        if after.any()
        else math.nan,
        "task_settling_time_s": settled,
        "task_settled": 0.0 if math.isnan(settled) else 1.0,
        "task_path_length_m": _path_length(signals["task_position"]),
        "task_reference_path_length_m": _path_length(signals["task_reference_position"]),
        "task_actuation_energy_J": float(power.sum() * period),
    }
