"""The world's objects and contact forces as drawn (`uvms_pin.physics.world`).

Paths under the scene root: ``world/objects/<name>`` (each drawn as its kind's `Drawing`
says, plain data naming a meshcat geometry: a plane a sandy patch about the scene's centre,
solids grey-brown, meshes as their file's triangles) and ``world/contacts/pair<k>`` (orange arrows, one
per (body, object) pair, at the pair's contact point along the force on the body,
``SceneStyle.world_force_scale_m_per_N`` long per newton). Free objects are drawn under
``world/free/<name>`` (a lighter colour) and move with their logged pose (the
``free_objects`` signal); their own pairs' arrows are ``world/contacts/object<k>``. Fixtures
(``type = "urdf"``) are drawn under ``world/fixtures/<name>``, their links at their logged
joint positions (`uvms_pin.apps.viz.fixture_view`). A node's name is never a bare
number: three.js's animation tracks would read it as an index, and the arrow not move.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import meshcat
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from uvms_pin.apps.viz.fixture_view import FixtureView
from uvms_pin.physics.world.kind import Drawing
from uvms_pin.physics.world.objects import object_kind

__all__ = ["WorldView"]

_SAND, _ROCK, _ARROW, _FREE = 0x8A7A55, 0x807060, 0xFF9020, 0xC8643C
_STATE = 13  # per free object in the free_objects signal: p (3), quaternion (4), nu (6)


def _matrix(rotation, translation) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = np.asarray(rotation, dtype=float)
    out[:3, 3] = np.asarray(translation, dtype=float)
    return out


def _phong(color: int, opacity: float = 1.0) -> mg.MeshPhongMaterial:
    return mg.MeshPhongMaterial(color=color, opacity=opacity, transparent=opacity < 1.0)


_SAND_PATCH = _phong(_SAND, 0.9)


@dataclass(frozen=True)
class WorldView:
    """What a world record (`World.record`) draws.

    Attributes:
        objects: each object's record. pairs: ``body|object`` of each logged pair.
        center_world_m: where the scene is (a plane is drawn as a patch around it).
    """

    objects: tuple[dict[str, Any], ...]
    pairs: tuple[str, ...]
    center_world_m: np.ndarray
    free: tuple[dict[str, Any], ...] = ()
    object_pairs: tuple[str, ...] = ()
    fixtures: tuple[FixtureView, ...] = ()

    @classmethod
    def from_record(cls, record: dict | None, center_world_m) -> WorldView | None:
        kinds = ("objects", "free_objects", "fixtures")
        if not record or not any(record.get(kind) for kind in kinds):
            return None
        return cls(
            tuple(record.get("objects", ())),
            tuple(record.get("pairs", ())),
            np.asarray(center_world_m, dtype=float).reshape(3),
            tuple(record.get("free_objects", ())),
            tuple(record.get("object_pairs", ())),
            tuple(FixtureView.from_record(f) for f in record.get("fixtures", ())),
        )

    @property
    def has_plane(self) -> bool:
        """Some object is unbounded (a seafloor): the scene needs no floor of its own."""
        return any(_drawing(o).unbounded for o in self.objects)

    def build(self, node: meshcat.Visualizer, build_arrow: Callable) -> None:
        """Draw the objects under ``node`` and an arrow per pair (``build_arrow(node,
        color)``)."""
        for obj in self.objects:
            self._build_object(node[f"objects/{obj['name']}"], obj)
        for k in range(len(self.pairs)):
            build_arrow(node[f"contacts/pair{k}"], _ARROW)
        for obj in self.free:
            # the shape in a child node: the parent moves with the pose, the child turns
            # a cylinder (meshcat's lies along y)
            drawing = _drawing(obj)
            child = node[f"free/{obj['name']}/shape"]
            child.set_object(_geometry(drawing), _phong(_FREE))
            child.set_transform(_matrix(drawing.rotation_in_object, drawing.offset_in_object_m))
        for k in range(len(self.object_pairs)):
            build_arrow(node[f"contacts/object{k}"], _ARROW)
        for view in self.fixtures:
            view.build(node[f"fixtures/{view.name}"])

    def fixture_poses(self, joints: Mapping[str, np.ndarray] | None) -> dict[str, Any]:
        """Poses of the fixtures' bodies for one logged row of each fixture's signal (by the
        fixture's name; a fixture without a row: its initial joint positions)."""
        out: dict[str, Any] = {}
        for view in self.fixtures:
            out.update(view.poses(None if joints is None else joints.get(view.name)))
        return out

    def free_poses(self, states: np.ndarray | None) -> dict[str, Any]:
        """Poses of the free objects for one logged row of the ``free_objects`` signal
        (their initial poses without one)."""
        out: dict[str, Any] = {}
        rows = None if states is None else np.asarray(states, dtype=float).reshape(-1, _STATE)
        for k, obj in enumerate(self.free):
            if rows is None:
                position = np.asarray(obj["position_world_m"], dtype=float)
                quat = pin.Quaternion(np.asarray(obj["rotation_world"], dtype=float)).coeffs()
            else:
                position, quat = rows[k, :3], rows[k, 3:7]
            out[f"world/free/{obj['name']}"] = (position.copy(), np.array(quat), np.ones(3))
        return out

    def _build_object(self, node: meshcat.Visualizer, obj: dict[str, Any]) -> None:
        rotation = np.asarray(obj["rotation_world"], dtype=float)
        position = np.asarray(obj["position_world_m"], dtype=float)
        drawing = _drawing(obj)
        if drawing.unbounded:
            # the patch nearest the scene's centre
            normal = rotation[:, 2]
            position = self.center_world_m - ((self.center_world_m - position) @ normal) * normal
        in_object = _matrix(drawing.rotation_in_object, drawing.offset_in_object_m)
        node.set_object(_geometry(drawing), _SAND_PATCH if drawing.unbounded else _phong(_ROCK))
        node.set_transform(_matrix(rotation, position) @ in_object)

    def arrows(
        self, contacts: np.ndarray | None, arrow: Callable, objects: np.ndarray | None = None
    ) -> dict[str, Any]:
        """Poses of the pairs' arrows for one logged row of the ``world_contact`` signal
        (pairs * 9: force [N], point [m], moment) and of ``free_object_contact``
        (``objects``): ``arrow(path, tail, vector)``."""
        out: dict[str, Any] = {}
        for label, names, row in (
            ("pair", self.pairs, contacts),
            ("object", self.object_pairs, objects),
        ):
            rows = None if row is None else np.asarray(row, dtype=float).reshape(-1, 9)
            if rows is not None and len(rows) != len(names):
                rows = None  # a record that does not fit: no arrows rather than wrong ones
            for k in range(len(names)):
                force = None if rows is None else rows[k, :3]
                tail = np.zeros(3) if rows is None else rows[k, 3:6]
                out.update(arrow(f"world/contacts/{label}{k}", tail, force))
        return out


def _drawing(obj: dict[str, Any]) -> Drawing:
    """How an object's record is drawn: its kind's drawing (plain data)."""
    return object_kind(obj["type"]).drawing(obj)


def _geometry(drawing: Drawing) -> mg.Geometry:
    """The meshcat geometry a drawing names, with its arguments."""
    return getattr(mg, drawing.geometry)(*drawing.args)
