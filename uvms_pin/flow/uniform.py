"""A uniform, constant current."""

from __future__ import annotations

import numpy as np

from uvms_pin.checks import finite_vector
from uvms_pin.flow.base import FlowField, as_points, zero_gradient_kinematics


class UniformCurrent(FlowField):
    """u(t, p) = U, the same everywhere and always (world frame) [m/s]."""

    def __init__(self, velocity_world_m_s):
        self.velocity_world_m_s = finite_vector("velocity_world_m_s", velocity_world_m_s, 3)

    def velocity(self, time_s, points_world):
        return np.tile(self.velocity_world_m_s, (len(as_points(points_world)), 1))

    def local_acceleration(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3))

    def velocity_gradient(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3, 3))

    # uniform in space: no gradient of du/dt, no curvature
    gradient_kinematics = zero_gradient_kinematics

    def acceleration(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3))

    def record(self) -> dict:
        return {"type": "uniform_current", "velocity_world_m_s": self.velocity_world_m_s.tolist()}

    def __repr__(self) -> str:
        return f"UniformCurrent({self.velocity_world_m_s.tolist()})"
