"""The UVMS and its task drawn in meshcat: one scene shared by the live view and the replay.

What is drawn (paths under ``/meshcat/uvms_pin``):

- ``robot/visuals/<joint>/<geometry>``: the URDF's ``<visual>`` geometry (primitives with
  their materials, meshes), one node per moving body (named after its joint) holding that
  body's geometry at its fixed placement, so that an animation moves a body, not each piece;
- ``robot/collisions/<joint>/<geometry>``: the ``<collision>`` shapes, translucent orange,
  when asked for (``show="collision"`` or ``"both"``);
- ``environment/*``: the spring (anchor sphere + helix from the anchor to the tip) or the
  compliant plane (translucent slab);
- ``forces/measured`` (red) and ``forces/desired`` (green): contact force arrows from the
  tip, ``SceneStyle.force_scale_m_per_N`` long per newton (0.5 m/N by default);
- ``current`` (blue): the water current, above the vehicle, ``current_scale_m_per_m_s`` long
  per m/s (1 m per m/s by default);
- ``trail``: the end-effector path; ``plumb``: a line from the vehicle down to the sea floor;
- ``floor``: a sandy sea floor with a 0.5 m grid ``floor_clearance_m`` below the lowest point
  (not drawn when the world has a seafloor of its own); a deep-water background gradient;
- ``world/*``: the world's objects and contact arrows (`uvms_pin.apps.viz.world_view`).

A scene is static geometry (`UvmsScene.build`) plus, per instant, a pose for each moving
node (`UvmsScene.poses`): position, quaternion (x, y, z, w) and scale. The live view sends
them as transforms, the replay records them as animation tracks.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import meshcat
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import umsgpack

from uvms_pin.apps.viz.robot_view import (
    COLLISION_RGBA,
    Pose,
    body_poses,
    draw_bodies,
    geometry_groups,
)
from uvms_pin.apps.viz.surface import SurfaceView
from uvms_pin.apps.viz.world_view import WorldView
from uvms_pin.errors import VizError
from uvms_pin.model.uvms import UVMS

ROOT = "uvms_pin"
_Y = np.array([0.0, 1.0, 0.0])
_TINY = 1e-6


_RED = 0xE03030
_GREEN = 0x20C040
_BLUE = 0x3080FF
_TRAIL = 0xFFE040


@dataclass(frozen=True)
class SceneStyle:
    """Scales and sizes of the drawn quantities.

    Attributes:
        force_scale_m_per_N: arrow length per newton of contact force [m/N].
        current_scale_m_per_m_s: arrow length per m/s of current [m/(m/s)].
        floor_clearance_m: sea floor this far below the lowest point of the run [m].
        arrow_radius_m: shaft radius of the arrows [m].
        world_force_scale_m_per_N: arrow length per newton of a world contact force [m/N].
    """

    force_scale_m_per_N: float = 0.5
    world_force_scale_m_per_N: float = 0.02
    current_scale_m_per_m_s: float = 1.0
    floor_clearance_m: float = 1.0
    arrow_radius_m: float = 0.008


@dataclass(frozen=True)
class EnvironmentView:
    """What the end-effector touches, as drawn: a spring anchor or a plane."""

    kind: str  # "spring" or "plane"
    point_world_m: np.ndarray  # spring anchor / a point of the plane
    normal_world: np.ndarray | None = None  # plane only: outward unit normal

    @classmethod
    def from_record(
        cls, record: Mapping[str, Any] | None, ee_position0_world_m: np.ndarray
    ) -> EnvironmentView | None:
        """From a contact model's record (`ContactModel.record`, ``metadata['world']`` of a
        rollout). As in `uvms_pin.physics.contact`, a spring or plane not attached yet (no
        anchor or point) is where the tip is at t = 0."""
        if not record:
            return None
        kind = record.get("type")
        where = record.get("anchor_world_m" if kind == "spring" else "point_world_m")
        point = np.asarray(ee_position0_world_m if where is None else where, dtype=float)
        if kind == "spring":
            return cls("spring", point)
        if kind == "plane":
            normal = np.asarray(record["normal_world"], dtype=float)
            return cls("plane", point, normal / np.linalg.norm(normal))
        raise VizError(f"cannot draw an environment of type {kind!r}")


@dataclass
class Frame:
    """One instant to show: configuration and contact forces (world axes, N)."""

    time_s: float
    q: np.ndarray
    force_measured_world_N: np.ndarray | None = None
    force_desired_world_N: np.ndarray | None = None
    world_contact: np.ndarray | None = None  # a row of the rollout's world_contact signal
    free_objects: np.ndarray | None = None  # a row of the free_objects signal (poses)
    object_contact: np.ndarray | None = None  # a row of free_object_contact
    fixtures: Mapping[str, np.ndarray] | None = None  # a row of each fixture's signal, by name


class RecordingWindow:
    """A stand-in for meshcat's ``ViewerWindow`` that records commands instead of sending.

    ``meshcat.Visualizer(window=RecordingWindow())`` draws into a list of msgpack-encoded
    commands that a static page replays in order (see `uvms_pin.apps.viz.replay`).
    """

    def __init__(self, float_precision: str = "single"):
        self.commands: list[bytes] = []
        self._precision = float_precision

    def send(self, command) -> None:
        self.commands.append(umsgpack.packb(command.lower(), force_float_precision=self._precision))


def recording_visualizer() -> tuple[meshcat.Visualizer, RecordingWindow]:
    window = RecordingWindow()
    return meshcat.Visualizer(window=window), window


def quaternion_y_to(direction: np.ndarray) -> np.ndarray:
    """Quaternion (x, y, z, w) of the rotation taking +Y onto ``direction``."""
    norm = float(np.linalg.norm(direction))
    if norm < _TINY:
        return np.array([0.0, 0.0, 0.0, 1.0])
    return pin.Quaternion.FromTwoVectors(_Y, np.asarray(direction) / norm).coeffs().copy()


def pose_matrix(pose: Pose) -> np.ndarray:
    """4x4 homogeneous matrix of a pose (rotation times scale, then translation)."""
    position, quat, scale = pose
    out = np.eye(4)
    rot = pin.Quaternion(quat[3], quat[0], quat[1], quat[2]).toRotationMatrix()
    out[:3, :3] = rot * np.asarray(scale)[None, :]
    out[:3, 3] = position
    return out


def _translation(p) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = p
    return out


def _material(color: int, opacity: float = 1.0, **kw) -> mg.MeshPhongMaterial:
    if opacity < 1.0:
        kw.update(transparent=True, opacity=opacity)
    return mg.MeshPhongMaterial(color=color, **kw)


def _helix(turns: int = 10, radius: float = 0.015, points_per_turn: int = 16) -> np.ndarray:
    """A unit-length helix along +Y (3, N): the spring, stretched by its node's scale."""
    s = np.linspace(0.0, 1.0, turns * points_per_turn + 1)
    angle = 2.0 * math.pi * turns * s
    return np.vstack([radius * np.cos(angle), s, radius * np.sin(angle)]).astype(np.float32)


class UvmsScene:
    """Static geometry and per-instant poses of a UVMS run.

    Args:
        uvms: the model; its URDF (``uvms.source``) provides the visual geometry.
        environment: what the tip touches, or None.
        current_world_m_s: uniform current (3,), drawn when non-zero.
        show_desired: draw the desired-force arrow (a controller that tracks a force).
        extent_world_m: points (N, 3) to keep in view (vehicle and tip over the run); the
            camera, the scene centre and the floor depth follow from them.
        style: scales and sizes.
        visual_model: the geometry to draw; default: the visual elements of the URDF
            ``uvms.source`` (meshes found through ``package_dirs``).
        show: the robot's geometry to draw: ``"visual"`` (the URDF's ``<visual>``
            elements), ``"collision"`` (its ``<collision>`` shapes, translucent orange) or
            ``"both"`` (each group can be hidden in meshcat's controls).
        surface: the free surface (animated waves, or the level z = 0 of still water), or
            None (water without a top: not drawn).
    """

    def __init__(
        self,
        uvms: UVMS,
        *,
        environment: EnvironmentView | None = None,
        current_world_m_s=(0.0, 0.0, 0.0),
        show_desired: bool = False,
        extent_world_m: np.ndarray | None = None,
        style: SceneStyle | None = None,
        visual_model: pin.GeometryModel | None = None,
        package_dirs: tuple[str, ...] = (),
        surface: SurfaceView | None = None,
        world: WorldView | None = None,
        show: str = "visual",
    ):
        self.uvms = uvms
        self.surface = surface
        self.world = world
        self.environment = environment
        self.current_world_m_s = np.asarray(current_world_m_s, dtype=float).reshape(3)
        self.show_forces = environment is not None or show_desired
        self.show_desired = show_desired
        self.style = style or SceneStyle()
        urdf = Path(uvms.source) if uvms.source else None
        #: what is drawn of the robot, by node group ("visuals", "collisions")
        self.geometry = geometry_groups(
            uvms.model, urdf, show, visual_model=visual_model, package_dirs=package_dirs
        )
        self.data = uvms.model.createData()

        points = np.atleast_2d(
            extent_world_m if extent_world_m is not None else uvms.neutral_configuration()[:3]
        )
        if environment is not None:
            points = np.vstack([points, environment.point_world_m])
        lo, hi = points.min(axis=0), points.max(axis=0)
        self.center_world_m = 0.5 * (lo + hi)
        self.floor_z_m = float(lo[2]) - self.style.floor_clearance_m
        size = float(np.max(hi - lo))
        self.camera_distance_m = max(1.1, 0.9 * size + 0.55)

    def legend(self) -> str:
        """What the colours and arrow lengths mean, for what this scene draws."""
        parts = []
        if "collisions" in self.geometry:
            parts.append("collision shapes (translucent orange)")
        if self.show_forces:
            forces = "measured (red)" + (", desired (green)" if self.show_desired else "")
            parts.append(f"contact force: {forces}, {self.style.force_scale_m_per_N:g} m per N")
        if np.linalg.norm(self.current_world_m_s) > _TINY:
            parts.append(f"current (blue): {self.style.current_scale_m_per_m_s:g} m per m/s")
        if self.environment is not None:
            parts.append(
                "spring (orange) to its anchor"
                if self.environment.kind == "spring"
                else "compliant plane (grey)"
            )
        if self.surface is not None:
            parts.append("free surface (translucent blue tiles)")
        if self.world is not None:
            scale = self.style.world_force_scale_m_per_N
            parts.append(f"world contact forces (orange), {scale:g} m per N")
        floor = self.world is None or not self.world.has_plane
        parts.append("tip trail (yellow)" + ("; sea floor 0.5 m grid" if floor else ""))
        return "; ".join(parts)

    # ---- static geometry ---------------------------------------------------------------
    def build(self, vis: meshcat.Visualizer) -> None:
        """Draw everything that does not move, and the camera and background."""
        vis["/Background"].set_property("top_color", [40 / 255, 120 / 255, 170 / 255])
        vis["/Background"].set_property("bottom_color", [4 / 255, 22 / 255, 46 / 255])
        vis["/Grid"].set_property("visible", False)
        vis["/Axes"].set_property("visible", False)
        # orbit about the scene centre: the scene is shifted so that its centre is the origin
        direction = np.array([0.45, -0.85, 0.3])
        offset = self.camera_distance_m * direction / np.linalg.norm(direction)
        # the camera lives in a y-up frame: (x, y, z)_world -> (x, z, -y)
        vis["/Cameras/default/rotated/<object>"].set_property(
            "position", [float(offset[0]), float(offset[2]), float(-offset[1])]
        )
        root = vis[ROOT]
        root.set_transform(_translation(-self.center_world_m))
        self._build_robot(root)
        if self.world is None or not self.world.has_plane:
            self._build_floor(root)
        if self.world is not None:
            self.world.build(root["world"], self._build_arrow)
        self._build_environment(root)
        if self.surface is not None:
            self.surface.build(root)
        if self.show_forces:
            # measured: wide and translucent, so that the desired one shows inside it
            self._build_arrow(root["forces/measured"], _RED, radius_factor=1.8, opacity=0.55)
            if self.show_desired:
                self._build_arrow(root["forces/desired"], _GREEN, radius_factor=0.8)
        if np.linalg.norm(self.current_world_m_s) > _TINY:
            self._build_arrow(root["current"], _BLUE, radius_factor=1.5)
        root["plumb"].set_object(
            mg.Line(
                mg.PointsGeometry(np.array([[0, 0], [0, 0], [0, -1]], dtype=np.float32)),
                mg.LineBasicMaterial(color=0xC0E0FF, transparent=True, opacity=0.6),
            )
        )

    def _build_robot(self, root: meshcat.Visualizer) -> None:
        for group, geometry in self.geometry.items():
            rgba = COLLISION_RGBA if group == "collisions" else None
            draw_bodies(root[f"robot/{group}"], self.uvms.model, geometry, rgba)

    def _build_floor(self, root: meshcat.Visualizer) -> None:
        half = 5.0
        floor = root["floor"]
        floor.set_transform(_translation([*self.center_world_m[:2], self.floor_z_m]))
        floor["sand"].set_object(mg.Box([2 * half, 2 * half, 0.02]), _material(0x8A7A55, 0.85))
        floor["sand"].set_transform(_translation([0.0, 0.0, -0.011]))
        ticks = np.arange(-half, half + 1e-9, 0.5)
        segments = []
        for c in ticks:
            segments += [[c, -half, 0.0], [c, half, 0.0], [-half, c, 0.0], [half, c, 0.0]]
        floor["grid"].set_object(
            mg.LineSegments(
                mg.PointsGeometry(np.array(segments, dtype=np.float32).T),
                mg.LineBasicMaterial(color=0x5A4E35),
            )
        )

    def _build_environment(self, root: meshcat.Visualizer) -> None:
        env = self.environment
        if env is None:
            return
        node = root["environment"]
        if env.kind == "spring":
            node["anchor"].set_object(mg.Sphere(0.03), _material(0x803010))
            node["anchor"].set_transform(_translation(env.point_world_m))
            node["spring"].set_object(
                mg.Line(mg.PointsGeometry(_helix()), mg.LineBasicMaterial(color=0xFFB060))
            )
        else:
            quat = quaternion_y_to(env.normal_world)
            slab = pose_matrix((env.point_world_m, quat, np.ones(3)))
            node["plane"].set_object(mg.Box([1.2, 0.01, 1.2]), _material(0xA0A0A0, 0.35))
            # the slab's -Y face is the surface; it extends behind it (against the normal)
            node["plane"].set_transform(slab @ _translation([0.0, -0.005, 0.0]))

    def _build_arrow(
        self, node: meshcat.Visualizer, color: int, radius_factor=1.0, opacity=1.0
    ) -> None:
        r = self.style.arrow_radius_m * radius_factor
        head = 4.0 * self.style.arrow_radius_m  # the same head length for every arrow
        node["shaft"].set_object(mg.Cylinder(1.0, r), _material(color, opacity))
        node["head"].set_object(
            mg.Cylinder(head, radiusTop=0.0, radiusBottom=2.2 * r), _material(color, opacity)
        )
        node.set_transform(pose_matrix(_hidden()))

    # ---- per instant -------------------------------------------------------------------
    def ee_position(self, q: np.ndarray) -> np.ndarray:
        """The end-effector position (the vehicle origin for a model without one) [m]."""
        return tip_position(self.uvms, self.data, q)

    def poses(self, frame: Frame) -> dict[str, Pose]:
        """Pose of every moving node (paths relative to the scene root) at one instant."""
        model, data = self.uvms.model, self.data
        q = np.asarray(frame.q, dtype=float)
        pin.forwardKinematics(model, data, q)
        out: dict[str, Pose] = {}
        for group, geometry in self.geometry.items():
            out.update(body_poses(model, data, geometry, f"robot/{group}"))
        tip = _tip(self.uvms, self.data)
        base = q[:3]
        if self.environment is not None and self.environment.kind == "spring":
            span = tip - self.environment.point_world_m
            length = max(float(np.linalg.norm(span)), _TINY)
            out["environment/spring"] = (
                self.environment.point_world_m.copy(),
                quaternion_y_to(span),
                np.array([1.0, length, 1.0]),
            )
        if self.show_forces:
            scale = self.style.force_scale_m_per_N
            out.update(self._arrow("forces/measured", tip, frame.force_measured_world_N, scale))
            if self.show_desired:
                out.update(self._arrow("forces/desired", tip, frame.force_desired_world_N, scale))
        if np.linalg.norm(self.current_world_m_s) > _TINY:
            above = base + np.array([0.0, 0.0, 0.35])
            scale = self.style.current_scale_m_per_m_s
            out.update(self._arrow("current", above, self.current_world_m_s, scale))
        depth = max(float(base[2] - self.floor_z_m), _TINY)
        out["plumb"] = (base.copy(), np.array([0.0, 0.0, 0.0, 1.0]), np.array([1.0, 1.0, depth]))
        if self.surface is not None:
            out.update(self.surface.poses(frame.time_s))
        if self.world is not None:
            scale = self.style.world_force_scale_m_per_N
            out.update(
                self.world.arrows(
                    frame.world_contact,
                    lambda path, tail, f: self._arrow(path, tail, f, scale),
                    frame.object_contact,
                )
            )
            out.update(self.world.free_poses(frame.free_objects))
            out.update(self.world.fixture_poses(frame.fixtures))
        return out

    def _arrow(self, path: str, tail, vector, scale: float) -> dict[str, Pose]:
        head_len = 4.0 * self.style.arrow_radius_m
        vector = None if vector is None else np.asarray(vector, dtype=float)[:3]
        length = (
            0.0
            if vector is None or not np.all(np.isfinite(vector))
            else scale * float(np.linalg.norm(vector))
        )
        if length < 1e-4:
            return {
                path: _hidden(),
                f"{path}/shaft": _plain([0.0, 0.0, 0.0], [1.0, _TINY, 1.0]),
                f"{path}/head": _plain([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
            }
        shaft = max(length - head_len, _TINY)
        head = min(1.0, length / head_len)
        return {
            path: (np.asarray(tail, dtype=float).copy(), quaternion_y_to(vector), np.ones(3)),
            f"{path}/shaft": _plain([0.0, 0.5 * shaft, 0.0], [1.0, shaft, 1.0]),
            f"{path}/head": _plain([0.0, shaft + 0.5 * head * head_len, 0.0], [head, head, head]),
        }

    def show(self, vis: meshcat.Visualizer, frame: Frame) -> None:
        """Move every node to its pose at one instant (live view)."""
        root = vis[ROOT]
        for path, pose in self.poses(frame).items():
            root[path].set_transform(pose_matrix(pose))

    @staticmethod
    def trail_object(points_world_m: np.ndarray) -> mg.Line:
        """The end-effector trail through ``points`` (N, 3), as a meshcat line."""
        pts = np.asarray(points_world_m, dtype=np.float32).reshape(-1, 3)
        if len(pts) == 1:
            pts = np.vstack([pts, pts])
        return mg.Line(mg.PointsGeometry(pts.T), mg.LineBasicMaterial(color=_TRAIL))


def _plain(position, scale) -> Pose:
    return (np.asarray(position, float), np.array([0.0, 0.0, 0.0, 1.0]), np.asarray(scale, float))


def _hidden() -> Pose:
    return (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), np.full(3, _TINY))


def tip_position(uvms: UVMS, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """The end-effector position at ``q`` (the vehicle origin for a model without one) [m],
    ``data`` the model's work buffer: what a scene's extent is drawn from, without the
    scene (its geometry is read from the URDF's meshes)."""
    pin.forwardKinematics(uvms.model, data, q)
    return _tip(uvms, data)


def _tip(uvms: UVMS, data: pin.Data) -> np.ndarray:
    if uvms.ee_frame_id is None:
        return data.oMi[1].translation.copy()  # a vehicle alone: trace its origin
    return pin.updateFramePlacement(uvms.model, data, uvms.ee_frame_id).translation.copy()
