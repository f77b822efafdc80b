"""Scalar summaries of a rollout (what `metrics.json` holds)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from uvms_pin.rollout import Rollout


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else math.nan


def compute_metrics(rollout: Rollout) -> dict[str, float]:
    """Metrics of any run: timing, energy, motion and effort.

    Energy drift is max |E(t) - E(0)| / max(|E(0)|, K(0)) over the run (E = T + U), the
    number an energy-conservation check looks at. Efforts: vehicle force = |tau[0:3]|,
    vehicle torque = |tau[3:6]|, joint torques = max over joints of |tau_j|.
    """
    meta = rollout.metadata
    out: dict[str, float] = {
        "simulated_time_s": float(meta.get("simulated_time_s", math.nan)),
        "wall_time_s": float(meta.get("wall_time_s", math.nan)),
        "real_time_factor": float(meta.get("real_time_factor", math.nan)),
        "n_samples": float(len(rollout)),
    }
    if len(rollout) == 0:
        return out
    kinetic = rollout.kinetic_energy_J
    total = rollout.total_energy_J
    scale = max(abs(total[0]), kinetic[0], 1e-12)
    out.update(
        kinetic_energy_initial_J=float(kinetic[0]),
        kinetic_energy_final_J=float(kinetic[-1]),
        energy_relative_drift_max=float(np.max(np.abs(total - total[0])) / scale),
        energy_max_increase_J=float(np.max(np.diff(total))) if len(total) > 1 else 0.0,
        vehicle_displacement_m=float(np.linalg.norm(rollout.q[-1, :3] - rollout.q[0, :3])),
        vehicle_speed_final_m_s=float(np.linalg.norm(rollout.v[-1, :3])),
        vehicle_angular_speed_final_rad_s=float(np.linalg.norm(rollout.v[-1, 3:6])),
    )
    force = np.linalg.norm(rollout.tau[:, :3], axis=1)
    torque = np.linalg.norm(rollout.tau[:, 3:6], axis=1)
    joints = np.abs(rollout.tau[:, 6:])
    out.update(
        vehicle_force_peak_N=float(force.max()),
        vehicle_force_rms_N=_rms(force),
        vehicle_torque_peak_Nm=float(torque.max()),
        vehicle_torque_rms_Nm=_rms(torque),
        joint_torque_peak_Nm=float(joints.max()) if joints.size else 0.0,
        joint_torque_rms_Nm=_rms(joints),
    )
    return out
