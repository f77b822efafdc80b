"""Normalized actions: a in [-1, 1]^n  ->  commanded generalized input tau = s * a.

The action drives the vehicle's six axes and the arm joints: all nv entries of tau, or,
on a model whose jaw joints a ``[gripper]`` servo drives (`uvms_pin.control.jaw_servo`),
every entry but the jaw's (the servo gives those, as beside a controller in ``uvms-pin
run``). The scale s is what the actuators can actually give on each axis, so the box
[-1, 1]^n covers every input the plant can apply:

- vehicle (tau[:6], body wrench [N, N m]): with thrusters, s_i = max over thrusts
  f in [-f_reverse, f_forward] of |(B f)_i| (B the allocation matrix): each thruster
  pushes in the sign of B_ij that makes axis i largest, s_i = max(sum_j max(B_ij u_j,
  B_ij l_j), -sum_j min(B_ij u_j, B_ij l_j)). An axis no thruster reaches (s_i = 0) gets
  s_i = 1: its command is dropped by the allocation anyway.
- arm joints (tau[6:] [N m]): the joints' effort limits.

The commanded tau then goes through the plant's `Actuation` (allocation and saturation),
exactly as a controller's output does in ``uvms-pin run``.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits


def thruster_axis_capacity(actuation: ThrustersAndJointLimits) -> np.ndarray:
    """Largest |body wrench component| the thrusters can produce, per axis (6,) [N, N m]."""
    b = actuation.allocation
    upper = np.array([t.max_forward_N for t in actuation.thrusters])
    lower = -np.array([t.max_reverse_N for t in actuation.thrusters])
    push_up = np.maximum(b * upper, b * lower).sum(axis=1)
    push_down = np.minimum(b * upper, b * lower).sum(axis=1)
    return np.maximum(push_up, -push_down)


def action_scale(
    actuation: Actuation,
    nv: int,
    override: np.ndarray | list[float] | None = None,
    driven: np.ndarray | None = None,
) -> np.ndarray:
    """The scale s of tau[driven] = s * a (module docstring).

    Args:
        actuation: the plant's actuation.
        nv: number of generalized velocities.
        override: an explicit scale (one per driven entry) [N, N m], > 0; required when an
            axis has no actuation limit (`Unlimited` actuation, or arm torques not limited).
        driven: the entries of tau the action drives (increasing indices); None: all nv.

    Raises:
        ParameterError: a missing or bad scale.
    """
    size = nv if driven is None else len(driven)
    if override is not None:
        try:
            scale = np.asarray(override, dtype=float).reshape(-1)
        except (TypeError, ValueError):  # text, a table: not numbers
            scale = np.full(0, np.nan)
        if scale.shape != (size,) or not np.all(np.isfinite(scale)) or np.any(scale <= 0.0):
            raise ParameterError(
                f"action_scale must be {size} positive finite numbers [N, N m], got {override}"
            )
        return scale
    if not isinstance(actuation, ThrustersAndJointLimits):
        raise ParameterError(
            f"the scenario's actuation ({type(actuation).__name__}) has no limits to normalize "
            "actions by: give the scenario an [actuation] table, or pass "
            f"action_scale=<{size} numbers [N, N m]> to gym.make"
        )
    if actuation.joint_effort_limits_Nm is None:
        raise ParameterError(
            "the scenario's arm torques are unlimited (actuation.limit_joint_torques = false): "
            f"pass action_scale=<{size} numbers [N, N m]> to gym.make"
        )
    vehicle = thruster_axis_capacity(actuation)
    vehicle[vehicle <= 0.0] = 1.0
    scale = np.concatenate([vehicle, actuation.joint_effort_limits_Nm])
    return scale if driven is None else scale[driven]
