"""The world as the sensors see it: one `RayCaster` of the fixed objects, the free objects,
the fixtures, the robot's own links (and the other robots') and the free surface, posed from
the system's state when a sensor fires (`Scene.update`), never rebuilt.

- fixed objects (`uvms_pin.physics.world.objects.WorldObject`): a plane as the analytic plane
  seen from its outward side; a box, sphere, cylinder and ellipsoid as themselves; a mesh as
  its file's triangles (`TriangleMesh`: its concavities are seen, though it collides as its
  hull);
- the robot's links: their collision pieces (`uvms_pin.physics.world.robot_geometry`: the
  URDF ``<collision>`` shapes, a box or mesh as its convex hull), each labelled with its
  link, placed by the forward kinematics of q;
- each free object: its pieces at its logged pose (x, y, z, quaternion x, y, z, w);
- each fixture (`uvms_pin.physics.world.fixture.Fixture`): its links' collision pieces,
  labelled ``<fixture>.<link>``, placed by its own forward kinematics at its joints'
  positions (its logged ``<fixture>`` signal; its start until given);
- the other robots of a run of several (``[[robots]]``): their links' collision pieces,
  labelled ``<robot>.<link>``, placed by their own configurations;
- the free surface z = 0, seen from below.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.uvms import UVMS
from uvms_pin.perception.caster import RayCaster, Shape
from uvms_pin.perception.compiled_caster import CompiledCaster, caster_for
from uvms_pin.perception.mesh import TriangleMesh
from uvms_pin.perception.shapes import (
    Convex,
    Cylinder,
    Ellipsoid,
    Plane,
    Sphere,
    box,
    convex_of_points,
)
from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.robot_geometry import RobotPiece, robot_pieces

__all__ = ["SURFACE", "Scene", "add_objects", "scene_of", "shape_of"]

#: the free surface's label name
SURFACE = "surface"

#: flips z: the surface plane's frame, its normal down into the water
_FACING_DOWN = np.diag([1.0, -1.0, -1.0])


def shape_of(geometry: Any) -> Shape:
    """The ray shape of a coal geometry (in the same frame)."""
    if isinstance(geometry, coal.Halfspace):
        return Plane()
    if isinstance(geometry, coal.Box):
        return box(geometry.halfSide)
    if isinstance(geometry, coal.Sphere):
        return Sphere(float(geometry.radius))
    if isinstance(geometry, coal.Ellipsoid):
        return Ellipsoid(tuple(float(r) for r in geometry.radii))
    if isinstance(geometry, coal.Cylinder):
        return Cylinder(float(geometry.radius), 2.0 * float(geometry.halfLength))
    if isinstance(geometry, coal.ConvexBase):
        return convex_of_points(np.asarray(geometry.points(), dtype=float).reshape(-1, 3))
    raise ModelError(f"the sensors cannot see a {type(geometry).__name__}")


def _seen_shape(obj: WorldObject) -> Shape | Convex | TriangleMesh:
    """A fixed object's shape as seen: a mesh file by its triangles, the rest as they collide."""
    if obj.kind == "mesh" and "path" in obj.params:
        from uvms_pin.hydro.mesh import load_mesh_geometry

        found = load_mesh_geometry(Path(obj.params["path"]), tuple(obj.params["scale"]))
        return TriangleMesh(found.vertices_m, found.triangles)
    return shape_of(obj.shape)


def _plane_frame(obj: WorldObject) -> tuple[np.ndarray, np.ndarray]:
    """A plane's frame: its point, z along its outward normal (its placement's)."""
    return obj.placement.rotation.copy(), obj.placement.translation.copy()


def add_objects(caster: RayCaster, objects: Sequence[WorldObject]) -> None:
    """Each fixed object into ``caster``, as it is seen, where it is placed."""
    for obj in objects:
        rotation, position = _plane_frame(obj)
        caster.add(obj.name, _seen_shape(obj), rotation, position)


class Scene:
    """The caster of a UVMS in its world, and where each of its bodies is.

    Args:
        uvms: the robot (its links' collision pieces are seen).
        objects: the fixed objects. free: the free objects (`FreeObject`).
        fixtures: the fixtures (`Fixture`), each seen at its start until `update` moves it.
        others: the other robots of a run of several, (name, UVMS) each, seen at their
            neutral configurations until `update` places them.
        surface: the free surface z = 0 is seen from below.
        backend: "core" (the compiled caster, `uvms_pin.perception.compiled_caster`) or
            "python" (the reference `RayCaster`): chosen here, once, for every sensor of
            the scene.
    """

    def __init__(
        self,
        uvms: UVMS,
        objects: Sequence[WorldObject] = (),
        free: Sequence[Any] = (),
        fixtures: Sequence[Any] = (),
        others: Sequence[tuple[str, UVMS]] = (),
        *,
        surface: bool = True,
        backend: str = "core",
    ):
        self.uvms = uvms
        self.caster: RayCaster = caster_for(backend)
        self.data = uvms.model.createData()
        add_objects(self.caster, objects)
        #: whether the free surface z = 0 is in the scene (a sensor above it is in the air)
        self.has_surface = bool(surface)
        if surface:
            self.caster.add(SURFACE, Plane(), _FACING_DOWN, np.zeros(3))
        names = _link_names(uvms)
        #: the robot's links' names; the planes facing up (the seafloor)
        self.robot_names = tuple(names)
        self.floor_names = {o.name for o in objects if o.is_plane and o.normal_world[2] > 0.1}
        self._robot = self._add_pieces(robot_pieces(uvms, names), names)
        self._free = [
            self._add_pieces(o.pieces, [o.name] * (1 + max((p.body for p in o.pieces), default=0)))
            for o in free
        ]
        #: each fixture's label names -> the fixture's name (a camera's reflectance of a
        #: fixture colours all its links)
        self.fixture_of = {label: f.name for f in fixtures for label in f.piece_names}
        self.fixture_names = tuple(f.name for f in fixtures)
        self._fixtures = [
            (f.uvms.model, f.uvms.model.createData(), self._add_pieces(f.pieces, f.piece_names))
            for f in fixtures
        ]
        for (model, data, pieces), f in zip(self._fixtures, fixtures, strict=True):
            self._place(model, data, pieces, f.q0)
        self._others = []
        #: the other robots' links' label names (a camera shades them as robots)
        self.other_robot_names: tuple[str, ...] = ()
        for name, other in others:
            links = _link_names(other)
            labels = [f"{name}.{link}" for link in links]
            placed = self._add_pieces(robot_pieces(other, links), labels)
            self._others.append((other.model, other.model.createData(), placed))
            self._place(*self._others[-1], other.neutral_configuration())
            self.other_robot_names += tuple(labels)

    def _add_pieces(
        self, pieces: Sequence[RobotPiece], names: Sequence[str]
    ) -> list[tuple[int, RobotPiece]]:
        return [(self.caster.add(names[p.body], shape_of(p.shape)), p) for p in pieces]

    @property
    def compiled(self) -> bool:
        """Whether its casts (and its cameras' shading) run in the compiled core."""
        return isinstance(self.caster, CompiledCaster)

    @property
    def names(self) -> list[str]:
        """Each label's name: label k is ``names[k - 1]`` (0: nothing met)."""
        return self.caster.names

    def update(
        self,
        q: np.ndarray,
        object_poses: Sequence[np.ndarray] = (),
        fixture_positions: Sequence[np.ndarray] | None = None,
        other_robots: Sequence[np.ndarray] | None = None,
    ) -> None:
        """The bodies where the robot's configuration ``q`` (nq,), each free object's pose
        (7,) [m; quaternion x, y, z, w], each fixture's joint positions (its nq,) [rad or
        m] and each other robot's configuration put them (None: the fixtures, the other
        robots stay where they are)."""
        self._place(self.uvms.model, self.data, self._robot, q)
        if fixture_positions is not None:
            for (model, data, pieces), q_f in zip(self._fixtures, fixture_positions, strict=True):
                self._place(model, data, pieces, q_f)
        if other_robots is not None:
            for (model, data, pieces), q_r in zip(self._others, other_robots, strict=True):
                self._place(model, data, pieces, q_r)
        for bodies, pose in zip(self._free, object_poses, strict=True):
            frame = pin.XYZQUATToSE3(np.asarray(pose, dtype=float))
            for index, piece in bodies:
                placed = frame * piece.placement_in_joint
                self.caster.set_pose(index, placed.rotation, placed.translation)

    def _place(self, model: pin.Model, data: pin.Data, pieces, q: np.ndarray) -> None:
        """An articulated body's ``pieces`` where its configuration ``q`` puts them."""
        pin.forwardKinematics(model, data, np.asarray(q, dtype=float))
        for index, piece in pieces:
            placed = data.oMi[piece.joint_id] * piece.placement_in_joint
            self.caster.set_pose(index, placed.rotation, placed.translation)

    def frame_placement(self, frame_id: int) -> pin.SE3:
        """A frame of the robot's model in the world, after `update`."""
        pin.updateFramePlacement(self.uvms.model, self.data, frame_id)
        return self.data.oMf[frame_id]


def _link_names(uvms: UVMS) -> list[str]:
    """The robot's links the sensors see: those with collision pieces (its surface bodies)."""
    return [uvms.hydro_bodies[int(k)].name for k in uvms.surface_bodies.body_index]


def scene_of(
    uvms: UVMS,
    world: Any | None,
    *,
    surface: bool = True,
    backend: str = "core",
    others: Sequence[tuple[str, UVMS]] = (),
) -> Scene:
    """The scene of a robot in its world (`uvms_pin.physics.world.world.World`: its
    objects, free objects and fixtures; or None: the robot alone in open water), with the
    free surface when the water has one, the other robots of a run of several (``others``),
    cast by ``backend`` (the plant's: "core" or "python")."""
    if world is None:
        return Scene(uvms, others=others, surface=surface, backend=backend)
    return Scene(
        uvms, world.objects, world.free, world.fixtures, others, surface=surface, backend=backend
    )
