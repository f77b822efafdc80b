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
import tempfile
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.catalog import ArmEntry, resolve_arm
from uvms_pin.model.mount.existing_arm import existing_arm
from uvms_pin.model.mount.hull import first_box
from uvms_pin.model.mount.joints import prepare_arm_joints
from uvms_pin.model.mount.links import mark_dry_links, resolve_meshes, strip_undefined_materials
from uvms_pin.model.mount.names import (
    added_names,
    original_name,
    rename_clashes,
    unique_frame_names,
)
from uvms_pin.model.mount.origin import add_fixed_joint
from uvms_pin.model.mount.pose import parse_mount_pose
from uvms_pin.model.mount.selection import select_arm
from uvms_pin.model.mount.text import urdf_text, write_text_file
from uvms_pin.model.mount.tool import (
    REFERENCE_PROBE,
    ProbeTool,
    add_tool_frames,
    tool_axis_in_link,
)
from uvms_pin.model.mount.tree import URDFTree
from uvms_pin.model.resources import find_model
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3, UVMS

__all__ = ["MergedURDF", "MountResult", "merge_urdf", "mount_arm", "mount_arm_detailed"]

_KEEP_TOP_LEVEL = ("link", "joint", "material", "hydrodynamics")


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
    tool: ProbeTool | None = REFERENCE_PROBE,
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
    tool: ProbeTool | None = REFERENCE_PROBE,
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
    removed_links, removed_joints = ([], []) if keep_existing_arm else existing_arm(vehicle)
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
    selection = select_arm(arm, arm_base_link, ee_link, sensor_link)
    base, ee, subtree, chain = selection.base, selection.ee, selection.subtree, selection.chain
    sensor_link = selection.sensor_link
    axis = tool_axis_in_link(arm, tool_axis, chain, ee, apath)

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
        if arm.child_of(n) in subtree and arm.child_of(n) != base
    ]
    locked = prepare_arm_joints(arm_joints, chain, locks, apath)

    # ---- renaming clashes, mesh paths
    vehicle_names = (set(vehicle.links) | set(vehicle.joints)) - set(removed_links + removed_joints)
    frames = unique_frame_names(vehicle_names)
    reserved = added_names(sensor_link=sensor_link, with_tool=tool is not None, ee_link=ee)
    renamed = rename_clashes(arm, arm_links, arm_joints, vehicle_names, reserved)

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
            resolve_meshes(item, vpath, package_dirs, needs_collision=False)
            out.append(item)
    for element in arm.root:
        if element.tag == "material" and element.get("name") not in materials:
            out.append(copy.deepcopy(element))
            materials.add(element.get("name"))
    for link in arm_links:
        has_hydro = link.find("hydrodynamics") is not None or any(
            h.get("link") == original_name(link.get("name"), renamed)
            for h in arm.root.findall("hydrodynamics")
        )
        resolve_meshes(
            link,
            apath,
            package_dirs,
            needs_collision=not has_hydro,
            link_name=original_name(link.get("name"), renamed),
        )
        strip_undefined_materials(link, materials)
        out.append(link)
    dry = mark_dry_links(arm_links, arm, renamed, allow_dry_links)
    for element in arm.root.findall("hydrodynamics"):
        if element.get("link") in subtree:
            item = copy.deepcopy(element)
            item.set("link", renamed.get(item.get("link"), item.get("link")))
            out.append(item)
    out.extend(arm_joints)
    base_new = renamed.get(base, base)
    ee_new = renamed.get(ee, ee)
    add_fixed_joint(out, frames["arm_mount_joint"], vlink, base_new, placement)
    sensor_new = None if sensor_link is None else renamed.get(sensor_link, sensor_link)
    sensor_frame, ee_frame = add_tool_frames(out, frames, ee_new, sensor_new, tool, axis)

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
        hull_box=first_box(vehicle.links[vlink]),
        removed_links=removed_links,
        removed_joints=removed_joints,
    )


def _catalog_entry(arm: str | Path | ArmEntry) -> ArmEntry | None:
    """The catalogue entry ``arm`` names (an ArmEntry, or a name that is not a file)."""
    if isinstance(arm, ArmEntry):
        return resolve_arm(arm)
    if isinstance(arm, str) and not Path(arm).is_file() and Path(arm).suffix.lower() != ".urdf":
        return resolve_arm(arm)  # a catalogue name, else a ParameterError listing them
    return None


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
