"""Point contacts with Coulomb friction between spheres on bodies and a fixed plane (the
seafloor), as constraints (Pinocchio's `PointContactConstraintModel`), solved implicitly by
`step.constrained_velocity`.

A sphere of radius R centred at c (on a body) and the plane through p0 with outward unit
normal n: the gap is r = n . (c - p0) - R [m] and the contact point on the sphere is
p = c - R n. Each contact has three rows in the contact frame C = (t1, t2, n) [world axes]:

    J v = C^T (v_p - 0)        the velocity of the sphere's point relative to the plane,
                               tangential (two rows) then normal [m/s]
    lambda = (lambda_t1, lambda_t2, lambda_n) [N s], the impulse of the plane on the body,
    in the Coulomb cone  |lambda_t| <= mu lambda_n.

Pinocchio's point contact gives the velocity of its second point relative to its first, in
the first point's frame: the first point is the plane's (joint 0, the world, placed at the
projection p - r n of the contact point, its z the normal), the second the sphere's (its
body's joint, placed at p, the same rotation). Built anew at every configuration: as the
sphere rolls, its contact point moves on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.rows import ConstraintRows, evaluated

__all__ = [
    "ContactSphere",
    "PlaneContacts",
    "contact_frame",
    "contact_rows",
    "point_contact",
    "point_jacobian",
]

_UNIT = "N s"


@dataclass(frozen=True)
class ContactSphere:
    """A sphere fixed on a body: ``joint_id`` (its Pinocchio joint), ``center_in_joint``
    (3,) [m] in that joint's frame, ``radius_m`` [m] (0: a point)."""

    joint_id: int
    center_in_joint: np.ndarray
    radius_m: float

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "center_in_joint", finite_vector("center_in_joint", self.center_in_joint, 3)
        )
        if not (math.isfinite(self.radius_m) and self.radius_m >= 0.0):
            raise ParameterError(f"a contact sphere's radius must be >= 0 [m], got {self.radius_m}")


@dataclass(frozen=True)
class PlaneContacts:
    """Spheres on bodies against the fixed plane through ``point_world`` (3,) [m] with the
    outward normal ``normal_world`` (3,) (normalised here), Coulomb friction ``friction``
    (mu >= 0). ``margin`` [m]: a sphere is solved when its gap is at most the reach of its
    contact point over the period plus this."""

    spheres: tuple[ContactSphere, ...]
    point_world: np.ndarray
    normal_world: np.ndarray
    friction: float
    margin: float = 1.0e-3
    name: str = "contacts"

    def __post_init__(self) -> None:
        object.__setattr__(self, "point_world", finite_vector("point_world", self.point_world, 3))
        normal = finite_vector("normal_world", self.normal_world, 3)
        if np.linalg.norm(normal) < 1e-12:
            raise ParameterError("the plane's normal_world must not be zero")
        object.__setattr__(self, "normal_world", normal / np.linalg.norm(normal))
        if not (math.isfinite(self.friction) and self.friction >= 0.0):
            raise ParameterError(f"the friction coefficient must be >= 0, got {self.friction}")
        if not (math.isfinite(self.margin) and self.margin >= 0.0):
            raise ParameterError(f"the contacts' margin must be >= 0 [m], got {self.margin}")

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """The contacts at q that can close within ``period_s`` at ``speed``
        (`ConstraintSet.rows`): three rows per contact (t1, t2, n)."""
        evaluated_contacts, gaps, labels = [], [], []
        for k, sphere in enumerate(self.spheres):
            if not 0 < sphere.joint_id < model.njoints:
                raise ParameterError(f"contact sphere {k}: no joint {sphere.joint_id} in the model")
            center = data.oMi[sphere.joint_id].act(sphere.center_in_joint)
            gap = float(self.normal_world @ (center - self.point_world)) - sphere.radius_m
            point = center - sphere.radius_m * self.normal_world
            normal_rate = self.normal_world @ point_jacobian(model, data, sphere.joint_id, point)
            if gap > period_s * np.abs(normal_rate) @ speed + self.margin:
                continue
            evaluated_contacts.append(
                point_contact(
                    model, data, sphere.joint_id, (point, self.normal_world, gap), self.friction
                )
            )
            gaps.append(gap)
            labels.append(f"{model.names[sphere.joint_id]}[{k}]")
        return contact_rows(self.name, model.nv, evaluated_contacts, gaps, labels)


def contact_rows(
    name: str, nv: int, evaluated_contacts: list, gaps: list[float], labels: list[str], where=()
) -> ConstraintRows:
    """The rows (three a contact: t1, t2, n) of point contacts, each as `point_contact`
    gives it, with its signed gap [m] and its label; ``where``: `ConstraintRows.where`."""
    if not evaluated_contacts:
        return ConstraintRows.empty(name, _UNIT, nv)
    models, datas, jacobians = zip(*evaluated_contacts, strict=True)
    return ConstraintRows(
        name,
        _UNIT,
        tuple(models),
        tuple(datas),
        np.vstack(jacobians),
        np.array([[0.0, 0.0, gap] for gap in gaps]).reshape(-1),
        np.tile([False, False, True], len(gaps)),
        tuple(f"{label} {axis}" for label in labels for axis in ("t1", "t2", "n")),
        tuple(where),
    )


def contact_frame(normal: np.ndarray) -> np.ndarray:
    """C = (t1, t2, n) (3x3, a rotation) with n its third column."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(helper, normal)
    t1 /= np.linalg.norm(t1)
    return np.column_stack([t1, np.cross(normal, t1), normal])


def point_jacobian(
    model: pin.Model, data: pin.Data, joint_id: int, point: np.ndarray
) -> np.ndarray:
    """J_p (3 x nv): the world velocity of the body point at ``point`` (world) [m/s],
    v_p = v_o + w x (p - o) from the joint's world-aligned Jacobian at its origin o; zero on
    the universe (joint 0: a fixture's root link), whose Jacobian Pinocchio does not give."""
    if joint_id == 0:
        return np.zeros((3, model.nv))
    # a model of one velocity (a fixture's single joint): eigenpy gives a (6,) vector
    jacobian = pin.getJointJacobian(model, data, joint_id, pin.LOCAL_WORLD_ALIGNED).reshape(6, -1)
    offset = point - data.oMi[joint_id].translation
    return jacobian[:3] - pin.skew(offset) @ jacobian[3:]


def point_contact(
    model: pin.Model,
    data: pin.Data,
    joint_id: int,
    touching: tuple[np.ndarray, np.ndarray, float],
    friction: float,
    surface_joint: int = 0,
) -> tuple[pin.ConstraintModel, pin.ConstraintData, np.ndarray]:
    """The evaluated point contact (`rows.evaluated`: three rows t1, t2, n) of the body of
    ``joint_id`` at its material point ``touching`` = (point (3,) [m], the surface's
    outward unit normal (3,), the signed gap r [m]) with the Coulomb cone of ``friction``:
    the surface's point p - r n is the first (on ``surface_joint``: 0 the fixed world, else
    a moving body; its z the normal), the body's point p the second (the same rotation), as
    the module's docstring says. With a moving surface the rows are C^T (J_body(p) -
    J_surface(p)) v: Pinocchio takes both bodies' velocities at the second point p."""
    point, normal, gap = touching
    frame = contact_frame(normal)
    placed = data.oMi[joint_id]
    surface = data.oMi[surface_joint] if surface_joint else None
    contact = pin.PointContactConstraintModel(
        model,
        surface_joint,
        pin.SE3(frame, point - gap * normal)
        if surface is None
        else surface.actInv(pin.SE3(frame, point - gap * normal)),
        joint_id,
        pin.SE3(placed.rotation.T @ frame, placed.actInv(point)),
    )
    contact.setFriction(friction)
    return evaluated(model, data, contact)
