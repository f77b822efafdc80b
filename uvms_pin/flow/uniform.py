"""A uniform, constant current."""

from __future__ import annotations

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.flow.base import FlowField, as_points


def finite_vector3(value, name: str) -> np.ndarray:
    """A finite (3,) float vector, or ParameterError naming ``name``."""
    vector = np.asarray(value, dtype=float).reshape(-1)
    if vector.shape != (3,) or not np.all(np.isfinite(vector)):
        raise ParameterError(f"{name} must be 3 finite numbers, got {value!r}")
    return vector


class UniformCurrent(FlowField):
    """u(t, p) = U, the same everywhere and always (world frame) [m/s]."""

    def __init__(self, velocity_world_m_s):
        self.velocity_world_m_s = finite_vector3(velocity_world_m_s, "velocity_world_m_s")

    def velocity(self, time_s, points_world):
        return np.tile(self.velocity_world_m_s, (len(as_points(points_world)), 1))

    def local_acceleration(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3))

    def velocity_gradient(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3, 3))

    def acceleration(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3))

    def __repr__(self) -> str:
        return f"UniformCurrent({self.velocity_world_m_s.tolist()})"
