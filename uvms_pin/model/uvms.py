"""URDF -> UVMS: the static model (Pinocchio model, per-body hydrodynamics, frames).

Pinocchio builds the rigid multibody with a free-flyer root and merges links attached by
fixed joints into their parent joint's body. The hydrodynamic extension (docs/physics.md)
is read here from the same file; each link's coefficients become a `HydroBody` attached to
the Pinocchio joint that carries the link, with the link's placement in that joint's frame,
so nothing is approximated when links are merged.
"""

from __future__ import annotations

import dataclasses
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError, ModelWarning, ParameterError
from uvms_pin.hydro import geometry
from uvms_pin.hydro.added_mass import added_mass_in_parent
from uvms_pin.hydro.mesh import load_mesh_geometry, mesh_hydro
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.native_stderr import captured_native_stderr
from uvms_pin.model.resources import package_search_path, resolve_resource
from uvms_pin.results.format import numbers_text

DEFAULT_WATER_DENSITY_KG_M3 = 1025.0  # sea water; a parameter of load_uvms, never hidden
DEFAULT_EE_FRAME = "ee"
DEFAULT_SENSOR_FRAME = "ft_sensor"

_HYDRO_TAGS = {"volume", "center_of_buoyancy", "added_mass", "linear_damping", "quadratic_damping"}


@dataclass(frozen=True)
class HydroBody:
    """Hydrodynamic parameters of one link attached to one Pinocchio joint.

    Attributes:
        name: the URDF link (or ``link/collision[k]`` for a derived primitive).
        joint_id: index of the Pinocchio joint whose body carries this link.
        placement_in_joint: SE3 of the hydro frame (where the coefficients are given)
            relative to the joint frame.
        params: coefficients in the hydro frame.
    """

    name: str
    joint_id: int
    placement_in_joint: pin.SE3
    params: HydroParams

    @property
    def action_joint_to_body(self) -> np.ndarray:
        """X (6x6) with nu_body = X nu_joint."""
        return self.placement_in_joint.inverse().action


@dataclass
class UVMS:
    """A loaded underwater vehicle-manipulator system (static model plus a work buffer).

    Attributes:
        model: Pinocchio model, free-flyer root (joint 1) = the vehicle.
        data: Pinocchio data used as a work buffer by the dynamics functions (not
            thread-safe; use `copy()` for one UVMS per thread or process).
        hydro_bodies: every link's hydrodynamic parameters with its joint and placement.
        water_density_kg_m3: rho used for buoyancy and derived coefficients.
        ee_frame_id, sensor_frame_id: Pinocchio frame indices of the end-effector and of
            the wrist force/torque sensor, or None for a model without them (a vehicle
            alone): what needs them asks through `require_ee_frame`.
        source: path of the URDF file.
    """

    model: pin.Model
    hydro_bodies: tuple[HydroBody, ...]
    water_density_kg_m3: float
    ee_frame_id: int | None
    sensor_frame_id: int | None
    source: str = ""
    data: pin.Data = field(init=False, repr=False)
    added_mass_per_joint: np.ndarray = field(init=False, repr=False)
    hydro_bodies_with_damping: tuple[HydroBody, ...] = field(init=False, repr=False)
    volume_per_joint_m3: np.ndarray = field(init=False, repr=False)
    center_of_buoyancy_per_joint_m: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.data = self.model.createData()
        nj = self.model.njoints
        added = np.zeros((nj, 6, 6))
        volume = np.zeros(nj)
        moment = np.zeros((nj, 3))
        for body in self.hydro_bodies:
            p = body.params
            added[body.joint_id] += added_mass_in_parent(p.added_mass, body.action_joint_to_body)
            volume[body.joint_id] += p.volume_m3
            moment[body.joint_id] += p.volume_m3 * body.placement_in_joint.act(
                p.center_of_buoyancy_m
            )
        cob = np.zeros((nj, 3))
        nz = volume > 0.0
        cob[nz] = moment[nz] / volume[nz, None]
        self.added_mass_per_joint = added
        self.volume_per_joint_m3 = volume
        self.center_of_buoyancy_per_joint_m = cob
        self.hydro_bodies_with_damping = tuple(
            b
            for b in self.hydro_bodies
            if np.any(b.params.linear_damping) or np.any(b.params.quadratic_damping)
        )
        # joints that carry added mass: the only ones the mass matrix must visit
        self.joints_with_added_mass = tuple(
            int(j) for j in np.flatnonzero(np.any(added, axis=(1, 2)))
        )
        self.joints_with_volume = tuple(int(j) for j in np.flatnonzero(volume))
        # stacked per-body constants for the vectorized hot path (dynamics._fluid_wrenches)
        damped = self.hydro_bodies_with_damping
        self.damping_joint_ids = np.array([b.joint_id for b in damped], dtype=int)
        self.damping_action = np.array([b.action_joint_to_body for b in damped]).reshape(-1, 6, 6)
        self.damping_rotation_in_joint = np.array(
            [b.placement_in_joint.rotation for b in damped]
        ).reshape(-1, 3, 3)
        self.damping_origin_in_joint_m = np.array(
            [b.placement_in_joint.translation for b in damped]
        ).reshape(-1, 3)
        self.damping_linear = np.array([b.params.linear_damping for b in damped]).reshape(-1, 6, 6)
        self.damping_quadratic = np.array([b.params.quadratic_damping for b in damped]).reshape(
            -1, 6
        )

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_core_dynamics", None)  # the compiled core (C++): rebuilt on first use
        return state

    # ---- sizes and aggregates -------------------------------------------------------
    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    @property
    def n_arm_joints(self) -> int:
        return self.model.nv - 6

    @property
    def mass_kg(self) -> float:
        """Rigid-body mass in air [kg]."""
        return float(sum(inertia.mass for inertia in self.model.inertias))

    @property
    def volume_m3(self) -> float:
        """Total displaced volume [m^3]."""
        return float(self.volume_per_joint_m3.sum())

    @property
    def net_buoyancy_N(self) -> float:
        """Buoyancy minus weight [N]: > 0 floats up, < 0 sinks."""
        g = float(np.linalg.norm(self.model.gravity.linear))
        return (self.water_density_kg_m3 * self.volume_m3 - self.mass_kg) * g

    @property
    def arm_joint_names(self) -> list[str]:
        return list(self.model.names[2:])

    @property
    def has_end_effector(self) -> bool:
        return self.ee_frame_id is not None

    def require_ee_frame(self, needed_by: str) -> int:
        """The end-effector frame index; ModelError naming ``needed_by`` when there is none."""
        if self.ee_frame_id is None:
            raise ModelError(
                f"{needed_by} needs an end-effector frame, and this model has none (a vehicle "
                "without an arm? mount one with uvms_pin.mount_arm, or name the frame with "
                "load_uvms(..., ee_frame=NAME))",
                path=self.source or None,
            )
        return self.ee_frame_id

    def neutral_configuration(self) -> np.ndarray:
        """q at the origin, level, arm at zero (clipped into the joint limits)."""
        q = pin.neutral(self.model)
        lo = self.model.lowerPositionLimit[7:]
        hi = self.model.upperPositionLimit[7:]
        q[7:] = np.clip(q[7:], lo, hi)
        return q

    def copy(self) -> UVMS:
        """An independent UVMS sharing the static parts but with its own work buffer."""
        return dataclasses.replace(self)

    def with_model(self, model: pin.Model) -> UVMS:
        """The same hydrodynamics and frames on another (e.g. re-scaled) Pinocchio model."""
        return dataclasses.replace(self, model=model)

    def with_hydro(self, transform: Callable[[HydroBody], HydroParams]) -> UVMS:
        """A UVMS whose every body's params are replaced by ``transform(body)``."""
        bodies = tuple(dataclasses.replace(b, params=transform(b)) for b in self.hydro_bodies)
        return dataclasses.replace(self, hydro_bodies=bodies)


# ---- loading ----------------------------------------------------------------------------


def read_urdf_root(path: Path) -> ET.Element:
    """The <robot> element of a URDF file; ModelError naming the file otherwise."""
    where = str(path)
    if not path.is_file():
        raise ModelError("file not found", path=where)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ModelError(f"not well-formed XML ({exc})", path=where) from exc
    if root.tag != "robot":
        raise ModelError(f"root element is <{root.tag}>, expected <robot>", path=where)
    return root


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
        package_dirs: directories containing packages, searched first for the
            ``package://`` mesh paths of collision meshes (then the installed
            example-robot-data; see `uvms_pin.model.resources`). Relative mesh paths are relative
            to the URDF's directory.

    Raises:
        ModelError: naming the file, the link and what is wrong.
    """
    path = Path(urdf_path)
    where = str(path)
    if not np.isfinite(water_density_kg_m3) or water_density_kg_m3 <= 0.0:
        raise ParameterError(f"water_density_kg_m3 must be positive, got {water_density_kg_m3}")
    root = read_urdf_root(path)
    links = {link.get("name"): link for link in root.findall("link")}
    if not links:
        raise ModelError("no <link> elements", path=where)
    hydro_elements = _collect_hydro_elements(root, links, where)
    try:
        with captured_native_stderr() as urdfdom:  # its errors go into our message
            model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    except Exception as exc:  # Pinocchio raises ValueError/RuntimeError for bad URDFs
        detail = f" (urdfdom: {urdfdom.text})" if urdfdom.text else ""
        raise ModelError(f"Pinocchio could not build the model: {exc}{detail}", path=where) from exc

    _check_joint_limits(root, where)
    _read_armature(root, model, where)
    bodies: list[HydroBody] = []
    checked: dict[int, list] = {}  # joint -> [mass kg, volume m^3, link names] of wet links
    for name, link in links.items():
        has_inertial = link.find("inertial") is not None
        collisions = link.findall("collision")
        hydro = hydro_elements.get(name)
        if hydro is not None and not has_inertial:
            raise ModelError("has <hydrodynamics> but no <inertial>", path=where, link=name)
        if collisions and not has_inertial:
            raise ModelError("has <collision> geometry but no <inertial>", path=where, link=name)
        if not has_inertial:
            continue  # a frame-only link: no body, no hydrodynamics
        mass_kg = _check_inertial(link.find("inertial"), where, name)
        n_bodies = len(bodies)
        frame_id = model.getFrameId(name, pin.BODY)
        if frame_id >= len(model.frames):
            raise ModelError("not found in the Pinocchio model", path=where, link=name)
        frame = model.frames[frame_id]
        joint_id = int(frame.parentJoint)
        if hydro is not None:
            params = _parse_hydro(hydro, where, name)
            bodies.append(HydroBody(name, joint_id, frame.placement, params))
        elif collisions and derive_missing:
            for k, collision in enumerate(collisions):
                origin, params = _derive_from_collision(
                    collision, water_density_kg_m3, where, name, path.parent, package_dirs
                )
                bodies.append(
                    HydroBody(f"{name}/collision[{k}]", joint_id, frame.placement * origin, params)
                )
        elif not allow_dry_links:
            raise ModelError(
                "has mass but no <hydrodynamics> element and no collision primitive to derive "
                "coefficients from (pass allow_dry_links=True to accept a dry link)",
                path=where,
                link=name,
            )
        if len(bodies) > n_bodies:  # a dry link accepted by allow_dry_links is no surprise
            entry = checked.setdefault(joint_id, [0.0, 0.0, []])
            entry[0] += mass_kg
            entry[1] += sum(b.params.volume_m3 for b in bodies[n_bodies:])
            entry[2].append(name)
    # per rigid body (links merged by fixed joints): a buoyancy link beside a mass link is fine
    for mass_kg, volume_m3, names in checked.values():
        _warn_on_mass_volume_mismatch(mass_kg, volume_m3, where, "', '".join(names))

    return UVMS(
        model=model,
        hydro_bodies=tuple(bodies),
        water_density_kg_m3=float(water_density_kg_m3),
        ee_frame_id=_optional_frame_id(model, ee_frame, DEFAULT_EE_FRAME, where),
        sensor_frame_id=_optional_frame_id(model, sensor_frame, DEFAULT_SENSOR_FRAME, where),
        source=where,
    )


def _check_inertial(inertial: ET.Element, where: str, link: str) -> float:
    """Validate <inertial> ourselves; return the mass [kg].

    Fix: urdfdom only prints to stderr when <mass> or <inertia> is missing or non-numeric,
    and Pinocchio then builds the link with zero mass and/or zero rotational inertia, which
    silently changes the dynamics (or makes M singular). Origin xyz/rpy are checked too.
    """
    _origin(inertial.find("origin"), where, link)
    mass_el = inertial.find("mass")
    if mass_el is None:
        raise ModelError("<inertial> has no <mass>", path=where, link=link)
    mass = _numbers(mass_el.get("value"), 1, "<mass value>", where, link)[0]
    if mass < 0.0:
        raise ModelError(f"negative mass {mass} kg", path=where, link=link)
    inertia_el = inertial.find("inertia")
    if inertia_el is None:
        raise ModelError("<inertial> has no <inertia>", path=where, link=link)
    entries = {
        key: float(_numbers(inertia_el.get(key), 1, f"<inertia {key}>", where, link)[0])
        for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    }
    _check_rotational_inertia(entries, mass, where, link)
    return mass


# Relative slack of the inertia checks: URDF inertias are often printed with 3-4 digits,
# and a flat plate (I3 = I1 + I2 exactly) must not fail on its rounding.
_INERTIA_RELATIVE_TOLERANCE = 1e-3


def _check_rotational_inertia(entries: dict[str, float], mass_kg: float, where: str, link: str):
    """The rotational inertia of a body [kg m^2] must be one a mass distribution can have.

    I = sum m_k (|r_k|^2 1 - r_k r_k^T) gives: principal moments I1 <= I2 <= I3 all >= 0
    (positive semi-definite: zero for a point mass), the triangle inequality
    I1 + I2 >= I3 (I1 + I2 - I3 = 2 sum m_k z_k^2 in the principal frame), and I = 0 when
    the mass is zero. Negative diagonal entries are refused outright.
    """
    matrix = np.array(
        [
            [entries["ixx"], entries["ixy"], entries["ixz"]],
            [entries["ixy"], entries["iyy"], entries["iyz"]],
            [entries["ixz"], entries["iyz"], entries["izz"]],
        ]
    )
    principal = np.linalg.eigvalsh(matrix)
    scale = float(np.max(np.abs(principal)))
    if scale == 0.0:
        return
    moments = "(" + numbers_text(principal, 6, ", ") + ")"
    if mass_kg == 0.0:
        raise ModelError(
            f"zero mass but a rotational inertia (principal moments {moments} kg m^2)",
            path=where,
            link=link,
        )
    negative = [k for k in ("ixx", "iyy", "izz") if entries[k] < 0.0]
    if negative or principal[0] < -_INERTIA_RELATIVE_TOLERANCE * scale:
        raise ModelError(
            f"inertia is not positive semi-definite: principal moments {moments} "
            f"kg m^2{' (negative ' + ', '.join(negative) + ')' if negative else ''}",
            path=where,
            link=link,
        )
    if principal[0] + principal[1] < principal[2] * (1.0 - _INERTIA_RELATIVE_TOLERANCE):
        raise ModelError(
            f"inertia violates the triangle inequality I1 + I2 >= I3: principal moments "
            f"{moments} kg m^2 (no mass distribution has them)",
            path=where,
            link=link,
        )


def _check_joint_limits(root: ET.Element, where: str) -> None:
    """<limit lower upper> of every revolute and prismatic joint: lower <= upper.

    Pinocchio keeps an inverted interval, and clipping into it (initial state, null-space
    target) then gives a configuration outside both bounds.
    """
    for joint in root.findall("joint"):
        limit = joint.find("limit")
        if limit is None or joint.get("type") not in ("revolute", "prismatic"):
            continue
        name = f"joint {joint.get('name', '?')}"
        lower = float(_numbers(limit.get("lower", "0"), 1, "<limit lower>", where, name)[0])
        upper = float(_numbers(limit.get("upper", "0"), 1, "<limit upper>", where, name)[0])
        if lower > upper:
            raise ModelError(
                f"joint '{joint.get('name', '?')}': <limit> lower = {lower} > upper = {upper}",
                path=where,
            )


def _warn_on_mass_volume_mismatch(mass_kg: float, volume_m3: float, where: str, link: str):
    """A link that displaces water but weighs nothing (or the reverse) is legal but rarely
    meant: buoyancy without weight (or weight without buoyancy) on that link."""
    if volume_m3 > 0.0 and mass_kg == 0.0:
        cause = f"displaces {volume_m3:.6g} m^3 of water but has zero mass"
    elif mass_kg > 0.0 and volume_m3 == 0.0:
        cause = f"has {mass_kg:.6g} kg of mass but displaces no water (zero volume)"
    else:
        return
    warnings.warn(f"{where}: link '{link}': {cause}", ModelWarning, stacklevel=3)


def _read_armature(root: ET.Element, model: pin.Model, where: str) -> None:
    """``<joint><armature value="kg m^2"/></joint>``: reflected rotor inertia of a joint's
    drive (J_rotor N^2), added to the diagonal of M (Pinocchio's ``model.armature``)."""
    for joint in root.findall("joint"):
        element = joint.find("armature")
        if element is None:
            continue
        name = joint.get("name", "?")
        value = float(
            _numbers(element.get("value"), 1, "<armature value>", where, f"joint {name}")[0]
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


def _collect_hydro_elements(root: ET.Element, links: dict, where: str) -> dict[str, ET.Element]:
    found: dict[str, ET.Element] = {}
    for name, link in links.items():
        elements = link.findall("hydrodynamics")
        if len(elements) > 1:
            raise ModelError("has more than one <hydrodynamics> element", path=where, link=name)
        if elements:
            found[name] = elements[0]
    for element in root.findall("hydrodynamics"):
        name = element.get("link")
        if name is None:
            raise ModelError('top-level <hydrodynamics> needs a link="NAME" attribute', path=where)
        if name not in links:
            raise ModelError(
                "top-level <hydrodynamics> names a link that does not exist", path=where, link=name
            )
        if name in found:
            raise ModelError("has more than one <hydrodynamics> element", path=where, link=name)
        found[name] = element
    return found


def _numbers(text: str | None, count: int, what: str, where: str, link: str) -> np.ndarray:
    if text is None:
        raise ModelError(f"{what} is missing its value", path=where, link=link)
    try:
        values = np.array([float(tok) for tok in text.split()])
    except ValueError as exc:
        raise ModelError(f"{what} has a non-numeric value '{text}'", path=where, link=link) from exc
    if values.size != count:
        raise ModelError(f"{what} needs {count} numbers, got {values.size}", path=where, link=link)
    if not np.all(np.isfinite(values)):
        raise ModelError(f"{what} has a non-finite value", path=where, link=link)
    return values


def _matrix_6x6(element: ET.Element | None, what: str, where: str, link: str) -> np.ndarray:
    if element is None:
        return np.zeros((6, 6))
    diagonal, matrix = element.get("diagonal"), element.get("matrix")
    if (diagonal is None) == (matrix is None):
        raise ModelError(
            f'<{what}> needs exactly one of diagonal="6 numbers" or matrix="36 numbers"',
            path=where,
            link=link,
        )
    if diagonal is not None:
        values = _numbers(diagonal, 6, f"<{what} diagonal>", where, link)
        if np.any(values < 0.0):
            raise ModelError(
                f"<{what}> diagonal must be >= 0 (magnitudes), got {values.tolist()}",
                path=where,
                link=link,
            )
        return np.diag(values)
    return _numbers(matrix, 36, f"<{what} matrix>", where, link).reshape(6, 6)


def _parse_hydro(element: ET.Element, where: str, link: str) -> HydroParams:
    for child in element:
        if child.tag not in _HYDRO_TAGS:
            raise ModelError(
                f"unknown tag <{child.tag}> in <hydrodynamics>; known: {', '.join(sorted(_HYDRO_TAGS))}",
                path=where,
                link=link,
            )
    volume_el = element.find("volume")
    if volume_el is None:
        raise ModelError("<hydrodynamics> has no <volume>", path=where, link=link)
    volume = float(_numbers(volume_el.get("value"), 1, "<volume value>", where, link)[0])
    if volume < 0.0:
        raise ModelError(f"negative volume {volume} m^3", path=where, link=link)
    cob_el = element.find("center_of_buoyancy")
    cob = (
        np.zeros(3)
        if cob_el is None
        else _numbers(cob_el.get("xyz"), 3, "<center_of_buoyancy xyz>", where, link)
    )
    added = _matrix_6x6(element.find("added_mass"), "added_mass", where, link)
    linear = _matrix_6x6(element.find("linear_damping"), "linear_damping", where, link)
    quad_el = element.find("quadratic_damping")
    quadratic = np.zeros(6)
    if quad_el is not None:
        quadratic = _numbers(
            quad_el.get("diagonal"), 6, "<quadratic_damping diagonal>", where, link
        )
    try:
        return HydroParams(volume, cob, added, linear, quadratic, derived=False, origin="URDF")
    except ParameterError as exc:
        raise ModelError(str(exc), path=where, link=link) from exc


def _origin(element: ET.Element | None, where: str, link: str) -> pin.SE3:
    if element is None:
        return pin.SE3.Identity()
    xyz = _numbers(element.get("xyz", "0 0 0"), 3, "<origin xyz>", where, link)
    rpy = _numbers(element.get("rpy", "0 0 0"), 3, "<origin rpy>", where, link)
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)


def _derive_from_collision(
    collision: ET.Element,
    water_density_kg_m3: float,
    where: str,
    link: str,
    base_dir: Path = Path("."),
    package_dirs: Sequence[str | Path] = (),
) -> tuple[pin.SE3, HydroParams]:
    origin = _origin(collision.find("origin"), where, link)
    geom = collision.find("geometry")
    shape = None if geom is None or len(geom) == 0 else geom[0]
    if shape is None:
        raise ModelError("<collision> has no <geometry> shape", path=where, link=link)
    try:
        if shape.tag == "box":
            size = _numbers(shape.get("size"), 3, "<box size>", where, link)
            return origin, geometry.box_hydro(size, water_density_kg_m3)
        if shape.tag == "cylinder":
            radius = _numbers(shape.get("radius"), 1, "<cylinder radius>", where, link)[0]
            length = _numbers(shape.get("length"), 1, "<cylinder length>", where, link)[0]
            return origin, geometry.cylinder_hydro(radius, length, water_density_kg_m3)
        if shape.tag == "sphere":
            radius = _numbers(shape.get("radius"), 1, "<sphere radius>", where, link)[0]
            return origin, geometry.sphere_hydro(radius, water_density_kg_m3)
        if shape.tag == "mesh":
            # volume and bounding primitive of the mesh (uvms_pin.hydro.mesh)
            filename = shape.get("filename")
            if not filename:
                raise ModelError("<mesh> has no filename", path=where, link=link)
            resolved = resolve_resource(filename, base_dir, package_dirs)
            if resolved is None:
                searched = ", ".join(str(d) for d in package_search_path(package_dirs))
                raise ModelError(
                    f"cannot derive hydrodynamics from collision <mesh>: file '{filename}' not "
                    f"found (relative paths from {base_dir}; package:// searched in: "
                    f"{searched or 'none'}); fix the path, pass package_dirs, or add a "
                    "<hydrodynamics> element",
                    path=where,
                    link=link,
                )
            scale = _numbers(shape.get("scale", "1 1 1"), 3, "<mesh scale>", where, link)
            return origin, mesh_hydro(load_mesh_geometry(resolved, scale), water_density_kg_m3)
    except ParameterError as exc:
        raise ModelError(
            f"cannot derive hydrodynamics from <{shape.tag}>: {exc}", path=where, link=link
        ) from exc
    raise ModelError(
        f"cannot derive hydrodynamics from collision <{shape.tag}> (box, cylinder, sphere and "
        "mesh are supported); add a <hydrodynamics> element",
        path=where,
        link=link,
    )
