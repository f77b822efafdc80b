"""URDF -> `UVMS`: Pinocchio builds the rigid multibody with a free-flyer root, the
hydrodynamic extension is read from the same file (`uvms_pin.model.urdf.bodies`), and what
urdfdom and Pinocchio accept silently is checked here (joint limits, armature, frames)."""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.checks import flag, number
from uvms_pin.errors import ModelError, ModelWarning, ParameterError
from uvms_pin.model.native_stderr import captured_native_stderr
from uvms_pin.model.resources import package_folders
from uvms_pin.model.urdf.bodies import hydro_bodies
from uvms_pin.model.urdf.hydrodynamics import hydro_elements_by_link
from uvms_pin.model.urdf.lift_drag import read_fins
from uvms_pin.model.urdf.read import read_numbers, read_urdf_root, single
from uvms_pin.model.uvms import BODY_DENSITY, DEFAULT_WATER_DENSITY_KG_M3, UVMS, WATER_DENSITY

__all__ = ["DEFAULT_EE_FRAME", "DEFAULT_SENSOR_FRAME", "load_uvms"]

DEFAULT_EE_FRAME = "ee"
DEFAULT_SENSOR_FRAME = "ft_sensor"


def load_uvms(
    urdf_path: str | Path,
    *,
    water_density_kg_m3: float = DEFAULT_WATER_DENSITY_KG_M3,
    ee_frame: str | None = None,
    sensor_frame: str | None = None,
    derive_missing: bool = True,
    allow_dry_links: bool = False,
    package_dirs: Sequence[str | Path] = (),
) -> UVMS:
    """Load a UVMS from a URDF with the hydrodynamic extension.

    Args:
        urdf_path: the URDF file. Its root link becomes the free-flying vehicle.
        water_density_kg_m3: rho [kg/m^3] for buoyancy and derived coefficients.
        ee_frame, sensor_frame: names of the end-effector and force/torque sensor frames;
            a name given must exist. None (default): ``ee`` and ``ft_sensor`` when the file
            has them, else no such frame (a vehicle without an arm loads; a controller or
            environment that needs the end-effector raises, see `UVMS.require_ee_frame`).
        derive_missing: links without a <hydrodynamics> element get coefficients derived
            from their collision primitives (marked ``derived``).
        allow_dry_links: accept links with mass but neither hydrodynamics nor collision
            geometry (they get no hydrodynamic effect) instead of raising.
        package_dirs: directories containing packages (or one, alone), searched first for
            the ``package://`` mesh paths of collision meshes (then the installed
            example-robot-data; see `uvms_pin.model.resources`). Relative mesh paths are relative
            to the URDF's directory.

    Raises:
        ModelError: naming the file, the link and what is wrong.
    """
    if not isinstance(urdf_path, str | Path):
        raise ParameterError(f"urdf_path must be a path to a URDF file, got {urdf_path!r}")
    path = Path(urdf_path)
    where = str(path)
    water_density_kg_m3 = number("water_density_kg_m3", water_density_kg_m3)
    derive_missing = flag("derive_missing", derive_missing)
    allow_dry_links = flag("allow_dry_links", allow_dry_links)
    for name, frame in (("ee_frame", ee_frame), ("sensor_frame", sensor_frame)):
        if frame is not None and not isinstance(frame, str):
            raise ParameterError(f"{name} must be a frame's name (or None), got {frame!r}")
    package_dirs = package_folders(package_dirs)
    if not np.isfinite(water_density_kg_m3) or water_density_kg_m3 <= 0.0:
        raise ParameterError(f"water_density_kg_m3 must be positive, got {water_density_kg_m3}")
    WATER_DENSITY.check("water_density_kg_m3", water_density_kg_m3)
    root = read_urdf_root(path)
    links = {link.get("name"): link for link in root.findall("link")}
    if not links:
        raise ModelError("no <link> elements", path=where)
    hydro_elements = hydro_elements_by_link(root, links, where)
    model = _build_model(path)
    _check_joint_limits(root, where)
    _check_joint_axes(root, where)
    _read_armature(root, model, where)
    bodies = hydro_bodies(
        model,
        links,
        hydro_elements,
        water_density_kg_m3,
        where,
        derive_missing=derive_missing,
        allow_dry_links=allow_dry_links,
        base_dir=path.parent,
        package_dirs=package_dirs,
    )
    uvms = UVMS(
        model=model,
        hydro_bodies=tuple(bodies),
        water_density_kg_m3=float(water_density_kg_m3),
        ee_frame_id=_optional_frame_id(model, ee_frame, DEFAULT_EE_FRAME, where),
        sensor_frame_id=_optional_frame_id(model, sensor_frame, DEFAULT_SENSOR_FRAME, where),
        source=where,
        fins=read_fins(root, model, where),
    )
    uvms.arm_joints  # noqa: B018 - refuses a planar or floating arm joint now, naming it
    _check_densities(uvms, where)
    return uvms


def _check_densities(uvms: UVMS, where: str) -> None:
    """Each body's mass over the water it displaces (links merged onto one joint together):
    refused if no body can be that light or dense, warned if far from usual (`BODY_DENSITY`)."""
    model = uvms.model
    for joint_id in range(1, model.njoints):
        mass, volume = model.inertias[joint_id].mass, uvms.volume_per_joint_m3[joint_id]
        if mass <= 0.0 or volume <= 0.0:
            continue  # a body without mass or volume: warned about where its links are read
        links = [b.name for b in uvms.hydro_bodies if b.joint_id == joint_id]
        what = (
            f"the body on joint '{model.names[joint_id]}' (links {', '.join(links)}): "
            f"{mass:.4g} kg displacing {volume:.4g} m^3, a mean density of"
        )
        density = mass / volume
        refusal = BODY_DENSITY.refusal(density)
        if refusal is not None:
            raise ModelError(f"{what} {refusal}{_dry(uvms, joint_id)}", path=where)
        warning = BODY_DENSITY.warning(density)
        if warning is not None:
            warnings.warn(f"{where}: {what} {warning}", ModelWarning, stacklevel=3)


def _dry(uvms: UVMS, joint_id: int) -> str:
    """What a refusal adds when links of the body displace no water (an imported link its
    source leaves dry, beside a small wet one: a probe): their volume is missing, not a unit
    wrong."""
    dry = [
        b.name for b in uvms.hydro_bodies if b.joint_id == joint_id and b.params.volume_m3 == 0.0
    ]
    if not dry:
        return ""
    return (
        f"; of its links, {', '.join(dry)} displace no water (volume 0): if they are dry in "
        "the source (an imported model's), give them their volume"
    )


def _build_model(path: Path) -> pin.Model:
    """Pinocchio's model of the file, free-flyer root; urdfdom's complaints in the error."""
    try:
        with captured_native_stderr() as urdfdom:  # its errors go into our message
            return pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    except Exception as exc:  # Pinocchio raises ValueError/RuntimeError for bad URDFs
        detail = f" (urdfdom: {urdfdom.text})" if urdfdom.text else ""
        raise ModelError(
            f"Pinocchio could not build the model: {exc}{detail}", path=str(path)
        ) from exc


def _check_joint_limits(root: ET.Element, where: str) -> None:
    """<limit lower upper> of every revolute and prismatic joint: lower <= upper.

    Pinocchio keeps an inverted interval, and clipping into it (initial state, null-space
    target) then gives a configuration outside both bounds.
    """
    for joint in root.findall("joint"):
        limit = single(joint, "limit", where, f"joint {joint.get('name', '?')}")
        if limit is None or joint.get("type") not in ("revolute", "prismatic"):
            continue
        name = f"joint {joint.get('name', '?')}"
        lower = float(read_numbers(limit.get("lower", "0"), 1, "<limit lower>", where, name)[0])
        upper = float(read_numbers(limit.get("upper", "0"), 1, "<limit upper>", where, name)[0])
        if lower > upper:
            raise ModelError(
                f"joint '{joint.get('name', '?')}': <limit> lower = {lower} > upper = {upper}",
                path=where,
            )


def _check_joint_axes(root: ET.Element, where: str) -> None:
    """<axis xyz> of every moving joint: finite and not zero (Pinocchio normalises it; a
    zero axis gives a joint that moves nothing, and a mass matrix singular on it)."""
    for joint in root.findall("joint"):
        axis = single(joint, "axis", where, f"joint {joint.get('name', '?')}")
        if axis is None or joint.get("type") not in ("revolute", "continuous", "prismatic"):
            continue
        name = joint.get("name", "?")
        xyz = read_numbers(axis.get("xyz", "1 0 0"), 3, "<axis xyz>", where, f"joint {name}")
        if not np.linalg.norm(xyz) > 1e-12:
            raise ModelError(
                f"joint '{name}': <axis xyz=\"{axis.get('xyz')}\"> is zero; give the direction "
                "the joint turns about (revolute, continuous) or slides along (prismatic)",
                path=where,
            )


def _read_armature(root: ET.Element, model: pin.Model, where: str) -> None:
    """``<joint><armature value="kg m^2"/></joint>``: reflected rotor inertia of a joint's
    drive (J_rotor N^2), added to the diagonal of M (Pinocchio's ``model.armature``)."""
    for joint in root.findall("joint"):
        element = single(joint, "armature", where, f"joint {joint.get('name', '?')}")
        if element is None:
            continue
        name = joint.get("name", "?")
        value = float(
            read_numbers(element.get("value"), 1, "<armature value>", where, f"joint {name}")[0]
        )
        if value < 0.0:
            raise ModelError(f"joint '{name}': negative armature {value} kg m^2", path=where)
        if not model.existJointName(name):
            raise ModelError(
                f"joint '{name}' with <armature> is not a moving joint of the model", path=where
            )
        joint_model = model.joints[model.getJointId(name)]
        model.armature[joint_model.idx_v : joint_model.idx_v + joint_model.nv] = value


def _optional_frame_id(model: pin.Model, name: str | None, default: str, where: str) -> int | None:
    """The frame ``name`` (must exist), or with None the frame ``default`` if it exists."""
    if name is None:
        return int(model.getFrameId(default)) if model.existFrame(default) else None
    return _frame_id(model, name, where)


def _frame_id(model: pin.Model, name: str, where: str) -> int:
    if not model.existFrame(name):
        names = sorted({f.name for f in model.frames})
        raise ModelError(f"frame '{name}' not found; frames are: {', '.join(names)}", path=where)
    return int(model.getFrameId(name))
