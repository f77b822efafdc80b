"""What the robot touches and what pushes it: compliant contact and disturbances.

Contact models return lambda, the wrench the end-effector exerts ON the environment
(docs/physics.md), at the end-effector point in world-aligned axes; the robot receives
-lambda through the contact-point Jacobian. The controller never sees these objects.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from uvms_pin.errors import ParameterError


def _vector(name: str, x, n: int) -> np.ndarray:
    arr = np.asarray(x, dtype=float).reshape(-1)
    if arr.shape != (n,):
        raise ParameterError(f"{name} must have {n} numbers, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} has a non-finite value: {arr}")
    return arr


class ContactModel(ABC):
    """A compliant environment in contact with the end-effector."""

    def attach(self, position_world_m: np.ndarray) -> None:  # noqa: B027 - optional hook
        """Called once at t = 0 with the end-effector position (e.g. to anchor a spring)."""

    @abstractmethod
    def wrench_on_environment_world(
        self, position_world_m: np.ndarray, velocity_world_m_s: np.ndarray
    ) -> np.ndarray:
        """lambda = [force N; torque N m] exerted by the end-effector, world axes."""


@dataclass
class LinearSpring(ContactModel):
    """The paper's environment: f_e = K_f (p - p_0), anchored where the tip is at t = 0.

    Attributes:
        stiffness_N_m: diagonal of K_f (3,) [N/m], positive.
        anchor_world_m: p_0; None = the end-effector position at t = 0 (f_e(0) = 0).
    """

    stiffness_N_m: np.ndarray
    anchor_world_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.stiffness_N_m = _vector("spring stiffness_N_m", self.stiffness_N_m, 3)
        if np.any(self.stiffness_N_m < 0.0):
            raise ParameterError(f"spring stiffness must be >= 0, got {self.stiffness_N_m}")
        if self.anchor_world_m is not None:
            self.anchor_world_m = _vector("spring anchor_world_m", self.anchor_world_m, 3)
        self._anchor = self.anchor_world_m  # the effective anchor, set again by attach()

    def attach(self, position_world_m):
        given = self.anchor_world_m
        self._anchor = np.array(position_world_m if given is None else given, dtype=float)

    def wrench_on_environment_world(self, position_world_m, velocity_world_m_s):
        if self._anchor is None:
            raise ParameterError("LinearSpring has no anchor: call attach() or give anchor_world_m")
        out = np.zeros(6)
        out[:3] = self.stiffness_N_m * (position_world_m - self._anchor)
        return out


@dataclass
class CompliantPlane(ContactModel):
    """A unilateral Kelvin-Voigt surface: pushes back only while the tip is inside it.

    With penetration d = (p_s - p) . n (n: outward normal, towards the robot),
    lambda = -n max(0, k d + c d_dot): the contact is lost (no pull) when the tip leaves.

    Attributes:
        point_world_m: a point of the surface; None = the tip position at t = 0.
        normal_world: outward unit normal (normalised here).
        stiffness_N_m: k > 0. damping_N_s_m: c >= 0.
    """

    normal_world: np.ndarray
    stiffness_N_m: float
    damping_N_s_m: float = 0.0
    point_world_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = _vector("plane normal_world", self.normal_world, 3)
        norm = float(np.linalg.norm(n))
        if norm == 0.0:
            raise ParameterError("plane normal_world must be non-zero")
        self.normal_world = n / norm
        if not (self.stiffness_N_m > 0.0 and math.isfinite(self.stiffness_N_m)):
            raise ParameterError(f"plane stiffness_N_m must be positive, got {self.stiffness_N_m}")
        if not (self.damping_N_s_m >= 0.0 and math.isfinite(self.damping_N_s_m)):
            raise ParameterError(f"plane damping_N_s_m must be >= 0, got {self.damping_N_s_m}")
        if self.point_world_m is not None:
            self.point_world_m = _vector("plane point_world_m", self.point_world_m, 3)
        self._point = self.point_world_m  # the effective surface point, set again by attach()

    def attach(self, position_world_m):
        given = self.point_world_m
        self._point = np.array(position_world_m if given is None else given, dtype=float)

    def wrench_on_environment_world(self, position_world_m, velocity_world_m_s):
        if self._point is None:
            raise ParameterError(
                "CompliantPlane has no surface point: call attach() or give point_world_m"
            )
        depth = float((self._point - position_world_m) @ self.normal_world)
        out = np.zeros(6)
        if depth <= 0.0:
            return out
        rate = -float(velocity_world_m_s @ self.normal_world)
        push = max(0.0, self.stiffness_N_m * depth + self.damping_N_s_m * rate)
        out[:3] = -push * self.normal_world
        return out


# ---- disturbances: wrenches on the vehicle body -----------------------------------------


@dataclass(frozen=True)
class SinusoidalDisturbance:
    """delta(t) = amplitude sin(2 pi t / period + phase), a body wrench on the vehicle.

    The paper's: amplitude 0.15 N on x, y, z, period 7 s.
    """

    amplitude: np.ndarray = field(default_factory=lambda: np.array([0.15, 0.15, 0.15, 0, 0, 0]))
    period_s: float = 7.0
    phase_rad: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "amplitude", _vector("disturbance amplitude", self.amplitude, 6))
        if not (self.period_s > 0.0 and math.isfinite(self.period_s)):
            raise ParameterError(f"disturbance period_s must be positive, got {self.period_s}")
        if not math.isfinite(self.phase_rad):
            raise ParameterError(f"disturbance phase_rad must be finite, got {self.phase_rad}")

    def __call__(self, time_s: float) -> np.ndarray:
        return self.amplitude * math.sin(2.0 * math.pi * time_s / self.period_s + self.phase_rad)


Disturbance = Callable[[float], np.ndarray]
"""Any function of time returning a (6,) body wrench [N; N m] on the vehicle."""
