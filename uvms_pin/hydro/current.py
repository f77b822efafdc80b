"""Ocean current as seen by a body: an irrotational, uniform, constant world velocity."""

from __future__ import annotations

import numpy as np

from uvms_pin.hydro.vector import cross3, mat_t_vec


def current_velocity_body(
    rotation_world_body: np.ndarray, current_world_m_s: np.ndarray
) -> np.ndarray:
    """nu_c = [R^T v_c; 0]: the fluid's body-frame twist at the body origin [m/s; rad/s].

    R may be a stack (..., 3, 3); the result is (..., 6).
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
