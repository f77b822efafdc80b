"""Fixed objects of the world, in coal's shapes (the collision library Pinocchio links),
of the kinds of `uvms_pin.physics.world.kinds` (one module each: a ``plane``, ``box``,
``sphere``, ``cylinder``, ``mesh``...; `uvms_pin.physics.world.kind` says what a kind
carries): importing this module registers every kind.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import coal
import numpy as np
import pinocchio as pin

import uvms_pin.physics.world.kinds  # noqa: F401 (registers every kind)
from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.contact_law import check_friction
from uvms_pin.physics.world.kind import KINDS, ObjectKind, convex_hull

__all__ = [
    "WorldObject",
    "convex_hull",
    "fixed_object",
    "kind_names",
    "object_kind",
    "plane",
    "registered_kinds",
    "solid",
]


@dataclass(frozen=True)
class WorldObject:
    """One fixed object (built from checked parameters: `fixed_object`).

    Attributes:
        name: for logs and views. kind: its ``type`` (`object_kind`).
        shape: the coal geometry, in the object's frame.
        placement: the object's frame in the world (a plane: its point, z along its normal).
        friction_static, friction_kinetic: mu_s >= mu_k >= 0 against it.
        bound_radius_m: a sphere about the placement holding the object (inf: a plane).
        params: what it was made from (sizes, pose, file), as plain data for records and
            views.
    """

    name: str
    kind: str
    shape: Any
    placement: pin.SE3
    friction_static: float
    friction_kinetic: float
    bound_radius_m: float
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def is_plane(self) -> bool:
        """A half-space (unbounded): it touches a piece by the piece's corners."""
        return isinstance(self.shape, coal.Halfspace)

    @property
    def normal_world(self) -> np.ndarray:
        """A plane's outward unit normal (its frame's z)."""
        return self.placement.rotation[:, 2].copy()

    @property
    def transform(self) -> coal.Transform3s:
        return coal.Transform3s(self.placement.rotation, self.placement.translation)

    def record(self) -> dict[str, Any]:
        """Plain data: what the views draw and a rollout keeps."""
        return {
            "name": self.name,
            "type": self.kind,
            "position_world_m": self.placement.translation.tolist(),
            "rotation_world": self.placement.rotation.tolist(),
            "friction_static": float(self.friction_static),
            "friction_kinetic": float(self.friction_kinetic),
            **self.params,
        }


def kind_names() -> tuple[str, ...]:
    """Every registered ``type``."""
    return tuple(KINDS)


def registered_kinds() -> tuple[ObjectKind, ...]:
    """Every registered kind."""
    return tuple(KINDS.values())


def object_kind(kind: str) -> ObjectKind:
    """The registered kind ``kind`` (ParameterError naming the known ones)."""
    if kind not in KINDS:
        raise ParameterError(f"unknown world-object type '{kind}' (one of {', '.join(KINDS)})")
    return KINDS[kind]


def fixed_object(
    name: str, kind: str, params: dict[str, Any], friction: tuple[float, float]
) -> WorldObject:
    """The fixed object of ``params`` as `ObjectKind.check` returned them (trusted here)
    and friction (mu_s, mu_k) checked by the caller."""
    of = KINDS[kind]
    shape, radius = of.geometry(params)
    return WorldObject(name, kind, shape, of.placement(params), *friction, radius, params)


def checked(name: str, kind: str, raw: Mapping[str, Any], friction: tuple[float, float]):
    """(kind's checked parameters, friction): the one check of an object given in code or
    read from a scenario."""
    check_friction(*friction, f"object '{name}'")
    return object_kind(kind).check(name, raw), (float(friction[0]), float(friction[1]))


def plane(name: str, point_world_m, normal_world, mu_s: float, mu_k: float) -> WorldObject:
    """The half-space below ``point`` along the outward ``normal`` (normalised here)."""
    raw = {"point_world_m": point_world_m, "normal_world": normal_world}
    return fixed_object(name, "plane", *checked(name, "plane", raw, (mu_s, mu_k)))


def solid(
    name: str,
    kind: str,
    sizes: dict[str, Any],
    position_world_m,
    rpy_rad,
    mu_s: float,
    mu_k: float,
) -> WorldObject:
    """A solid of a registered kind (``sizes``: its keys, e.g. a box's ``size_m`` (3,), a
    sphere's ``radius_m``, a mesh's ``path`` and ``scale``) at a pose."""
    raw = {**sizes, "position_world_m": position_world_m, "rpy_rad": rpy_rad}
    return fixed_object(name, kind, *checked(name, kind, raw, (mu_s, mu_k)))
