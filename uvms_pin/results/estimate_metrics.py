"""Metrics of a navigation estimate, from the signals the estimator logs (``estimate``,
``estimate_variance``, `uvms_pin.sim.estimation.estimator`) and the true state:

- errors, estimate minus truth: position and velocity in the world [m, m/s]; attitude, the
  rotation vector of R_true^T R_est in body axes [rad] (the filter's error coordinates);
- their norms' RMS and maximum over the run, and the position error at the end;
- the fraction of error components within 3 of the filter's sigmas (position, attitude,
  velocity): about 0.997 for a consistent filter with Gaussian errors.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from uvms_pin.results.rollout_data import RolloutData

__all__ = ["ESTIMATE_SIGNALS", "estimate_errors", "estimate_metrics"]

#: the signals an estimate's metrics and figure need
ESTIMATE_SIGNALS = ("estimate", "estimate_variance")


def estimate_errors(rollout: RolloutData) -> dict[str, np.ndarray]:
    """Errors (n, 3) estimate minus truth, and the filter's sigmas (n, 3): ``position``
    [m], ``attitude`` [rad], ``velocity`` [m/s] and ``*_sigma``."""
    estimate, variance = rollout.signals["estimate"], rollout.signals["estimate_variance"]
    attitude = np.empty((len(rollout), 3))
    velocity_true = np.empty((len(rollout), 3))
    for k, (q, v, est) in enumerate(zip(rollout.q, rollout.v, estimate, strict=True)):
        rotation_true = pin.Quaternion(q[3:7]).normalized().toRotationMatrix()
        rotation_est = pin.Quaternion(est[3:7]).normalized().toRotationMatrix()
        attitude[k] = pin.log3(rotation_true.T @ rotation_est)
        velocity_true[k] = rotation_true @ v[:3]
    sigma = np.sqrt(np.maximum(variance, 0.0))
    return {
        "position": estimate[:, :3] - rollout.q[:, :3],
        "velocity": estimate[:, 7:10] - velocity_true,
        "attitude": attitude,
        "position_sigma": sigma[:, 0:3],
        "velocity_sigma": sigma[:, 3:6],
        "attitude_sigma": sigma[:, 6:9],
    }


def estimate_metrics(rollout: RolloutData) -> dict[str, float]:
    """The metrics above (none without an estimate)."""
    if len(rollout) == 0 or not all(name in rollout.signals for name in ESTIMATE_SIGNALS):
        return {}
    errors = estimate_errors(rollout)
    out: dict[str, float] = {}
    for name, unit in (("position", "m"), ("attitude", "rad"), ("velocity", "m_s")):
        norm = np.linalg.norm(errors[name], axis=1)
        out[f"estimate_{name}_error_rms_{unit}"] = float(np.sqrt(np.mean(norm**2)))
        out[f"estimate_{name}_error_max_{unit}"] = float(norm.max())
    out["estimate_position_error_final_m"] = float(np.linalg.norm(errors["position"][-1]))
    within = [
        np.abs(errors[name]) <= 3.0 * errors[f"{name}_sigma"]
        for name in ("position", "attitude", "velocity")
    ]
    out["estimate_within_3_sigma_fraction"] = float(np.mean(within)) if within else math.nan
    return out
