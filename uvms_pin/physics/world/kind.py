"""What a kind of world object is, and the one registry of kinds (``[[world.objects]] type``).

A kind is one module of `uvms_pin.physics.world.kinds` that calls `register` with its
`ObjectKind` on import: its scenario keys and their one check (`ObjectKind.check`, where
the object's parameters enter from a scenario or from code: what it returns is trusted
downstream), its coal geometry, its drawing (plain data, `Drawing`), and, when it can
move, its free counterpart (`FreeShape`: mass properties and the hydrodynamic body its
buoyancy, added mass and damping come from). `uvms_pin.physics.world.objects` imports every
kind module (the one list of kinds) and looks kinds up.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from uvms_pin import checks
from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.model.urdf.collision import collision_hydro, collision_piece
from uvms_pin.model.uvms import HydroBody

__all__ = [
    "KINDS",
    "NO_POINTS",
    "SOLID_POSE",
    "Compiled",
    "Drawing",
    "FreeShape",
    "Key",
    "ObjectKind",
    "checked_pose",
    "collision_body",
    "convex_hull",
    "invalid",
    "positive",
    "positive_vector",
    "register",
    "solid_placement",
]

Params = dict[str, Any]

#: a shape of the core made from sizes alone: no points
NO_POINTS = np.zeros((3, 0))


@dataclass(frozen=True)
class Key:
    """One key of a kind's ``[[world.objects]]`` table.

    Attributes:
        name: the key. holds: "number", "vector" (3 numbers) or "path" (a file, relative
            to the scenario's folder). default: its value when absent (None: required).
    """

    name: str
    holds: str = "number"
    default: Any = None


#: the pose keys of every solid (not a plane): its centre and roll-pitch-yaw
SOLID_POSE = (Key("position_world_m", "vector"), Key("rpy_rad", "vector", (0.0, 0.0, 0.0)))


@dataclass(frozen=True)
class Drawing:
    """How the views draw a kind, as plain data.

    Attributes:
        geometry: a geometry of meshcat (three.js), by its class name in
            ``meshcat.geometry``: "Box", "Sphere", "Cylinder" (along its y), "Ellipsoid",
            "TriangularMeshGeometry". args: its constructor's arguments.
        rotation_in_object, offset_in_object_m: the drawn shape's frame in the object's.
        unbounded: drawn about the point of the object's z = 0 plane nearest the scene's
            centre (a plane: a half-space has no extent to draw).
    """

    geometry: str
    args: tuple
    rotation_in_object: np.ndarray = field(default_factory=lambda: np.eye(3))
    offset_in_object_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    unbounded: bool = False


@dataclass(frozen=True)
class FreeShape:
    """What a kind needs to be a free object (a rigid body of its own).

    Attributes:
        mass_properties: params -> (volume [m^3], centre of mass in the object's frame (3,)
            [m], inertia of unit mass about it (3, 3) [m^2]) of the homogeneous solid.
        hydro_body: (link name, params, water density [kg/m^3]) -> the `HydroBody` on the
            object's joint (1) that gives its buoyancy, added mass, damping and hull.
    """

    mass_properties: Callable[[Params], tuple[float, np.ndarray, np.ndarray]]
    hydro_body: Callable[[str, Params, float], HydroBody]


@dataclass(frozen=True)
class Compiled:
    """The kind's shape in the compiled core (src/uvms_core/contact_shapes.hpp).

    Attributes:
        coal_type: the coal class of its shape (a subclass matches too).
        of: coal shape -> (the core's ``ContactKind`` name, sizes, points (3, n)): what
            ``ContactShape.set_geometry`` takes.
    """

    coal_type: type
    of: Callable[[Any], tuple[str, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class ObjectKind:
    """One kind of world object.

    Attributes:
        name: its ``type`` in ``[[world.objects]]``.
        keys: its table's keys (besides name, type, friction, fixed and mass).
        check: (object name, raw values by key) -> its parameters, checked (ParameterError
            naming the key, `invalid`), as plain data: the one check.
        geometry: params -> (coal shape in the object's frame, radius [m] of a sphere
            about its origin holding it, inf: unbounded).
        placement: params -> the object's frame in the world.
        drawing: params -> `Drawing`.
        compiled: its shape in the compiled core.
        free: its free counterpart (None: it cannot be free, e.g. a plane).
    """

    name: str
    keys: tuple[Key, ...]
    check: Callable[[str, Mapping[str, Any]], Params]
    geometry: Callable[[Params], tuple[Any, float]]
    placement: Callable[[Params], pin.SE3]
    drawing: Callable[[Params], Drawing]
    compiled: Compiled
    free: FreeShape | None = None


#: ``type`` -> its kind, filled by each module of `uvms_pin.physics.world.kinds` on import
KINDS: dict[str, ObjectKind] = {}


def register(kind: ObjectKind) -> ObjectKind:
    """Add ``kind`` to `KINDS` (a second kind of the same name is an error)."""
    if kind.name in KINDS:
        raise ParameterError(f"a world-object kind '{kind.name}' is registered already")
    KINDS[kind.name] = kind
    return kind


def invalid(name: str, key: str, what: str) -> ParameterError:
    """The error of object ``name``'s ``key`` (``.key`` names it for the scenario reader)."""
    error = ParameterError(f"object '{name}': {key} {what}")
    error.key = key
    return error


def positive(name: str, key: str, value: Any) -> float:
    """``value`` as a float > 0 and finite, else `invalid`."""
    try:
        checked = checks.number(key, value)
    except ParameterError:
        raise invalid(name, key, f"must be a number, got {value!r}") from None
    if not (np.isfinite(checked) and checked > 0.0):
        raise invalid(name, key, f"must be > 0, got {checked}")
    return checked


def positive_vector(name: str, key: str, value: Any) -> list[float]:
    """``value`` as 3 finite floats > 0, else `invalid`."""
    vector = finite_vector(f"object '{name}' {key}", value, 3)
    return [positive(name, key, v) for v in vector]


def checked_pose(name: str, raw: Mapping[str, Any]) -> Params:
    """A solid's pose keys (`SOLID_POSE`) checked: position (3,) [m], rpy (3,) [rad]."""
    position = finite_vector(f"object '{name}' position_world_m", raw["position_world_m"], 3)
    rpy = finite_vector(f"object '{name}' rpy_rad", raw.get("rpy_rad", (0.0, 0.0, 0.0)), 3)
    return {"position_world_m": position.tolist(), "rpy_rad": rpy.tolist()}


def solid_placement(params: Params) -> pin.SE3:
    """A solid's frame: its centre, turned by its roll-pitch-yaw."""
    rpy = np.asarray(params["rpy_rad"], dtype=float)
    return pin.SE3(pin.rpy.rpyToMatrix(rpy), np.asarray(params["position_world_m"], dtype=float))


#: the least thickness of a convex hull's points, as a fraction of their extent (the ratio
#: of their spread's smallest and largest singular values): flatter ones are refused, for
#: qhull fails on them inside coal and takes the process down (a 0.3 m square 3 nm thick)
LEAST_HULL_THICKNESS = 1e-6


def convex_hull(points_m: np.ndarray) -> coal.Convex:
    """coal's convex hull (qhull) of the points (n, 3). The points it is built from stay
    with it (``hull.built_from_m``): the compiled core builds the same hull from the same
    points (qhull's output depends on their order, not only on the polytope).

    Raises:
        ParameterError: fewer than 4 points, a non-finite one, or points that span no
            volume (thinner than `LEAST_HULL_THICKNESS` of their extent: a plane, a line).
    """
    source = np.array(points_m, dtype=float).reshape(-1, 3)
    if len(source) < 4 or not np.all(np.isfinite(source)):
        raise ParameterError(
            f"a convex hull needs 4 or more finite points, got {len(source)} "
            f"({'all' if np.all(np.isfinite(source)) else 'not all'} finite)"
        )
    spread = np.linalg.svd(source - source.mean(axis=0), compute_uv=False)
    if not spread[2] > LEAST_HULL_THICKNESS * spread[0]:
        # all points one point: no extent to divide by
        thickness = spread[2] / spread[0] if spread[0] > 0.0 else 0.0
        raise ParameterError(
            "a convex hull needs points that span a volume: these are flat (thickness "
            f"{thickness:.2g} of their extent, below {LEAST_HULL_THICKNESS:g}); "
            "give the body a thickness"
        )
    points = coal.StdVec_Vec3s()
    for p in source:
        points.append(p)
    hull = coal.Convex.convexHull(points, True, None)
    hull.built_from_m = source
    return hull


def collision_body(link: str, geometry_xml: str, water_density_kg_m3: float) -> HydroBody:
    """The hydrodynamic body of a URDF ``<collision>`` shape (``geometry_xml``: ``<box
    .../>``, ``<mesh .../>``...) on joint 1, derived as a link's without ``<hydrodynamics>``
    is (`uvms_pin.model.urdf.bodies`): its coefficients at the shape's frame (a mesh's: its
    bounding primitive's), the shape its hull."""
    element = ET.fromstring(f"<collision><geometry>{geometry_xml}</geometry></collision>")
    origin, params = collision_hydro(element, water_density_kg_m3, link, link)
    to_body = origin.inverse()
    piece = collision_piece(element, link, link).placed(to_body.rotation, to_body.translation)
    return HydroBody(f"{link}/collision[0]", 1, origin, params, (piece,))
