"""The task's initial configuration for any arm: the tool on the contact point, pointing forward.

With the vehicle held at its initial pose, the arm joints are solved so that the end-effector
frame ``ee`` reaches a target placement in the world (the reference arm's tool tip and
orientation at the scenario's start):

- position first: damped least squares on the position error;
- orientation second, in the null space of the position task (task-priority inverse
  kinematics, Siciliano & Slotine 1991): an arm with fewer than 6 joints (or at a point where
  its wrist cannot orient freely) keeps the contact point and gets as close as it can to the
  orientation, and the result says how far it is;
- joint limits by clipping, with a margin (0.05 rad or 5 % of the range); several starts (the neutral configuration, the middle of the
  limits, then seeded random ones); a solution whose joint origins (and the points half-way
  between consecutive ones) are inside the hull box, inflated by ``hull_margin_m``, is
  rejected (a coarse check, not a collision model).

The contact point is *reachable* when some start ends within ``position_tolerance_m``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.uvms import UVMS

#: Position-only iterations after the prioritized ones (converge the contact point).
_POLISH_ITERATIONS = 60
#: Distance kept from the joint limits: the smaller of this [rad or m] and a fraction of the range.
_LIMIT_MARGIN_RAD = 0.05
_LIMIT_MARGIN_FRACTION = 0.05

__all__ = ["InitialConfiguration", "solve_initial_configuration"]


@dataclass
class InitialConfiguration:
    """Result of :func:`solve_initial_configuration`.

    Attributes:
        reachable: the position was reached within tolerance by a hull-clear solution.
        q: the best configuration found (nq,).
        position_error_m: |p_ee - p_target| of q.
        orientation_error_rad: angle of R_ee^T R_target of q.
        reason: why not reachable ('' if reachable).
    """

    reachable: bool
    q: np.ndarray
    position_error_m: float
    orientation_error_rad: float
    reason: str = ""


def _arm_bounds(uvms: UVMS) -> tuple[np.ndarray, np.ndarray]:
    """Joint limits shrunk by a margin (the task must start off the limits).

    Raises ModelError for a continuous joint: the search moves q[7:] as one angle per
    joint, as `uvms_pin.mount_arm` makes them (a continuous joint becomes revolute)."""
    arm = uvms.arm_joints
    if "continuous" in arm.kinds:
        raise ModelError(
            "the initial-configuration search needs one configuration entry per arm joint; "
            f"joints {[n for n, k in zip(arm.names, arm.kinds, strict=True) if k == 'continuous']} "
            "are continuous (mount the arm with uvms_pin.mount_arm, which makes them revolute)",
            path=uvms.source or None,
        )
    lo = np.maximum(arm.lower, -2.0 * np.pi)
    hi = np.minimum(arm.upper, 2.0 * np.pi)
    margin = np.minimum(_LIMIT_MARGIN_RAD, _LIMIT_MARGIN_FRACTION * (hi - lo))
    return lo + margin, hi - margin


def _damped_pinv(a: np.ndarray, damping: float) -> np.ndarray:
    return a.T @ np.linalg.inv(a @ a.T + damping**2 * np.eye(a.shape[0]))


def _inside_hull(points: np.ndarray, hull: tuple[np.ndarray, np.ndarray], margin: float) -> bool:
    center, size = hull
    half = 0.5 * np.asarray(size) + margin
    return bool(np.any(np.all(np.abs(points - np.asarray(center)) < half, axis=1)))


def solve_initial_configuration(
    uvms: UVMS,
    vehicle_q: np.ndarray,
    target: pin.SE3,
    *,
    hull: tuple[np.ndarray, np.ndarray] | None = None,
    hull_margin_m: float = 0.02,
    position_tolerance_m: float = 1e-3,
    starts: int = 24,
    iterations: int = 300,
    seed: int = 0,
) -> InitialConfiguration:
    """Arm joints putting ``ee`` at ``target`` (world) with the vehicle at ``vehicle_q`` (7,).

    Args:
        uvms: the mounted system.
        vehicle_q: free-flyer part of q (position, quaternion xyzw).
        target: world placement wanted for the end-effector frame.
        hull: (centre, size) of the hull box in the vehicle frame, for the clearance check.
        hull_margin_m: clearance required around the hull box [m].
        position_tolerance_m: reach tolerance [m].
        starts, iterations, seed: search effort and reproducibility.
    """
    model = uvms.model
    data = model.createData()
    fid = uvms.ee_frame_id
    lo, hi = _arm_bounds(uvms)
    rng = np.random.default_rng(seed)
    guesses = [uvms.neutral_configuration()[7:], 0.5 * (lo + hi)]
    guesses += [rng.uniform(lo, hi) for _ in range(max(0, starts - 2))]
    n = uvms.n_arm_joints
    vehicle_placement = pin.XYZQUATToSE3(np.asarray(vehicle_q, dtype=float))
    best: tuple | None = None
    best_any: tuple | None = None
    reason = "contact point out of reach"
    for guess in guesses:
        q = np.concatenate([vehicle_q, guess])
        for it in range(iterations + _POLISH_ITERATIONS):
            pin.framesForwardKinematics(model, data, q)
            placement = data.oMf[fid]
            e_p = target.translation - placement.translation
            e_o = placement.rotation @ pin.log3(placement.rotation.T @ target.rotation)
            if np.linalg.norm(e_p) < 1e-9 and np.linalg.norm(e_o) < 1e-9:
                break
            jac = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)[:, 6:]
            j_p, j_o = jac[:3], jac[3:]
            dq = _damped_pinv(j_p, 1e-4) @ e_p
            if it < iterations:  # orientation in the null space of the position task
                null = np.eye(n) - np.linalg.pinv(j_p, rcond=1e-6) @ j_p
                dq2 = null @ (_damped_pinv(j_o @ null, 5e-2) @ (e_o - j_o @ dq))
                norm2 = float(np.linalg.norm(dq2))
                if norm2 > 0.2:
                    dq2 *= 0.2 / norm2
                dq = dq + dq2
            step = float(np.max(np.abs(dq)))
            if step > 0.3:
                dq *= 0.3 / step
            q[7:] = np.clip(q[7:] + dq, lo, hi)
        pin.framesForwardKinematics(model, data, q)
        placement = data.oMf[fid]
        pos_err = float(np.linalg.norm(target.translation - placement.translation))
        ori_err = float(np.linalg.norm(pin.log3(placement.rotation.T @ target.rotation)))
        limit_margin = float(np.min(np.minimum(q[7:] - lo, hi - q[7:]) / (hi - lo)))
        candidate = (round(ori_err, 4), -limit_margin, pos_err, q.copy())
        if best_any is None or pos_err < best_any[2]:
            best_any = candidate
        if pos_err > position_tolerance_m:
            continue
        if hull is not None:
            origins = np.array([data.oMi[j].translation for j in range(2, model.njoints)])
            origins = np.vstack([origins, placement.translation])
            points = np.vstack([origins, 0.5 * (origins[1:] + origins[:-1])])
            local = (points - vehicle_placement.translation) @ vehicle_placement.rotation
            if _inside_hull(local, hull, hull_margin_m):
                reason = "contact point only reachable through the hull"
                continue
        if best is None or candidate[:2] < best[:2]:
            best = candidate
    if best is None:
        _, _, pos_err, q = best_any
        pin.framesForwardKinematics(model, data, q)
        ori = float(np.linalg.norm(pin.log3(data.oMf[fid].rotation.T @ target.rotation)))
        return InitialConfiguration(False, q, pos_err, ori, f"{reason} (closest {pos_err:.3f} m)")
    ori_err, _, pos_err, q = best
    return InitialConfiguration(True, q, pos_err, float(ori_err))
