"""What a DVL needs of the world: its altitude above the bottom. A flat bottom at a depth
(``sensors.dvl.seabed_depth_m``), or the seafloor of the world table: its planes whose
outward normal points up (``[[world.objects]] type = "plane"``, flat or sloping). A DVL
whose beams are cast (``beams = 4``) sees the bottom through `bottom_caster`: the flat
bottom, or every fixed object of the world (its rocks and boxes as well as its planes)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.perception.caster import RayCaster
from uvms_pin.perception.scene import add_objects
from uvms_pin.perception.shapes import Plane
from uvms_pin.physics.world.objects import WorldObject

__all__ = ["FlatSeabed", "PlaneSeabed", "Seabed", "bottom_caster", "world_seabed"]


class Seabed(Protocol):
    """The bottom under a point."""

    def altitude_m(self, position_world_m: np.ndarray) -> float:
        """Height [m] of the point above the bottom straight below it (negative: under it)."""
        ...


@dataclass(frozen=True)
class FlatSeabed:
    """A flat bottom at z = -depth_m (the surface at z = 0, z up)."""

    depth_m: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.depth_m) and self.depth_m > 0.0):
            raise ParameterError(f"sea-bottom depth must be finite and > 0, got {self.depth_m}")

    def altitude_m(self, position_world_m: np.ndarray) -> float:
        return float(position_world_m[2] + self.depth_m)


@dataclass(frozen=True)
class PlaneSeabed:
    """The bottom made of planes n . (x - p0) = 0 (unit normals n with n_z > 0, up out of
    the ground). Straight below x the plane is n . (x - p0) / n_z under it; the bottom is
    the highest of them, so the altitude is their least."""

    points_world_m: tuple[tuple[float, float, float], ...]
    normals_world: tuple[tuple[float, float, float], ...]
    #: the world's fixed objects, all of them (what cast beams see; empty: the planes alone)
    objects: tuple[WorldObject, ...] = field(default=(), compare=False, repr=False)

    def altitude_m(self, position_world_m: np.ndarray) -> float:
        points, normals = np.asarray(self.points_world_m), np.asarray(self.normals_world)
        heights = np.einsum("ij,ij->i", normals, position_world_m - points) / normals[:, 2]
        return float(heights.min())


def world_seabed(objects: Sequence[WorldObject]) -> PlaneSeabed | None:
    """The seafloor of the world's ``objects``: its planes facing up (n_z > 0.1; a wall is
    not a bottom a DVL locks on), or None if it has none."""
    floors = [o for o in objects if o.is_plane and o.normal_world[2] > 0.1]
    if not floors:
        return None
    return PlaneSeabed(
        tuple(tuple(map(float, o.placement.translation)) for o in floors),
        tuple(tuple(map(float, o.normal_world)) for o in floors),
        tuple(objects),
    )


def bottom_caster(seabed: Seabed) -> RayCaster:
    """The bottom as cast beams see it (`uvms_pin.perception.caster`): a flat bottom's plane,
    or a world seafloor's fixed objects (its planes alone when it was given none)."""
    caster = RayCaster()
    if isinstance(seabed, FlatSeabed):
        caster.add("seabed", Plane(), np.eye(3), np.array([0.0, 0.0, -seabed.depth_m]))
    elif isinstance(seabed, PlaneSeabed) and seabed.objects:
        add_objects(caster, seabed.objects)
    elif isinstance(seabed, PlaneSeabed):
        up = np.array([0.0, 0.0, 1.0])
        for k, (point, normal) in enumerate(
            zip(seabed.points_world_m, seabed.normals_world, strict=True)
        ):
            rotation = pin.Quaternion.FromTwoVectors(up, np.asarray(normal)).toRotationMatrix()
            caster.add(f"seabed#{k}", Plane(), rotation, np.asarray(point, dtype=float))
    else:
        raise ParameterError(f"a DVL's beams cannot be cast at a {type(seabed).__name__}")
    return caster
