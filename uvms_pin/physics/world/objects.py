"""Fixed objects of the world, in coal's shapes (the collision library Pinocchio links).

A ``plane`` is a half-space, solid below its point along its outward normal (a tilted
normal gives a slope); a ``box``, ``sphere`` or ``cylinder`` (along its z) is placed by its
centre and roll-pitch-yaw; a ``mesh`` (STL, OBJ, DAE through trimesh) collides as its
convex hull (coal's GJK/EPA give depths and normals of convex shapes; a concave rock is
the hull of its points: model deep concavities as several objects).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.hydro.mesh import load_mesh_geometry
from uvms_pin.physics.world.contact_law import check_friction

__all__ = ["WorldObject", "convex_hull", "plane", "solid"]


@dataclass(frozen=True)
class WorldObject:
    """One fixed object.

    Attributes:
        name: for logs and views. kind: "plane", "box", "sphere", "cylinder" or "mesh".
        shape: the coal geometry, in the object's frame.
        placement: the object's frame in the world (a plane: its point, z along its normal).
        friction_static, friction_kinetic: mu_s >= mu_k >= 0 against it.
        bound_radius_m: a sphere about the placement holding the object (inf: a plane).
        params: what it was made from (sizes, file), as plain data for records and views.
    """

    name: str
    kind: str
    shape: Any
    placement: pin.SE3
    friction_static: float
    friction_kinetic: float
    bound_radius_m: float
    params: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_friction(self.friction_static, self.friction_kinetic, f"object '{self.name}'")

    @property
    def is_plane(self) -> bool:
        return self.kind == "plane"

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


def _frame_with_z(normal: np.ndarray) -> np.ndarray:
    """A rotation whose z axis is the unit vector ``normal``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, normal)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(normal, x), normal])


def plane(name: str, point_world_m, normal_world, mu_s: float, mu_k: float) -> WorldObject:
    """The half-space below ``point`` along the outward ``normal`` (normalised here)."""
    point = finite_vector(f"object '{name}' point_world_m", point_world_m, 3)
    normal = finite_vector(f"object '{name}' normal_world", normal_world, 3)
    size = float(np.linalg.norm(normal))
    if size == 0.0:
        raise ParameterError(f"object '{name}': normal_world must be non-zero")
    normal = normal / size
    shape = coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0)
    placement = pin.SE3(_frame_with_z(normal), point)
    params = {"point_world_m": point.tolist(), "normal_world": normal.tolist()}
    return WorldObject(name, "plane", shape, placement, mu_s, mu_k, np.inf, params)


def solid(
    name: str,
    kind: str,
    sizes: dict[str, Any],
    position_world_m,
    rpy_rad,
    mu_s: float,
    mu_k: float,
) -> WorldObject:
    """A box (``size_m`` (3,)), sphere (``radius_m``), cylinder (``radius_m``,
    ``length_m``, along z) or mesh (``path``: a file; ``scale``) at a pose."""
    position = finite_vector(f"object '{name}' position_world_m", position_world_m, 3)
    rpy = finite_vector(f"object '{name}' rpy_rad", rpy_rad, 3)
    placement = pin.SE3(pin.rpy.rpyToMatrix(rpy), position)
    shape, radius, params = _shape(name, kind, sizes)
    params = {**params, "rpy_rad": rpy.tolist()}
    return WorldObject(name, kind, shape, placement, mu_s, mu_k, radius, params)


def _positive(name: str, what: str, value: float) -> float:
    value = float(value)
    if not (np.isfinite(value) and value > 0.0):
        raise ParameterError(f"object '{name}': {what} must be > 0, got {value}")
    return value


def _shape(name: str, kind: str, sizes: dict[str, Any]) -> tuple[Any, float, dict[str, Any]]:
    """(coal shape, bounding radius about its origin [m], its parameters)."""
    if kind == "box":
        size = finite_vector(f"object '{name}' size_m", sizes["size_m"], 3)
        a, b, c = (_positive(name, "size_m", s) for s in size)
        return coal.Box(a, b, c), 0.5 * float(np.linalg.norm(size)), {"size_m": size.tolist()}
    if kind == "sphere":
        r = _positive(name, "radius_m", sizes["radius_m"])
        return coal.Sphere(r), r, {"radius_m": r}
    if kind == "cylinder":
        r = _positive(name, "radius_m", sizes["radius_m"])
        length = _positive(name, "length_m", sizes["length_m"])
        shape = coal.Cylinder(r, length)
        return shape, float(np.hypot(r, 0.5 * length)), {"radius_m": r, "length_m": length}
    if kind == "mesh":
        path = Path(sizes["path"])
        scale = finite_vector(f"object '{name}' scale", sizes.get("scale", [1.0] * 3), 3)
        vertices = load_mesh_geometry(path, tuple(scale)).vertices_m
        if vertices is None or len(vertices) < 4:
            raise ParameterError(f"object '{name}': the mesh {path} has too few vertices")
        hull = convex_hull(vertices)
        radius = float(np.max(np.linalg.norm(vertices, axis=1)))
        return hull, radius, {"path": str(path), "scale": scale.tolist()}
    raise ParameterError(f"object '{name}': unknown type '{kind}'")


def convex_hull(points_m: np.ndarray) -> coal.Convex:
    """coal's convex hull (qhull) of the points (n, 3). The points it is built from stay
    with it (``hull.built_from_m``): the compiled core builds the same hull from the same
    points (qhull's output depends on their order, not only on the polytope)."""
    source = np.array(points_m, dtype=float).reshape(-1, 3)
    points = coal.StdVec_Vec3s()
    for p in source:
        points.append(p)
    hull = coal.Convex.convexHull(points, True, None)
    hull.built_from_m = source
    return hull
