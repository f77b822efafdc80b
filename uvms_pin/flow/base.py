"""The flow-field interface and the superposition of fields."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError


def as_points(points_world: np.ndarray) -> np.ndarray:
    """Points as a float (n, 3) array; a single (3,) point becomes (1, 3)."""
    points = np.asarray(points_world, dtype=float)
    if points.ndim == 1:
        points = points[None, :]
    if points.ndim != 2 or points.shape[1] != 3:
        raise ParameterError(f"points_world must have shape (n, 3), got {points.shape}")
    return points


def zero_gradient_kinematics(
    flow: Any, time_s: float, points_world: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """`FlowField.gradient_kinematics` of a field whose du/dt does not vary in space and whose
    u has no curvature: zeros (n, 3, 3) and (n, 3, 3, 3). Such a field's class takes it as
    its method (``gradient_kinematics = zero_gradient_kinematics``)."""
    n = len(as_points(points_world))
    return np.zeros((n, 3, 3)), np.zeros((n, 3, 3, 3))


def checked_output(flow: Any, method: str, value: Any, shape: tuple[int, ...]) -> np.ndarray:
    """What ``flow.method`` returned, as a float array of ``shape``; else ParameterError
    naming the field and the method (a field of the user's that returns one point's value
    for n points would otherwise fail deep in numpy)."""
    array = np.asarray(value, dtype=float)
    if array.shape != shape:
        raise ParameterError(
            f"the flow {flow!r}: {method} returned shape {array.shape}, expected {shape} "
            f"(one row per point: n = {shape[0]})"
        )
    return array


class FlowField(ABC):
    """An undisturbed water flow u(t, p) in the world frame (waves: irrotational; a sheared
    current has vorticity, which bodies do not feel: the fluid twist has no angular part).

    Subclasses give the velocity, its local time derivative du/dt and its spatial gradient
    grad u (J_ij = du_i / dx_j); the material acceleration follows:

        Du/Dt = du/dt + (grad u) u                                  [m/s^2]

    which is what the inertial loads on a body need (the pressure gradient of the
    undisturbed flow is -grad p = rho (Du/Dt - g)).
    """

    @abstractmethod
    def velocity(self, time_s: float, points_world: np.ndarray) -> np.ndarray:
        """u (n, 3) [m/s] at the world points (n, 3) [m]."""

    @abstractmethod
    def local_acceleration(self, time_s: float, points_world: np.ndarray) -> np.ndarray:
        """du/dt (n, 3) [m/s^2] at fixed world points."""

    @abstractmethod
    def velocity_gradient(self, time_s: float, points_world: np.ndarray) -> np.ndarray:
        """grad u (n, 3, 3) [1/s]: entry [k, i, j] = du_i / dx_j at point k."""

    def acceleration(self, time_s: float, points_world: np.ndarray) -> np.ndarray:
        """Du/Dt = du/dt + (grad u) u (n, 3) [m/s^2]: the material acceleration."""
        return self.velocity_and_acceleration(time_s, points_world)[1]

    def kinematics(
        self, time_s: float, points_world: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(u, du/dt, grad u) at once; fields override it to share work between the three."""
        points = as_points(points_world)
        n = len(points)
        return (
            checked_output(self, "velocity", self.velocity(time_s, points), (n, 3)),
            checked_output(
                self, "local_acceleration", self.local_acceleration(time_s, points), (n, 3)
            ),
            checked_output(
                self, "velocity_gradient", self.velocity_gradient(time_s, points), (n, 3, 3)
            ),
        )

    def velocity_and_acceleration(
        self, time_s: float, points_world: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(u, Du/Dt) (n, 3) each, from one `kinematics` evaluation."""
        u, du_dt, grad = self.kinematics(time_s, points_world)
        return u, du_dt + np.einsum("kij,kj->ki", grad, u)

    def gradient_kinematics(
        self, time_s: float, points_world: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(grad du/dt (n, 3, 3) [1/s^2], the Hessian of u (n, 3, 3, 3) [1/(m s)], entry
        [k, i, j, l] = d2 u_i / dx_j dx_l at point k): the second-order kinematics that the
        derivatives of the dynamics need (`material_gradients`). A field defined outside
        uvms-pin gives them by overriding this method."""
        raise ParameterError(
            f"the flow {self!r} does not give its second-order kinematics (override "
            "FlowField.gradient_kinematics): the derivatives of the dynamics need them"
        )

    def material_gradients(
        self, time_s: float, points_world: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(u, grad u, Du/Dt, grad Du/Dt) at the points: what a body's hydrodynamic loads and
        their derivatives read from the flow. With G = grad u and H the Hessian,

            grad(Du/Dt)_ij = d(du_i/dt)/dx_j + sum_k H_ikj u_k + sum_k G_ik G_kj.
        """
        points = as_points(points_world)
        n = len(points)
        u, du_dt, grad = self.kinematics(time_s, points)
        grad_du_dt, hessian = self.gradient_kinematics(time_s, points)
        grad_du_dt = checked_output(self, "gradient_kinematics[0]", grad_du_dt, (n, 3, 3))
        hessian = checked_output(self, "gradient_kinematics[1]", hessian, (n, 3, 3, 3))
        material = du_dt + np.einsum("kij,kj->ki", grad, u)
        material_grad = grad_du_dt + np.einsum("kimj,km->kij", hessian, u) + np.matmul(grad, grad)
        return u, grad, material, material_grad

    @property
    def has_free_surface(self) -> bool:
        """True for fields that move the free surface (waves): bodies must stay below it."""
        return False

    def surface_elevation(self, time_s: float, xy_world: np.ndarray) -> np.ndarray:
        """Free-surface elevation eta (n,) [m] above z = 0 at horizontal points (n, 2)."""
        xy = np.asarray(xy_world, dtype=float).reshape(-1, 2)
        return np.zeros(len(xy))

    def surface_kinematics(
        self, time_s: float, xy_world: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(eta (n,) [m], d eta / dt (n,) [m/s], (d eta / dx, d eta / dy) (n, 2)) at
        horizontal points (n, 2): the free surface and how it moves (level and still here)."""
        xy = np.asarray(xy_world, dtype=float).reshape(-1, 2)
        return self.surface_elevation(time_s, xy), np.zeros(len(xy)), np.zeros((len(xy), 2))

    @property
    def elevation_bound_m(self) -> float:
        """A bound on |eta| [m] over all times and places (0 for a level surface; infinite
        for a field with a free surface that does not say): a body deeper than it is wet
        whatever the waves do."""
        return math.inf if self.has_free_surface else 0.0

    def record(self) -> dict[str, Any]:
        """This field as plain data (JSON: a rollout saves it), which
        `uvms_pin.flow.record.flow_from_record` turns back into the same field. A field
        defined outside uvms-pin records its type and repr only (it cannot be rebuilt)."""
        return {"type": type(self).__name__, "repr": repr(self)}

    def __add__(self, other: FlowField) -> SumFlow:
        if not isinstance(other, FlowField):
            return NotImplemented
        return SumFlow((self, other))


class SumFlow(FlowField):
    """The superposition of flow fields (linear: velocities, their time derivatives and
    gradients add; the material acceleration is formed from the sums, not summed)."""

    def __init__(self, fields: tuple[FlowField, ...]):
        if not isinstance(fields, tuple | list):
            raise ParameterError(f"SumFlow takes a tuple of FlowFields, got {fields!r}")
        flat: list[FlowField] = []
        for f in fields:
            if not isinstance(f, FlowField):
                raise ParameterError(f"SumFlow adds FlowFields, got {f!r}")
            flat.extend(f.fields if isinstance(f, SumFlow) else (f,))
        if not flat:
            raise ParameterError("SumFlow needs at least one field")
        self.fields = tuple(flat)

    def velocity(self, time_s, points_world):
        points = as_points(points_world)
        return sum(f.velocity(time_s, points) for f in self.fields)

    def local_acceleration(self, time_s, points_world):
        points = as_points(points_world)
        return sum(f.local_acceleration(time_s, points) for f in self.fields)

    def velocity_gradient(self, time_s, points_world):
        points = as_points(points_world)
        return sum(f.velocity_gradient(time_s, points) for f in self.fields)

    def kinematics(self, time_s, points_world):
        points = as_points(points_world)
        parts = [f.kinematics(time_s, points) for f in self.fields]
        return tuple(sum(p[i] for p in parts) for i in range(3))

    def gradient_kinematics(self, time_s, points_world):
        points = as_points(points_world)
        parts = [f.gradient_kinematics(time_s, points) for f in self.fields]
        return tuple(sum(p[i] for p in parts) for i in range(2))

    @property
    def has_free_surface(self) -> bool:
        return any(f.has_free_surface for f in self.fields)

    def surface_elevation(self, time_s, xy_world):
        return sum(f.surface_elevation(time_s, xy_world) for f in self.fields)

    def surface_kinematics(self, time_s, xy_world):
        parts = [f.surface_kinematics(time_s, xy_world) for f in self.fields]
        return tuple(sum(p[i] for p in parts) for i in range(3))

    @property
    def elevation_bound_m(self) -> float:
        return sum(f.elevation_bound_m for f in self.fields)

    def record(self) -> dict[str, Any]:
        return {"type": "sum", "fields": [f.record() for f in self.fields]}

    def __repr__(self) -> str:
        return " + ".join(repr(f) for f in self.fields)
