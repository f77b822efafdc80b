"""What the end-effector touches: compliant contact models.

A contact model returns lambda, the wrench the end-effector exerts ON the environment
(docs/physics.md), at the end-effector point in world-aligned axes; the robot receives
-lambda through the contact-point Jacobian. The controller never sees these objects.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError


class ContactModel(ABC):
    """A compliant environment in contact with the end-effector."""

    def attach(self, position_world_m: np.ndarray) -> None:  # noqa: B027 - optional hook
        """Called once at t = 0 with the end-effector position (e.g. to anchor a spring)."""

    @abstractmethod
    def wrench_on_environment_world(
        self, position_world_m: np.ndarray, velocity_world_m_s: np.ndarray
    ) -> np.ndarray:
        """lambda = [force N; torque N m] exerted by the end-effector, world axes."""

    def record(self) -> dict[str, Any]:
        """What the environment is, as plain data (a rollout saves it, views draw it): its
        type and, once attached, where it is."""
        return {"type": type(self).__name__}


class PlacedContact(ContactModel):
    """A contact placed at a given world point, or where the tip is when the run starts
    (`attach`)."""

    _given: np.ndarray | None = None  # the point given (None: the tip's at t = 0)
    _at: np.ndarray | None = None  # the effective point, set by attach() when not given

    def _place(self, label: str, point) -> np.ndarray | None:
        """``point`` checked (or None): the point given, where the model stays."""
        self._given = self._at = None if point is None else finite_vector(label, point, 3)
        return self._given

    def attach(self, position_world_m):
        given = self._given
        self._at = np.array(position_world_m if given is None else given, dtype=float)

    def placed_at(self) -> list[float] | None:
        """The effective point as a list (for records), None before a run."""
        return None if self._at is None else self._at.tolist()


@dataclass
class LinearSpring(PlacedContact):
    """The paper's environment: f_e = K_f (p - p_0), anchored where the tip is at t = 0.

    Attributes:
        stiffness_N_m: diagonal of K_f (3,) [N/m], positive.
        anchor_world_m: p_0; None = the end-effector position at t = 0 (f_e(0) = 0).
    """

    stiffness_N_m: np.ndarray
    anchor_world_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.stiffness_N_m = finite_vector("spring stiffness_N_m", self.stiffness_N_m, 3)
        if np.any(self.stiffness_N_m < 0.0):
            raise ParameterError(f"spring stiffness must be >= 0, got {self.stiffness_N_m}")
        self.anchor_world_m = self._place("spring anchor_world_m", self.anchor_world_m)

    @property
    def anchor(self) -> np.ndarray | None:
        """The effective anchor p_0 (3,) [m]: the given one, or the one `attach` set; None
        before a run."""
        return self._at

    def record(self) -> dict[str, Any]:
        stiffness = self.stiffness_N_m.tolist()
        return {"type": "spring", "stiffness_N_m": stiffness, "anchor_world_m": self.placed_at()}

    def wrench_on_environment_world(self, position_world_m, velocity_world_m_s):
        if self._at is None:
            raise ParameterError("LinearSpring has no anchor: call attach() or give anchor_world_m")
        out = np.zeros(6)
        out[:3] = self.stiffness_N_m * (position_world_m - self._at)
        return out


@dataclass
class CompliantPlane(PlacedContact):
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
        n = finite_vector("plane normal_world", self.normal_world, 3)
        norm = float(np.linalg.norm(n))
        if norm == 0.0:
            raise ParameterError("plane normal_world must be non-zero")
        self.normal_world = n / norm
        if not (self.stiffness_N_m > 0.0 and math.isfinite(self.stiffness_N_m)):
            raise ParameterError(f"plane stiffness_N_m must be positive, got {self.stiffness_N_m}")
        if not (self.damping_N_s_m >= 0.0 and math.isfinite(self.damping_N_s_m)):
            raise ParameterError(f"plane damping_N_s_m must be >= 0, got {self.damping_N_s_m}")
        self.point_world_m = self._place("plane point_world_m", self.point_world_m)

    @property
    def point(self) -> np.ndarray | None:
        """The effective surface point (3,) [m]: the given one, or the one `attach` set;
        None before a run."""
        return self._at

    def record(self) -> dict[str, Any]:
        return {
            "type": "plane",
            "normal_world": self.normal_world.tolist(),
            "point_world_m": self.placed_at(),
            "stiffness_N_m": float(self.stiffness_N_m),
            "damping_N_s_m": float(self.damping_N_s_m),
        }

    def wrench_on_environment_world(self, position_world_m, velocity_world_m_s):
        if self._at is None:
            raise ParameterError(
                "CompliantPlane has no surface point: call attach() or give point_world_m"
            )
        depth = float((self._at - position_world_m) @ self.normal_world)
        out = np.zeros(6)
        if depth <= 0.0:
            return out
        rate = -float(velocity_world_m_s @ self.normal_world)
        push = max(0.0, self.stiffness_N_m * depth + self.damping_N_s_m * rate)
        out[:3] = -push * self.normal_world
        return out
