"""A steady current whose speed varies with depth (a sheared current)."""

from __future__ import annotations

import numpy as np

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.flow.base import FlowField, as_points, zero_gradient_kinematics


class DepthProfileCurrent(FlowField):
    """u(p) = U f(depth), depth = -z [m], f linear between tabulated (depth, factor) pairs
    and constant beyond them.

    Args:
        velocity_world_m_s: U (3,) [m/s], the velocity where f = 1.
        depths_m: strictly increasing depths below the mean surface [m].
        factors: f at those depths (e.g. 1 at the surface, 0.3 near the sea floor).
    """

    def __init__(self, velocity_world_m_s, depths_m, factors):
        self.velocity_world_m_s = finite_vector("velocity_world_m_s", velocity_world_m_s, 3)
        try:
            depths = np.asarray(depths_m, dtype=float).reshape(-1)
            factors_ = np.asarray(factors, dtype=float).reshape(-1)
        except (TypeError, ValueError):  # strings, None, ragged lists
            depths = factors_ = np.zeros(0)
        if depths.shape != factors_.shape or depths.size < 2:
            raise ParameterError("depths_m and factors must be equal-length lists of >= 2 numbers")
        if not (np.all(np.isfinite(depths)) and np.all(np.isfinite(factors_))):
            raise ParameterError("depths_m and factors must be finite")
        if np.any(np.diff(depths) <= 0.0):
            raise ParameterError(f"depths_m must be strictly increasing, got {depths.tolist()}")
        self.depths_m, self.factors = depths, factors_

    @classmethod
    def power_law(
        cls,
        velocity_world_m_s,
        seabed_depth_m: float,
        exponent: float = 1.0 / 7.0,
        samples: int = 64,
    ) -> DepthProfileCurrent:
        """U ((d - depth) / d)^exponent (the 1/7 tidal-current law), tabulated."""
        if not seabed_depth_m > 0.0:
            raise ParameterError(f"seabed_depth_m must be positive, got {seabed_depth_m}")
        depths = np.linspace(0.0, seabed_depth_m, samples)
        return cls(
            velocity_world_m_s, depths, ((seabed_depth_m - depths) / seabed_depth_m) ** exponent
        )

    def _factor_and_slope(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        depth = -points[:, 2]
        factor = np.interp(depth, self.depths_m, self.factors)
        segment_slopes = np.diff(self.factors) / np.diff(self.depths_m)
        index = np.clip(
            np.searchsorted(self.depths_m, depth, side="right") - 1, 0, len(segment_slopes) - 1
        )
        inside = (depth > self.depths_m[0]) & (depth < self.depths_m[-1])
        d_factor_d_depth = np.where(inside, segment_slopes[index], 0.0)
        return factor, -d_factor_d_depth  # d/dz = -d/d(depth)

    def velocity(self, time_s, points_world):
        factor, _ = self._factor_and_slope(as_points(points_world))
        return factor[:, None] * self.velocity_world_m_s

    def local_acceleration(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3))

    def velocity_gradient(self, time_s, points_world):
        _, slope_z = self._factor_and_slope(as_points(points_world))
        grad = np.zeros((len(slope_z), 3, 3))
        grad[:, :, 2] = slope_z[:, None] * self.velocity_world_m_s
        return grad

    # steady, and linear in depth between the tabulated depths: no curvature (the kinks
    # at the tabulated depths are a set of measure zero)
    gradient_kinematics = zero_gradient_kinematics

    def record(self) -> dict:
        return {
            "type": "depth_profile_current",
            "velocity_world_m_s": self.velocity_world_m_s.tolist(),
            "depths_m": self.depths_m.tolist(),
            "factors": self.factors.tolist(),
        }

    def __repr__(self) -> str:
        return (
            f"DepthProfileCurrent({self.velocity_world_m_s.tolist()}, {len(self.depths_m)} depths)"
        )
