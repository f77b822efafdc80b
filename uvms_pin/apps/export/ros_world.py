"""The world's objects (`uvms_pin.physics.world`) as ROS frames and markers.

A fixed object is a frame of its name placed in ``map`` (``/tf_static``); a free object a
frame of its name that moves (``/tf``, from the ``free_objects`` signal). Each object is
drawn by one ``visualization_msgs/Marker`` in its own frame, as its kind's `Drawing` says:
a box a CUBE, a sphere or ellipsoid a SPHERE (scaled), a cylinder a CYLINDER (along z, as
the object's), a mesh a TRIANGLE_LIST; a plane a thin square patch about the point of the
plane nearest the run's first vehicle position.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.apps.export.ros_messages import header
from uvms_pin.physics.world.kind import Drawing
from uvms_pin.physics.world.objects import object_kind

__all__ = ["FREE_STATE", "markers", "object_pose"]

#: per free object in the ``free_objects`` signal: position (3), quaternion (4), twist (6)
FREE_STATE = 13
_CUBE, _SPHERE, _CYLINDER, _TRIANGLE_LIST = 1, 2, 3, 11
_FIXED_RGBA, _FREE_RGBA = (0.5, 0.44, 0.38, 1.0), (0.78, 0.39, 0.24, 1.0)


def object_pose(record: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """(position [m], quaternion x y z w) of an object's record in the world."""
    rotation = np.asarray(record["rotation_world"], dtype=float)
    position = np.asarray(record["position_world_m"], dtype=float)
    return position, pin.Quaternion(rotation).coeffs().copy()


def _shape(drawing: Drawing) -> tuple[int, list[float], list[dict]]:
    """(marker type, scale, points) of a drawing."""
    args = drawing.args
    if drawing.geometry == "Box":
        return _CUBE, [float(x) for x in args[0]], []
    if drawing.geometry == "Sphere":
        return _SPHERE, [2.0 * float(args[0])] * 3, []
    if drawing.geometry == "Ellipsoid":
        return _SPHERE, [2.0 * float(x) for x in args[0]], []
    if drawing.geometry == "Cylinder":  # (length, radius); the object's axis is its z
        length, radius = float(args[0]), float(args[1])
        return _CYLINDER, [2.0 * radius, 2.0 * radius, length], []
    vertices, faces = np.asarray(args[0], dtype=float), np.asarray(args[1], dtype=int)
    points = [
        {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])} for p in vertices[faces.ravel()]
    ]
    return _TRIANGLE_LIST, [1.0, 1.0, 1.0], points


def _marker(
    time_ns: int, record: dict[str, Any], ident: int, rgba, center_world_m: np.ndarray
) -> dict:
    drawing = object_kind(record["type"]).drawing(record)
    kind, scale, points = _shape(drawing)
    offset = np.asarray(drawing.offset_in_object_m, dtype=float).copy()
    if drawing.unbounded:  # the patch about the plane's point nearest the centre
        position, quaternion = object_pose(record)
        rotation = pin.Quaternion(np.asarray(quaternion)).toRotationMatrix()
        in_object = rotation.T @ (center_world_m - position)
        offset[:2] += in_object[:2]
    rotation = np.eye(3) if kind == _CYLINDER else np.asarray(drawing.rotation_in_object)
    quaternion = pin.Quaternion(rotation).coeffs()
    color = dict(zip("rgba", map(float, rgba), strict=True))
    return {
        "header": header(time_ns, record["name"]),
        "ns": "world",
        "id": ident,
        "type": kind,
        "action": 0,
        "pose": {
            "position": {"x": float(offset[0]), "y": float(offset[1]), "z": float(offset[2])},
            "orientation": dict(zip("xyzw", map(float, quaternion), strict=True)),
        },
        "scale": dict(zip("xyz", scale, strict=True)),
        "color": color,
        "lifetime": {"sec": 0, "nanosec": 0},
        "frame_locked": True,
        "points": points,
        "colors": [],
        "text": "",
        "mesh_resource": "",
        "mesh_use_embedded_materials": False,
    }


def markers(time_ns: int, world: dict[str, Any], center_world_m: np.ndarray) -> dict:
    """``visualization_msgs/MarkerArray`` of every object of a world record (fixed ones
    first, then free ones), each in its own frame."""
    fixed = [(o, _FIXED_RGBA) for o in world.get("objects", ())]
    free = [(o, _FREE_RGBA) for o in world.get("free_objects", ())]
    return {
        "markers": [
            _marker(time_ns, record, k, rgba, center_world_m)
            for k, (record, rgba) in enumerate(fixed + free)
        ]
    }
