"""The water's motion as seen by a body: its twist and the rate of that twist in body axes.

The fluid twist at a body is [R^T u; 0] (u the flow velocity at the body's reference point,
world frame; the flow's rotation is not applied to bodies). Its rate in body axes, for a
body rotating at w and a flow of material acceleration a = Du/Dt there, is
[R^T a - w x R^T u; 0] (from R_dot = R [w]x); for a uniform constant current a = 0.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.hydro.vector import cross3, mat_t_vec


def current_velocity_body(
    rotation_world_body: np.ndarray, current_world_m_s: np.ndarray
) -> np.ndarray:
    """nu_c = [R^T v_c; 0]: the fluid's body-frame twist at the body origin [m/s; rad/s].

    R may be a stack (..., 3, 3), v_c one (3,) velocity or one per body (..., 3); the
    result is (..., 6).
    """
    linear = mat_t_vec(
        rotation_world_body, np.broadcast_to(current_world_m_s, rotation_world_body.shape[:-1])
    )
    return np.concatenate([linear, np.zeros_like(linear)], axis=-1)


def current_acceleration_body(
    angular_velocity_body: np.ndarray, current_body_m_s: np.ndarray
) -> np.ndarray:
    """d/dt of nu_c in body components for a constant world current: [-w x v_c; 0].

    From v_c,body = R^T v_c,world and R_dot = R [w]x. Stacks broadcast: (..., 3) -> (..., 6).
    """
    linear = -cross3(angular_velocity_body, current_body_m_s)
    return np.concatenate([linear, np.zeros_like(linear)], axis=-1)


def flow_twist_rate_body(
    rotation_world_body: np.ndarray,
    angular_velocity_body: np.ndarray,
    flow_velocity_body_m_s: np.ndarray,
    flow_acceleration_world_m_s2: np.ndarray,
) -> np.ndarray:
    """nu_c_dot = [R^T a - w x v_c,body; 0] (..., 6) [m/s^2; rad/s^2].

    a = Du/Dt (world) at the body's point; with a = 0 this is `current_acceleration_body`.
    """
    linear = mat_t_vec(rotation_world_body, flow_acceleration_world_m_s2) - cross3(
        angular_velocity_body, flow_velocity_body_m_s
    )
    return np.concatenate([linear, np.zeros_like(linear)], axis=-1)
