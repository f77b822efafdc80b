"""Mount any arm URDF on a vehicle URDF: one UVMS from two files (docs/api.md).

The two files are merged into one URDF, written to a temporary directory and loaded with
:func:`uvms_pin.model.urdf.load.load_uvms`, so the hydrodynamic extension, the derivation of
missing coefficients from collision geometry (meshes included) and every check of the loader
apply unchanged; the temporary file is removed before returning.

What the merge does, in order (`uvms_pin.model.mount.merge`; the module doing each step in
brackets):

1. Checks both trees: every joint names existing links, no link has two parents (a closed
   chain), one root per file. Errors name the file, the link or joint, and what is wrong
   (``tree``).
2. Keeps the arm's subtree below ``arm_base_link`` (default: the arm's root) and chooses the
   end-effector (wrist) link ``ee_link`` if not given: follow the arm from its base while one
   single branch carries moving joints, stop before a branch or a gripper joint (a name with
   finger, gripper, jaw or hand) (``selection``).
3. The arm's moving joints on the path base -> ``ee_link`` are the UVMS joints; every other
   moving joint (gripper fingers, a second branch) is locked (made fixed) at
   ``lock_positions[name]``, default 0 clipped into its limits (with ``moving_jaw=True`` the
   gripper's joints below the wrist keep moving instead, each its own joint, `<mimic>`
   dropped: `uvms_pin.model.jaw`). Continuous joints on the path
   become revolute with limits +-2 pi (so q has one angle per joint, as the rest of uvms-pin
   assumes) (``joints``).
4. Renames the arm's links and joints that clash with the vehicle's (prefix ``arm_``)
   (``names``), resolves every mesh path (``package://``, relative, ``file://``; see
   :mod:`uvms_pin.model.resources`) to an absolute path (``links``), and drops the arm's
   ``<transmission>``, ``<gazebo>`` and other non-kinematic elements.
5. Attaches the arm base to ``vehicle_link`` (default: the vehicle's root) with a fixed joint
   at ``mount_pose`` (``pose``).
6. Adds a fixed F/T sensor frame ``ft_sensor`` at ``ee_link``, its x axis along the tool axis,
   then the tool (a probe like the reference arm's: link ``tool`` with inertial and collision
   cylinder, coefficients derived) and the end-effector frame ``ee`` at its tip, x forward
   along the probe. With ``tool=None`` the ``ee`` frame is the sensor frame (``tool``).
7. Optionally trims the system (:mod:`uvms_pin.model.trim`): foam and ballast links on the
   vehicle (:mod:`uvms_pin.model.trim_urdf`).
"""

from __future__ import annotations

import inspect
import tempfile
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.catalog import ArmEntry, resolve_arm
from uvms_pin.model.mount.merge import ArmMerge, MergedURDF, merge_urdf
from uvms_pin.model.mount.names import RENAME_PREFIX
from uvms_pin.model.mount.text import urdf_text, write_text_file
from uvms_pin.model.resources import find_model
from uvms_pin.model.trim import TrimReport, TrimSpec, plan_trim
from uvms_pin.model.trim_urdf import add_trim_links
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3, UVMS

__all__ = ["MountResult", "mount_arm", "mount_arm_detailed"]


@dataclass(kw_only=True)
class MountResult(ArmMerge):
    """What :func:`mount_arm_detailed` returns: what the merge did with the arm
    (`uvms_pin.model.mount.merge.ArmMerge`'s attributes) and

    Attributes:
        uvms: the mounted system.
        urdf_text: the merged URDF (mesh paths absolute).
        trim: the trim report, or None.
    """

    uvms: UVMS
    urdf_text: str
    trim: object | None = None

    @property
    def derived_bodies(self) -> list[str]:
        """Hydrodynamic bodies whose coefficients were derived from geometry."""
        return [b.name for b in self.uvms.hydro_bodies if b.params.derived]


# ---------------------------------------------------------------------- public functions


def mount_arm(
    vehicle_urdf: str | Path, arm_urdf: str | Path | ArmEntry, mount_pose, **options
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
        options: keywords of :func:`mount_arm_detailed`, e.g. ``arm_base_link`` (the arm
            link bolted to the vehicle; default: the arm's root) and ``ee_link`` (the
            wrist/flange link carrying the F/T sensor; default: chosen, see the module
            docstring).

    Raises:
        ModelError: a file is malformed, a link is unknown, a closed chain, a missing mesh.
        ParameterError: a bad mount pose or tool.
    """
    return mount_arm_detailed(vehicle_urdf, arm_urdf, mount_pose, **options).uvms


#: the keywords `merge_urdf` takes (what mount_arm passes it)
_MERGE_OPTIONS = frozenset(inspect.signature(merge_urdf).parameters)


def mount_arm_detailed(
    vehicle_urdf: str | Path,
    arm_urdf: str | Path | ArmEntry,
    mount_pose,
    *,
    water_density_kg_m3: float = DEFAULT_WATER_DENSITY_KG_M3,
    trim=None,
    trim_joint_positions: Sequence[float] | None = None,
    save_urdf: str | Path | None = None,
    **merge_options,
) -> MountResult:
    """:func:`mount_arm` with every option, returning the UVMS and what was done.

    Args (beyond :func:`mount_arm`'s):
        water_density_kg_m3: passed to ``load_uvms``.
        trim: None/False (no trim), True (default `uvms_pin.model.trim.TrimSpec`) or a TrimSpec:
            add foam and ballast for neutral buoyancy and the chosen BG.
        trim_joint_positions: arm configuration at which to trim (default: neutral).
        save_urdf: also write the merged URDF there (atomically).
        merge_options: how the two files are merged, the keywords of
            :func:`uvms_pin.model.mount.merge.merge_urdf`: ``arm_base_link``, ``ee_link``
            (a catalogue entry's by default), ``vehicle_link``, ``sensor_link``,
            ``tool_axis``, ``tool``, ``lock_positions``, ``package_dirs`` (also passed to
            ``load_uvms``), ``allow_dry_links``, ``keep_existing_arm``, ``moving_jaw``.
    """
    known = _MERGE_OPTIONS - {"vehicle_urdf", "arm_urdf", "mount_pose"}
    unknown = sorted(set(merge_options) - known)
    if unknown:
        raise ParameterError(
            f"mount_arm: unknown option(s) {', '.join(unknown)}; the options are "
            f"water_density_kg_m3, trim, trim_joint_positions, save_urdf, {', '.join(sorted(known))}"
        )
    if save_urdf is not None and not isinstance(save_urdf, str | Path):
        raise ParameterError(f"mount_arm: save_urdf must be a path, got {save_urdf!r}")
    if not (trim is None or isinstance(trim, bool | TrimSpec)):
        raise ParameterError(
            f"mount_arm: trim must be True, False, None or a TrimSpec, got {trim!r}"
        )
    vehicle_urdf = find_model(vehicle_urdf) or vehicle_urdf
    entry = _catalog_entry(arm_urdf)
    if entry is not None:
        arm_urdf = entry.urdf
        for key in ("arm_base_link", "ee_link"):
            if merge_options.get(key) is None:
                merge_options[key] = getattr(entry, key)
    merged = merge_urdf(vehicle_urdf, arm_urdf, mount_pose, **merge_options)
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
        package_dirs=merge_options.get("package_dirs", ()),
    )
    source = f"mount_arm({vehicle_urdf} + {arm_urdf})"
    uvms = _load_merged(merged.root, source, **load_kw)
    report = None
    if trim:
        spec = trim if isinstance(trim, TrimSpec) else TrimSpec()
        report = _add_trim(uvms, merged, spec, trim_joint_positions)
        uvms = _load_merged(merged.root, source, **load_kw)
    text = urdf_text(merged.root)
    if save_urdf is not None:
        write_text_file(save_urdf, text)
    return _result(merged, uvms, text, report)


def _catalog_entry(arm: str | Path | ArmEntry) -> ArmEntry | None:
    """The catalogue entry ``arm`` names (an ArmEntry, or a name that is not a file)."""
    if isinstance(arm, ArmEntry):
        return resolve_arm(arm)
    if isinstance(arm, str) and not Path(arm).is_file() and Path(arm).suffix.lower() != ".urdf":
        return resolve_arm(arm)  # a catalogue name, else a ParameterError listing them
    return None


def _load_merged(root: ET.Element, source: str, **load_kw) -> UVMS:
    """Write the merged tree to a private temporary directory, load it, remove it; errors
    name ``source`` (the two files), not the temporary file."""
    with tempfile.TemporaryDirectory(prefix="uvms_pin_mount_") as tmp:
        path = Path(tmp) / "merged.urdf"
        path.write_text(urdf_text(root))
        try:
            uvms = load_uvms(path, **load_kw)
        except ModelError as exc:
            raise ModelError(str(exc).replace(str(path), source)) from exc
    uvms.source = source
    return uvms


def _add_trim(
    uvms: UVMS,
    merged: MergedURDF,
    spec: TrimSpec,
    trim_joint_positions: Sequence[float] | None,
) -> TrimReport:
    """Plan the trim of ``uvms`` with the arm at ``trim_joint_positions`` [rad or m]
    (default: neutral) and add the foam and ballast links to the merged tree."""
    q = uvms.neutral_configuration()
    if trim_joint_positions is not None:
        joints = np.asarray(trim_joint_positions, dtype=float).reshape(-1)
        if joints.shape != (uvms.n_arm_joints,) or not np.all(np.isfinite(joints)):
            raise ParameterError(
                f"trim_joint_positions needs {uvms.n_arm_joints} finite numbers, got {joints}"
            )
        q[7:] = uvms.arm_joints.configuration(joints)
    report = plan_trim(uvms, q, spec, hull=merged.hull_box)
    add_trim_links(merged.root, merged.vehicle_link, report, RENAME_PREFIX)
    return report


def _result(merged: MergedURDF, uvms: UVMS, text: str, report: TrimReport | None) -> MountResult:
    """The `MountResult` of a merge, the system loaded from it, its text and trim report."""
    arm = {f.name: getattr(merged, f.name) for f in fields(ArmMerge)}
    return MountResult(uvms=uvms, urdf_text=text, trim=report, **arm)
