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
import tempfile
import warnings
import xml.etree.ElementTree as ET
from functools import cache
from pathlib import Path

import meshcat
import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelWarning, VizError
from uvms_pin.model.resources import resolve_resource

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
            out[group] = _without_missing_meshes(model, urdf, group, kinds[group], dirs, exc)
    return out


def _without_missing_meshes(
    model: pin.Model, urdf: Path, group: str, kind, dirs: list[str], error: ValueError
) -> pin.GeometryModel:
    """The ``group`` geometry of ``urdf`` without the pieces whose mesh file is not found
    (a model whose meshes stayed behind: an imported one, a copied file), each named in a
    `ModelWarning`: the rest of the robot is drawn. VizError (``error``'s) when no mesh is
    missing, or the rest cannot be drawn either."""
    root = ET.parse(urdf).getroot()
    tag = group[:-1]  # "visual", "collision"
    missing: list[str] = []
    stand_ins = 0
    for link in root.iter("link"):
        pieces = link.findall(tag)
        lost = [piece for piece in pieces if not _found(piece, urdf, dirs)]
        for piece in lost:
            link.remove(piece)
            missing.append(
                f"link '{link.get('name')}': {piece.find('geometry/mesh').get('filename')}"
            )
        if tag == "visual" and lost and len(lost) == len(pieces):
            # nothing left to see of the link: its collision shapes stand in
            for shape in link.findall("collision"):
                if _found(shape, urdf, dirs):
                    stand_in = ET.SubElement(link, "visual")
                    stand_in.extend(list(shape))
                    stand_ins += 1
    if not missing:
        raise VizError(f"{urdf}: cannot draw its {group}: {error}") from error
    with tempfile.TemporaryDirectory() as folder:
        kept = Path(folder) / urdf.name
        ET.ElementTree(root).write(kept)
        try:
            geometry = pin.buildGeomFromUrdf(model, str(kept), kind, package_dirs=dirs)
        except ValueError as exc:
            raise VizError(f"{urdf}: cannot draw its {group}: {exc}") from exc
    shown = "; ".join(missing[:5]) + (f"; and {len(missing) - 5} more" if len(missing) > 5 else "")
    instead = (
        f"; {stand_ins} collision shape(s) drawn for links left with none" if stand_ins else ""
    )
    warnings.warn(
        f"{urdf}: {len(missing)} {tag} mesh file(s) not found, drawn without them "
        f"({shown}){instead}",
        ModelWarning,
        stacklevel=3,
    )
    return geometry


def _found(piece: ET.Element, urdf: Path, dirs: list[str]) -> bool:
    """Whether a ``<visual>`` or ``<collision>`` can be drawn as far as its file goes: a
    primitive, or a mesh whose file is found."""
    mesh = piece.find("geometry/mesh")
    return mesh is None or resolve_resource(mesh.get("filename", ""), urdf.parent, dirs) is not None


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
