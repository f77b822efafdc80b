"""Mount any arm URDF on a vehicle URDF: one UVMS from two files (docs/api.md).

The two files are merged into one URDF, written to a temporary directory and loaded with
:func:`uvms_pin.model.urdf.load.load_uvms`, so the hydrodynamic extension, the derivation of missing
coefficients from collision geometry (meshes included) and every check of the loader apply
unchanged; the temporary file is removed before returning.

What the merge does, in order:

1. Checks both trees: every joint names existing links, no link has two parents (a closed
   chain), one root per file. Errors name the file, the link or joint, and what is wrong.
2. Keeps the arm's subtree below ``arm_base_link`` (default: the arm's root) and chooses the
   end-effector (wrist) link ``ee_link`` if not given: follow the arm from its base while one
   single branch carries moving joints, stop before a branch or a gripper joint (a name with
   finger, gripper, jaw or hand).
3. The arm's moving joints on the path base -> ``ee_link`` are the UVMS joints; every other
   moving joint (gripper fingers, a second branch) is locked (made fixed) at
   ``lock_positions[name]``, default 0 clipped into its limits. Continuous joints on the path
   become revolute with limits +-2 pi (so q has one angle per joint, as the rest of uvms-pin
   assumes).
4. Renames the arm's links and joints that clash with the vehicle's (prefix ``arm_``),
   resolves every mesh path (``package://``, relative, ``file://``; see
   :mod:`uvms_pin.model.resources`) to an absolute path, and drops the arm's ``<transmission>``,
   ``<gazebo>`` and other non-kinematic elements.
5. Attaches the arm base to ``vehicle_link`` (default: the vehicle's root) with a fixed joint
   at ``mount_pose``.
6. Adds a fixed F/T sensor frame ``ft_sensor`` at ``ee_link``, its x axis along the tool axis,
   then the tool (a probe like the reference arm's: link ``tool`` with inertial and collision
   cylinder, coefficients derived) and the end-effector frame ``ee`` at its tip, x forward
   along the probe. With ``tool=None`` the ``ee`` frame is the sensor frame.
7. Optionally trims the system (:mod:`uvms_pin.model.trim`): foam and ballast links on the vehicle.
"""

from __future__ import annotations

import copy
import math
import tempfile
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.catalog import ArmEntry, resolve_arm
from uvms_pin.model.mount.origin import add_fixed_joint, origin_of, set_origin, vector_attribute
from uvms_pin.model.mount.text import urdf_text, write_text_file
from uvms_pin.model.mount.tree import MOVING_JOINT_TYPES, URDFTree
from uvms_pin.model.resources import find_model, resolve_resource
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3, UVMS
from uvms_pin.results.format import numbers_text

__all__ = [
    "MountResult",
    "ProbeTool",
    "hull_box",
    "merge_urdf",
    "mount_arm",
    "mount_arm_detailed",
    "parse_mount_pose",
]

_GRIPPER_WORDS = ("finger", "gripper", "jaw", "hand")
_KEEP_TOP_LEVEL = ("link", "joint", "material", "hydrodynamics")
_CONTINUOUS_LIMIT_RAD = 2.0 * math.pi
_RENAME_PREFIX = "arm_"
_AXES = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
    "-x": (-1.0, 0.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "-z": (0.0, 0.0, -1.0),
}


@dataclass(frozen=True)
class ProbeTool:
    """A rigid probe on the wrist: a solid cylinder along the tool axis, tip = ``ee``.

    Defaults are the reference arm's probe (models/README.md section 3): 0.08 m long,
    radius 8 mm, 50 g (steel-tipped, slightly heavier than the water it displaces).
    """

    length_m: float = 0.08
    radius_m: float = 0.008
    mass_kg: float = 0.05

    def __post_init__(self) -> None:
        for name in ("length_m", "radius_m", "mass_kg"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ParameterError(f"ProbeTool.{name} must be finite and > 0, got {value}")


@dataclass
class MountResult:
    """What :func:`mount_arm_detailed` returns.

    Attributes:
        uvms: the mounted system.
        urdf_text: the merged URDF (mesh paths absolute).
        arm_joints: the arm's moving joints, base to wrist (merged-model names).
        locked_joints: joints made fixed, with the position they were locked at [rad or m].
        renamed: arm names changed to avoid clashes with the vehicle (old -> new).
        arm_base_link, ee_link: the links used (arm file names).
        tool_axis_in_ee_link: unit vector of the tool axis in ``ee_link``'s frame.
        dry_links: arm links with mass but neither hydrodynamics nor collision geometry.
        trim: the trim report, or None.
        removed_links, removed_joints: the arm the vehicle file carried, replaced (empty
            for a vehicle alone or with ``keep_existing_arm=True``).
    """

    uvms: UVMS
    urdf_text: str
    arm_joints: list[str]
    locked_joints: dict[str, float]
    renamed: dict[str, str]
    arm_base_link: str
    ee_link: str
    tool_axis_in_ee_link: np.ndarray
    dry_links: list[str] = field(default_factory=list)
    trim: object | None = None
    removed_links: list[str] = field(default_factory=list)
    removed_joints: list[str] = field(default_factory=list)

    @property
    def derived_bodies(self) -> list[str]:
        """Hydrodynamic bodies whose coefficients were derived from geometry."""
        return [b.name for b in self.uvms.hydro_bodies if b.params.derived]


# ---------------------------------------------------------------------- public functions


def mount_arm(
    vehicle_urdf: str | Path,
    arm_urdf: str | Path | ArmEntry,
    mount_pose,
    *,
    arm_base_link: str | None = None,
    ee_link: str | None = None,
    **kwargs,
) -> UVMS:
    """Mount an arm on a vehicle: one UVMS (the vehicle is the free-flying root).

    When the vehicle file already carries an arm (``models/uvms_lbv150.urdf``), that arm
    is replaced: everything from its first moving joint down, with its ``ft_sensor``,
    ``tool`` and ``ee`` frames, is removed (a ``UserWarning`` and
    `MountResult.removed_links` say what); ``keep_existing_arm=True`` keeps it (two arms,
    the new one's names prefixed ``arm_`` where they clash; ``ee`` is the new arm's).

    Args:
        vehicle_urdf: vehicle URDF (with the hydrodynamic extension or collision geometry),
            or a shipped model name (``"lbv150"``).
        arm_urdf: arm URDF (``package://`` and relative mesh paths are resolved), or a
            catalogue entry: a name (``"ur5"``) or `uvms_pin.model.mount.catalog.ArmEntry` (its
            ``ee_link`` and ``arm_base_link`` are the defaults).
        mount_pose: pose of the arm base in ``vehicle_link``: a ``pin.SE3``, a 4x4
            homogeneous matrix, or ``(xyz, rpy)`` [m, rad].
        arm_base_link: the arm link bolted to the vehicle (default: the arm's root).
        ee_link: the wrist/flange link carrying the F/T sensor (default: chosen, see the
            module docstring).
        **kwargs: see :func:`mount_arm_detailed`.

    Raises:
        ModelError: a file is malformed, a link is unknown, a closed chain, a missing mesh.
        ParameterError: a bad mount pose or tool.
    """
    return mount_arm_detailed(
        vehicle_urdf, arm_urdf, mount_pose, arm_base_link=arm_base_link, ee_link=ee_link, **kwargs
    ).uvms


def mount_arm_detailed(
    vehicle_urdf: str | Path,
    arm_urdf: str | Path | ArmEntry,
    mount_pose,
    *,
    arm_base_link: str | None = None,
    ee_link: str | None = None,
    vehicle_link: str | None = None,
    sensor_link: str | None = None,
    tool_axis: str | Sequence[float] = "auto",
    tool: ProbeTool | None = ProbeTool(),
    lock_positions: Mapping[str, float] | None = None,
    water_density_kg_m3: float = DEFAULT_WATER_DENSITY_KG_M3,
    package_dirs: Sequence[str | Path] = (),
    allow_dry_links: bool = False,
    trim=None,
    trim_joint_positions: Sequence[float] | None = None,
    save_urdf: str | Path | None = None,
    keep_existing_arm: bool = False,
) -> MountResult:
    """:func:`mount_arm` with every option, returning the UVMS and what was done.

    Args (beyond :func:`mount_arm`'s):
        vehicle_link: vehicle link the arm is bolted to (default: the vehicle's root).
        sensor_link: an existing arm link to use as the F/T sensor frame (then no
            ``ft_sensor`` frame is added; with ``tool=None`` and an ``ee_link`` named as
            the end-effector frame, an arm file that already has both is used as it is).
        tool_axis: the tool direction in ``ee_link``'s frame: "x", "-z", ..., a 3-vector,
            or "auto" (the last arm joint's axis, pointing away from the arm).
        tool: the probe to add (None: no tool, ``ee`` = the sensor frame).
        lock_positions: positions of the joints that are locked (default 0, clipped).
        water_density_kg_m3, package_dirs, allow_dry_links: passed to ``load_uvms``.
        trim: None/False (no trim), True (default `uvms_pin.model.trim.TrimSpec`) or a TrimSpec:
            add foam and ballast for neutral buoyancy and the chosen BG.
        trim_joint_positions: arm configuration at which to trim (default: neutral).
        save_urdf: also write the merged URDF there (atomically).
        keep_existing_arm: keep an arm the vehicle file already carries (default: replace it).
    """
    vehicle_urdf = find_model(vehicle_urdf) or vehicle_urdf
    entry = _catalog_entry(arm_urdf)
    if entry is not None:
        arm_urdf = entry.urdf
        arm_base_link = arm_base_link if arm_base_link is not None else entry.arm_base_link
        ee_link = ee_link if ee_link is not None else entry.ee_link
    merged = merge_urdf(
        vehicle_urdf,
        arm_urdf,
        mount_pose,
        arm_base_link=arm_base_link,
        ee_link=ee_link,
        vehicle_link=vehicle_link,
        sensor_link=sensor_link,
        tool_axis=tool_axis,
        tool=tool,
        lock_positions=lock_positions,
        package_dirs=package_dirs,
        allow_dry_links=allow_dry_links,
        keep_existing_arm=keep_existing_arm,
    )
    if merged.removed_links:
        warnings.warn(
            f"mount_arm: replaced the arm {vehicle_urdf} carried: removed joints "
            f"{', '.join(merged.removed_joints)} and links {', '.join(merged.removed_links)} "
            "(keep_existing_arm=True keeps it)",
            UserWarning,
            stacklevel=3,
        )
    load_kw = dict(
        water_density_kg_m3=water_density_kg_m3,
        ee_frame=merged.ee_frame,
        sensor_frame=merged.sensor_frame,
        package_dirs=package_dirs,
    )
    source = f"mount_arm({vehicle_urdf} + {arm_urdf})"
    uvms = _load_text(merged.root, source, **load_kw)
    report = None
    if trim:
        from uvms_pin.model.trim import TrimSpec, plan_trim
        from uvms_pin.model.trim_urdf import add_trim_links

        spec = trim if isinstance(trim, TrimSpec) else TrimSpec()
        q = uvms.neutral_configuration()
        if trim_joint_positions is not None:
            joints = np.asarray(trim_joint_positions, dtype=float).reshape(-1)
            if joints.shape != (uvms.n_arm_joints,) or not np.all(np.isfinite(joints)):
                raise ParameterError(
                    f"trim_joint_positions needs {uvms.n_arm_joints} finite numbers, got {joints}"
                )
            q[7:] = joints
        report = plan_trim(uvms, q, spec, hull=merged.hull_box)
        add_trim_links(merged.root, merged.vehicle_link, report)
        uvms = _load_text(merged.root, source, **load_kw)
    text = urdf_text(merged.root)
    if save_urdf is not None:
        write_text_file(save_urdf, text)
    return MountResult(
        uvms=uvms,
        urdf_text=text,
        arm_joints=merged.arm_joints,
        locked_joints=merged.locked,
        renamed=merged.renamed,
        arm_base_link=merged.arm_base_link,
        ee_link=merged.ee_link,
        tool_axis_in_ee_link=merged.tool_axis,
        dry_links=merged.dry_links,
        trim=report,
        removed_links=merged.removed_links,
        removed_joints=merged.removed_joints,
    )


@dataclass
class MergedURDF:
    """The merged tree and what :func:`mount_arm_detailed` needs to load it."""

    root: ET.Element
    ee_frame: str
    sensor_frame: str
    vehicle_link: str
    arm_joints: list[str]
    locked: dict[str, float]
    renamed: dict[str, str]
    arm_base_link: str
    ee_link: str
    tool_axis: np.ndarray
    dry_links: list[str]
    hull_box: tuple[np.ndarray, np.ndarray] | None
    removed_links: list[str] = field(default_factory=list)
    removed_joints: list[str] = field(default_factory=list)


def merge_urdf(
    vehicle_urdf: str | Path,
    arm_urdf: str | Path,
    mount_pose,
    *,
    arm_base_link: str | None = None,
    ee_link: str | None = None,
    vehicle_link: str | None = None,
    sensor_link: str | None = None,
    tool_axis: str | Sequence[float] = "auto",
    tool: ProbeTool | None = ProbeTool(),
    lock_positions: Mapping[str, float] | None = None,
    package_dirs: Sequence[str | Path] = (),
    allow_dry_links: bool = False,
    keep_existing_arm: bool = False,
) -> MergedURDF:
    """Build the merged URDF tree (steps 1-6 of the module docstring); nothing is written."""
    placement = parse_mount_pose(mount_pose)
    vpath, apath = Path(vehicle_urdf), Path(arm_urdf)
    vehicle = URDFTree.read(vpath)
    arm = URDFTree.read(apath)
    removed_links, removed_joints = ([], []) if keep_existing_arm else _existing_arm(vehicle)
    vlink = (
        vehicle.root_link
        if vehicle_link is None
        else vehicle.require_link(vehicle_link, "vehicle_link")
    )
    if vlink in removed_links:
        raise ModelError(
            f"vehicle_link '{vlink}' belongs to the arm the vehicle file already carries, which "
            "is replaced (pass keep_existing_arm=True to mount on it)",
            path=str(vpath),
            link=vlink,
        )
    base = (
        arm.root_link if arm_base_link is None else arm.require_link(arm_base_link, "arm_base_link")
    )
    subtree = arm.subtree(base)
    if ee_link is None:
        ee = _choose_ee_link(arm, base)
    else:
        ee = arm.require_link(ee_link, "ee_link")
        if ee not in subtree:
            raise ModelError(
                f"ee_link '{ee}' is not below arm_base_link '{base}'", path=str(apath), link=ee
            )
    path_joints = arm.path_joints(base, ee)
    chain = [j for j in path_joints if arm.joints[j].get("type") in MOVING_JOINT_TYPES]
    if not chain:
        raise ModelError(
            f"no moving joint between arm_base_link '{base}' and ee_link '{ee}'", path=str(apath)
        )
    if sensor_link is not None:
        sensor_link = arm.require_link(sensor_link, "sensor_link")
        if sensor_link not in subtree:
            raise ModelError(
                f"sensor_link '{sensor_link}' is not below arm_base_link '{base}'",
                path=str(apath),
                link=sensor_link,
            )

    axis = _tool_axis(arm, tool_axis, chain, ee, apath)

    # ---- the arm's elements, restricted to the subtree, joints converted
    locks = dict(lock_positions or {})
    unknown = sorted(set(locks) - set(arm.joints))
    if unknown:
        raise ModelError(
            f"lock_positions names unknown joint(s): {', '.join(unknown)}", path=str(apath)
        )
    arm_links = [copy.deepcopy(arm.links[n]) for n in arm.link_order if n in subtree]
    arm_joints = [
        copy.deepcopy(arm.joints[n])
        for n in arm.joint_order
        if arm.joints[n].find("child").get("link") in subtree
        and arm.joints[n].find("child").get("link") != base
    ]
    locked: dict[str, float] = {}
    for joint in arm_joints:
        name = joint.get("name")
        kind = joint.get("type")
        if kind in ("floating", "planar"):
            raise ModelError(
                f"joint '{name}' is {kind}: an arm may only have revolute, continuous, "
                "prismatic and fixed joints",
                path=str(apath),
            )
        if kind not in MOVING_JOINT_TYPES and kind != "fixed":
            raise ModelError(f"joint '{name}' has unknown type '{kind}'", path=str(apath))
        if name in chain:
            if joint.find("mimic") is not None:
                joint.remove(joint.find("mimic"))
            if kind == "continuous":
                joint.set("type", "revolute")
                limit = joint.find("limit")
                if limit is None:
                    raise ModelError(
                        f"continuous joint '{name}' has no <limit effort velocity>",
                        path=str(apath),
                    )
                limit.set("lower", repr(-_CONTINUOUS_LIMIT_RAD))
                limit.set("upper", repr(_CONTINUOUS_LIMIT_RAD))
        elif kind in MOVING_JOINT_TYPES:
            locked[name] = _lock(joint, locks.get(name), apath)

    # ---- renaming clashes, mesh paths
    vehicle_names = (set(vehicle.links) | set(vehicle.joints)) - set(removed_links + removed_joints)
    frames = _unique_frame_names(vehicle_names)
    added_names = {"arm_mount_joint", "trim_foam", "trim_foam_joint"}
    added_names |= {"trim_ballast", "trim_ballast_joint"}
    if sensor_link is None:
        added_names |= {"ft_sensor", "ft_sensor_joint"}
    if tool is not None:
        added_names |= {"tool", "tool_joint", "ee", "ee_joint"}
    elif ee != "ee":
        added_names |= {"ee", "ee_joint"}
    renamed: dict[str, str] = {}
    for element in arm_links + arm_joints:
        name = element.get("name")
        if name in vehicle_names or name in added_names:
            new = _RENAME_PREFIX + name
            while new in vehicle_names or new in arm.links or new in arm.joints:
                new = _RENAME_PREFIX + new
            renamed[name] = new
    for element in arm_links + arm_joints:
        if element.get("name") in renamed:
            element.set("name", renamed[element.get("name")])
    for joint in arm_joints:
        for tag in ("parent", "child"):
            el = joint.find(tag)
            el.set("link", renamed.get(el.get("link"), el.get("link")))
        mimic = joint.find("mimic")
        if mimic is not None and mimic.get("joint") in renamed:
            mimic.set("joint", renamed[mimic.get("joint")])

    out = ET.Element(
        "robot", {"name": f"{vehicle.root.get('name', 'vehicle')}+{arm.root.get('name', 'arm')}"}
    )
    materials: set[str] = set()
    dropped = set(removed_links) | set(removed_joints)
    for element in vehicle.root:
        if element.get("name") in dropped or element.get("link") in dropped:
            continue  # the replaced arm (top-level <hydrodynamics link=...> included)
        if element.tag in _KEEP_TOP_LEVEL:
            item = copy.deepcopy(element)
            if item.tag == "material":
                materials.add(item.get("name"))
            _resolve_meshes(item, vpath, package_dirs, needs_collision=False)
            out.append(item)
    for element in arm.root:
        if element.tag == "material" and element.get("name") not in materials:
            out.append(copy.deepcopy(element))
            materials.add(element.get("name"))
    for link in arm_links:
        has_hydro = link.find("hydrodynamics") is not None or any(
            h.get("link") == _original(link.get("name"), renamed)
            for h in arm.root.findall("hydrodynamics")
        )
        _resolve_meshes(
            link,
            apath,
            package_dirs,
            needs_collision=not has_hydro,
            link_name=_original(link.get("name"), renamed),
        )
        _strip_undefined_materials(link, materials)
        out.append(link)
    dry = _mark_dry_links(arm_links, arm, renamed, allow_dry_links)
    for element in arm.root.findall("hydrodynamics"):
        if element.get("link") in subtree:
            item = copy.deepcopy(element)
            item.set("link", renamed.get(item.get("link"), item.get("link")))
            out.append(item)
    out.extend(arm_joints)
    base_new = renamed.get(base, base)
    ee_new = renamed.get(ee, ee)
    add_fixed_joint(out, frames["arm_mount_joint"], vlink, base_new, placement)

    # ---- sensor, tool and end-effector frames
    rot_tool = _rotation_with_x(axis)
    if sensor_link is None:
        sensor_frame = frames["ft_sensor"]
        out.append(ET.Element("link", {"name": sensor_frame}))
        add_fixed_joint(
            out, frames["ft_sensor_joint"], ee_new, sensor_frame, pin.SE3(rot_tool, np.zeros(3))
        )
    else:
        sensor_frame = renamed.get(sensor_link, sensor_link)
    ee_frame = frames["ee"]
    if tool is not None:
        out.append(_probe_link(frames["tool"], tool))
        add_fixed_joint(out, frames["tool_joint"], sensor_frame, frames["tool"], pin.SE3.Identity())
        out.append(ET.Element("link", {"name": ee_frame}))
        tip = pin.SE3(np.eye(3), np.array([tool.length_m, 0, 0]))
        add_fixed_joint(out, frames["ee_joint"], frames["tool"], ee_frame, tip)
    elif ee_new != ee_frame:
        out.append(ET.Element("link", {"name": ee_frame}))
        add_fixed_joint(out, frames["ee_joint"], sensor_frame, ee_frame, pin.SE3.Identity())

    return MergedURDF(
        root=out,
        ee_frame=ee_frame,
        sensor_frame=sensor_frame,
        vehicle_link=vlink,
        arm_joints=[renamed.get(j, j) for j in chain],
        locked={renamed.get(k, k): v for k, v in locked.items()},
        renamed=renamed,
        arm_base_link=base,
        ee_link=ee,
        tool_axis=axis,
        dry_links=dry,
        hull_box=_box_of(vehicle.links[vlink]),
        removed_links=removed_links,
        removed_joints=removed_joints,
    )


_ADDED_FRAMES = ("arm_mount_joint", "ft_sensor", "ft_sensor_joint", "tool", "tool_joint", "ee")
_ADDED_FRAMES += ("ee_joint",)


def _unique_frame_names(taken: set[str]) -> dict[str, str]:
    """The names of the frames the mount adds (``ee``, ``ft_sensor``, ...), prefixed with
    ``arm_`` while the vehicle already uses them (a kept arm has its own)."""
    out = {}
    for name in _ADDED_FRAMES:
        new = name
        while new in taken:
            new = _RENAME_PREFIX + new
        out[name] = new
    return out


def _existing_arm(vehicle: URDFTree) -> tuple[list[str], list[str]]:
    """(links, joints) of the arm a vehicle file already carries: everything below each
    first moving joint (one without a moving joint above it), and the ``ft_sensor``,
    ``tool`` and ``ee`` frames wherever they hang; empty for a vehicle alone."""
    starts = []
    for name in vehicle.joint_order:
        if vehicle.joints[name].get("type") in MOVING_JOINT_TYPES and not vehicle.moving_above(
            name
        ):
            starts.append(vehicle.child_of(name))
    starts += [f for f in ("ft_sensor", "tool", "ee") if f in vehicle.parent_joint]
    links: set[str] = set()
    for start in starts:
        links.update(vehicle.subtree(start))
    ordered_links = [n for n in vehicle.link_order if n in links]
    joints = [n for n in vehicle.joint_order if vehicle.child_of(n) in links]
    return ordered_links, joints


def _catalog_entry(arm: str | Path | ArmEntry) -> ArmEntry | None:
    """The catalogue entry ``arm`` names (an ArmEntry, or a name that is not a file)."""
    if isinstance(arm, ArmEntry):
        return resolve_arm(arm)
    if isinstance(arm, str) and not Path(arm).is_file() and Path(arm).suffix.lower() != ".urdf":
        return resolve_arm(arm)  # a catalogue name, else a ParameterError listing them
    return None


def hull_box(urdf: str | Path, link: str | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, full size) [m] of the first box collision of ``link`` (default: the root) in
    that link's frame, or None: the hull envelope used by the trim and the reach check."""
    tree = URDFTree.read(Path(urdf))
    name = tree.root_link if link is None else tree.require_link(link, "link")
    return _box_of(tree.links[name])


def parse_mount_pose(mount_pose) -> pin.SE3:
    """A ``pin.SE3`` from an SE3, a 4x4 matrix or ``(xyz, rpy)``.

    Raises:
        ParameterError: non-finite numbers, wrong shapes, or a rotation that is not
            orthonormal with determinant +1.
    """
    if isinstance(mount_pose, pin.SE3):
        rotation, translation = np.array(mount_pose.rotation), np.array(mount_pose.translation)
    else:
        try:
            if isinstance(mount_pose, tuple | list) and len(mount_pose) == 2:
                xyz = np.asarray(mount_pose[0], dtype=float).reshape(-1)
                rpy = np.asarray(mount_pose[1], dtype=float).reshape(-1)
                if xyz.shape != (3,) or rpy.shape != (3,):
                    raise ParameterError(
                        f"mount_pose (xyz, rpy) needs 3 + 3 numbers, got {xyz.size} + {rpy.size}"
                    )
                if not (np.all(np.isfinite(xyz)) and np.all(np.isfinite(rpy))):
                    raise ParameterError(f"mount_pose has a non-finite value: {xyz}, {rpy}")
                return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)
            matrix = np.asarray(mount_pose, dtype=float)
        except ParameterError:
            raise
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"mount_pose is not a pose: {mount_pose!r}") from exc
        if matrix.shape != (4, 4):
            raise ParameterError(
                f"mount_pose must be a pin.SE3, a 4x4 matrix or (xyz, rpy), got shape {matrix.shape}"
            )
        if not np.allclose(matrix[3], [0.0, 0.0, 0.0, 1.0]) and np.all(np.isfinite(matrix)):
            raise ParameterError(f"mount_pose last row must be [0 0 0 1], got {matrix[3]}")
        rotation, translation = matrix[:3, :3], matrix[:3, 3]
    if not (np.all(np.isfinite(rotation)) and np.all(np.isfinite(translation))):
        raise ParameterError("mount_pose has a non-finite value")
    deviation = float(np.max(np.abs(rotation.T @ rotation - np.eye(3))))
    if deviation > 1e-6 or np.linalg.det(rotation) < 0.0:
        raise ParameterError(
            "mount_pose rotation is not a rotation matrix (orthonormal, det +1): "
            f"max |R^T R - I| = {deviation:.3g}, det = {np.linalg.det(rotation):.6g}"
        )
    return pin.SE3(rotation, translation)


def _choose_ee_link(arm: URDFTree, base: str) -> str:
    """Follow the single branch that carries moving joints; stop before grippers."""
    current, last_moving_child = base, None
    while True:
        branches = []
        for joint in arm.children[current]:
            child = arm.child_of(joint)
            moving = arm.is_moving(joint)
            if moving or arm.moving_below(child):
                branches.append((joint, child, moving))
        if len(branches) != 1:
            break
        joint, child, moving = branches[0]
        if moving and any(w in joint.lower() for w in _GRIPPER_WORDS):
            break
        current = child
        if moving:
            last_moving_child = child
    if last_moving_child is None:
        raise ModelError(f"no moving joint below arm_base_link '{base}'", path=str(arm.path))
    return last_moving_child


def _original(name: str, renamed: dict[str, str]) -> str:
    for old, new in renamed.items():
        if new == name:
            return old
    return name


def _lock(joint: ET.Element, position: float | None, path: Path) -> float:
    """Make a moving joint fixed at ``position`` (default 0 clipped into its limits)."""
    name = joint.get("name")
    limit = joint.find("limit")
    lower = -math.inf if limit is None else float(limit.get("lower", "-inf"))
    upper = math.inf if limit is None else float(limit.get("upper", "inf"))
    if joint.get("type") == "continuous":
        lower, upper = -math.inf, math.inf
    value = float(np.clip(0.0 if position is None else position, lower, upper))
    if position is not None and not (math.isfinite(position) and lower <= position <= upper):
        raise ParameterError(
            f"lock position {position} of joint '{name}' is outside its limits [{lower}, {upper}]"
        )
    axis = vector_attribute(joint.find("axis"), "xyz", "1 0 0", path, name)
    axis = axis / np.linalg.norm(axis)
    origin = origin_of(joint, path)
    if joint.get("type") == "prismatic":
        motion = pin.SE3(np.eye(3), axis * value)
    else:
        motion = pin.SE3(pin.exp3(axis * value), np.zeros(3))
    set_origin(joint, origin * motion)
    joint.set("type", "fixed")
    for tag in ("limit", "mimic", "dynamics", "safety_controller", "calibration", "axis"):
        for element in joint.findall(tag):
            joint.remove(element)
    return value


def _probe_link(name: str, tool: ProbeTool) -> ET.Element:
    """A solid cylinder along x from the origin: inertial and collision (hydro derived)."""
    r, length, m = tool.radius_m, tool.length_m, tool.mass_kg
    ixx = 0.5 * m * r * r
    iyy = m * (3.0 * r * r + length * length) / 12.0
    link = ET.Element("link", {"name": name})
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", {"xyz": numbers_text([length / 2, 0, 0]), "rpy": "0 0 0"})
    ET.SubElement(inertial, "mass", {"value": repr(m)})
    ET.SubElement(
        inertial,
        "inertia",
        {"ixx": repr(ixx), "iyy": repr(iyy), "izz": repr(iyy), "ixy": "0", "ixz": "0", "iyz": "0"},
    )
    for tag in ("visual", "collision"):
        el = ET.SubElement(link, tag)
        ET.SubElement(
            el,
            "origin",
            {"xyz": numbers_text([length / 2, 0, 0]), "rpy": numbers_text([0, math.pi / 2, 0])},
        )
        geom = ET.SubElement(el, "geometry")
        ET.SubElement(geom, "cylinder", {"radius": repr(r), "length": repr(length)})
    return link


def _tool_axis(arm: URDFTree, tool_axis, chain: list[str], ee: str, path: Path) -> np.ndarray:
    if isinstance(tool_axis, str):
        if tool_axis in _AXES:
            return np.array(_AXES[tool_axis])
        if tool_axis != "auto":
            raise ParameterError(
                f"tool_axis must be 'auto', one of {', '.join(_AXES)} or a 3-vector, got {tool_axis!r}"
            )
        return _auto_tool_axis(arm, chain, ee, path)
    axis = np.asarray(tool_axis, dtype=float).reshape(-1)
    norm = float(np.linalg.norm(axis)) if axis.shape == (3,) else 0.0
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or norm == 0.0:
        raise ParameterError(f"tool_axis must be a non-zero finite 3-vector, got {tool_axis!r}")
    return axis / norm


def _placement_in(arm: URDFTree, link: str, joints: list[str], path: Path) -> dict[str, pin.SE3]:
    """Placements (zero configuration) of every link on the path, relative to its start."""
    out = {}
    current = pin.SE3.Identity()
    for joint in joints:
        current = current * origin_of(arm.joints[joint], path)
        out[arm.child_of(joint)] = current
    return out


def _auto_tool_axis(arm: URDFTree, chain: list[str], ee: str, path: Path) -> np.ndarray:
    """The last chain joint's axis in ``ee``'s frame, pointing away from the arm."""
    last = chain[-1]
    base = arm.joints[chain[0]].find("parent").get("link")
    joints = arm.path_joints(base, ee)
    placements = _placement_in(arm, ee, joints, path)
    joint_frame = placements[arm.child_of(last)]  # the last joint's frame (zero position)
    ee_frame = placements[ee]
    axis_joint = vector_attribute(arm.joints[last].find("axis"), "xyz", "1 0 0", path, last)
    axis_world = joint_frame.rotation @ (axis_joint / np.linalg.norm(axis_joint))
    if len(chain) > 1:
        prev = placements[arm.child_of(chain[-2])].translation
    else:
        prev = np.zeros(3)
    away = ee_frame.translation - prev
    if float(axis_world @ away) < 0.0:
        axis_world = -axis_world
    axis = ee_frame.rotation.T @ axis_world
    return axis / np.linalg.norm(axis)


def _rotation_with_x(axis: np.ndarray) -> np.ndarray:
    """A rotation whose x column is ``axis`` (the y column as close to the link's y as it can)."""
    x = axis / np.linalg.norm(axis)
    helper = np.array([0.0, 1.0, 0.0]) if abs(x[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    y = helper - (helper @ x) * x
    y /= np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


def _resolve_meshes(
    link: ET.Element,
    urdf: Path,
    package_dirs: Sequence[str | Path],
    *,
    needs_collision: bool,
    link_name: str | None = None,
) -> None:
    """Make mesh paths absolute; a missing collision mesh that is needed is an error;
    a missing visual mesh is dropped (it only matters for drawing)."""
    for tag in ("visual", "collision"):
        for element in list(link.findall(tag)):
            mesh = element.find("geometry/mesh")
            if mesh is None:
                continue
            filename = mesh.get("filename", "")
            resolved = resolve_resource(filename, urdf.parent, package_dirs)
            if resolved is not None:
                mesh.set("filename", str(resolved.resolve()))
            elif tag == "collision" and needs_collision:
                raise ModelError(
                    f"collision mesh '{filename}' not found (relative paths from {urdf.parent}; "
                    "package:// in package_dirs and the installed example-robot-data)",
                    path=str(urdf),
                    link=link_name or link.get("name"),
                )
            else:
                link.remove(element)


def _strip_undefined_materials(link: ET.Element, materials: set[str]) -> None:
    for visual in link.findall("visual"):
        material = visual.find("material")
        if material is not None and len(material) == 0 and material.get("name") not in materials:
            visual.remove(material)


def _box_of(link: ET.Element) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, full size) of the first box collision of a link, or None."""
    for collision in link.findall("collision"):
        box = collision.find("geometry/box")
        if box is None:
            continue
        origin = collision.find("origin")
        xyz = (
            np.zeros(3)
            if origin is None
            else np.array([float(t) for t in origin.get("xyz", "0 0 0").split()])
        )
        size = np.array([float(t) for t in box.get("size").split()])
        return xyz, size
    return None


def _mark_dry_links(
    links: list[ET.Element], arm: URDFTree, renamed: dict[str, str], allow_dry_links: bool
) -> list[str]:
    """Give links with an <inertial> but no geometry and no hydrodynamics an explicit empty
    ``<hydrodynamics>`` (volume 0): always for massless frame links, and for links with mass
    when ``allow_dry_links`` (returned: they weigh but displace nothing). Links with mass
    are otherwise left for `load_uvms` to reject, naming them."""
    top_level = {h.get("link") for h in arm.root.findall("hydrodynamics")}
    dry = []
    for link in links:
        name = link.get("name")
        inertial = link.find("inertial")
        if (
            inertial is None
            or link.find("collision") is not None
            or link.find("hydrodynamics") is not None
            or _original(name, renamed) in top_level
        ):
            continue
        mass_el = inertial.find("mass")
        try:
            mass = float(mass_el.get("value")) if mass_el is not None else math.nan
        except (TypeError, ValueError):
            continue  # load_uvms reports the bad <mass>
        if mass == 0.0 or (allow_dry_links and math.isfinite(mass)):
            ET.SubElement(link, "hydrodynamics").append(ET.Element("volume", {"value": "0"}))
            if mass > 0.0:
                dry.append(name)
    return dry


def _load_text(root: ET.Element, source: str, **load_kw) -> UVMS:
    """Write the merged tree to a private temporary directory, load it, remove it."""
    with tempfile.TemporaryDirectory(prefix="uvms_pin_mount_") as tmp:
        path = Path(tmp) / "merged.urdf"
        path.write_text(urdf_text(root))
        try:
            uvms = load_uvms(path, **load_kw)
        except ModelError as exc:
            raise ModelError(str(exc).replace(str(path), source)) from exc
    uvms.source = source
    return uvms
