"""The robot's URDF geometry in meshcat, one node per moving body.

Each geometry object (a ``<visual>`` or ``<collision>`` element: box, cylinder, sphere or
mesh) is drawn under ``<group>/<joint>/<name>``, at its fixed placement in its joint's frame
(mesh scale included); only the body nodes ``<group>/<joint>`` move, to the joint's pose
``oMi``. A body drawn from many pieces (a vehicle's frame, foam, tubes, thrusters) so costs a
replay one animation track, not one per piece.
"""

from __future__ import annotations

import importlib.util
import sys
import warnings
from functools import cache
from pathlib import Path

import meshcat
import numpy as np
import pinocchio as pin

from uvms_pin.errors import VizError

#: what ``show`` may ask for, and the node groups each draws
SHOWN = {"visual": ("visuals",), "collision": ("collisions",), "both": ("visuals", "collisions")}
#: colour of the collision shapes (RGBA): translucent orange over the visuals
COLLISION_RGBA = np.array([1.0, 0.55, 0.1, 0.45])

# (position, quaternion x y z w, scale)
Pose = tuple[np.ndarray, np.ndarray, np.ndarray]


def geometry_groups(
    model: pin.Model,
    urdf: Path | None,
    show: str,
    *,
    visual_model: pin.GeometryModel | None = None,
    package_dirs: tuple[str, ...] = (),
) -> dict[str, pin.GeometryModel]:
    """The geometry to draw, by group (``"visuals"``, ``"collisions"``), as ``show`` asks.

    Args:
        model: the kinematic model the geometry hangs on.
        urdf: the URDF file to read ``<visual>`` / ``<collision>`` from (None: only a given
            ``visual_model`` can be drawn).
        show: ``"visual"``, ``"collision"`` or ``"both"``.
        visual_model: the visual geometry, if already built.
        package_dirs: where ``package://`` and relative mesh paths are looked up.
    """
    if show not in SHOWN:
        raise VizError(f"show={show!r}: expected one of {', '.join(SHOWN)}")
    kinds = {"visuals": pin.GeometryType.VISUAL, "collisions": pin.GeometryType.COLLISION}
    out = {}
    for group in SHOWN[show]:
        if group == "visuals" and visual_model is not None:
            out[group] = visual_model
            continue
        if urdf is None or not urdf.is_file():
            raise VizError(
                f"{urdf}: no URDF file to read the {group[:-1]} geometry from"
                + (" (pass visual_model=)" if group == "visuals" else "")
            )
        # pinocchio looks a relative mesh path up in package_dirs only: the URDF's folder
        # last, so that it resolves as uvms-pin's own reader resolves it (its folder)
        dirs = [*(str(d) for d in package_dirs), str(urdf.parent)]
        try:
            out[group] = pin.buildGeomFromUrdf(model, str(urdf), kinds[group], package_dirs=dirs)
        except ValueError as exc:  # pinocchio: a mesh it cannot find or read
            raise VizError(f"{urdf}: cannot draw its {group}: {exc}") from exc
    return out


@cache
def _body_visualizer() -> type:
    """Pinocchio's meshcat loader (primitives, meshes, URDF colours), its nodes per body.

    ``pinocchio.visualize`` imports all of pinocchio's viewers, among them the viser one,
    which imports trimesh (and with it scipy.spatial and networkx) only to find viser
    missing: 0.7 s of CPU, a third of a replay's start-up, for a module nothing here uses.
    Where viser is not installed (that viewer cannot work) and trimesh is not imported yet,
    trimesh is hidden (``None`` in ``sys.modules`` makes its import fail) while
    pinocchio.visualize is imported, and is importable again after."""
    hide = "trimesh" not in sys.modules and importlib.util.find_spec("viser") is None
    if hide:
        sys.modules["trimesh"] = None  # type: ignore[assignment]
    try:
        from pinocchio.visualize import MeshcatVisualizer
    finally:
        if hide:
            del sys.modules["trimesh"]

    class BodyVisualizer(MeshcatVisualizer):
        def getViewerNodeName(self, geometry_object, geometry_type):
            return f"{self.model.names[geometry_object.parentJoint]}/{geometry_object.name}"

    return BodyVisualizer


def draw_bodies(
    node: meshcat.Visualizer,
    model: pin.Model,
    geometry: pin.GeometryModel,
    rgba: np.ndarray | None = None,
) -> None:
    """Every object of ``geometry`` under ``node[<joint>/<name>]`` at its placement in its
    joint's frame; ``rgba`` overrides the URDF colours (None: keep them)."""
    viz = _body_visualizer()(model, collision_model=None, visual_model=geometry)
    viz.initViewer(viewer=node)
    for obj in geometry.geometryObjects:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an unsupported geometry is skipped, not fatal
            viz.loadViewerGeometryObject(obj, pin.GeometryType.VISUAL, rgba)
        node[viz.getViewerNodeName(obj, pin.GeometryType.VISUAL)].set_transform(
            piece_placement(obj)
        )


def piece_placement(obj: pin.GeometryObject) -> np.ndarray:
    """4x4 transform of a piece in its body's node: its placement in the joint frame, the
    mesh scale applied to its axes."""
    placement = obj.placement.homogeneous.copy()
    placement[:3, :3] *= np.asarray(obj.meshScale, dtype=float)[None, :]
    return placement


def moving_bodies(model: pin.Model, geometry: pin.GeometryModel) -> list[int]:
    """The joints (indices) that carry at least one object of ``geometry``, in order."""
    return sorted({obj.parentJoint for obj in geometry.geometryObjects})


def body_poses(
    model: pin.Model, data: pin.Data, geometry: pin.GeometryModel, prefix: str
) -> dict[str, Pose]:
    """Pose of each body node ``prefix/<joint>`` (world frame, unit scale), from ``data.oMi``
    (forward kinematics done)."""
    out: dict[str, Pose] = {}
    for joint in moving_bodies(model, geometry):
        placement = data.oMi[joint]
        quat = pin.Quaternion(placement.rotation).coeffs().copy()
        out[f"{prefix}/{model.names[joint]}"] = (placement.translation.copy(), quat, np.ones(3))
    return out
