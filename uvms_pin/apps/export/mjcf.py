"""MJCF (MuJoCo's XML) of a UVMS: the same rigid multibody, MuJoCo's fluid model, buoyancy.

What is the same as in uvms-pin (tests/apps/export/test_mjcf.py checks it against Pinocchio):

- one MuJoCo body per Pinocchio joint, at the joint placement, with the joint's axis, its
  armature and its (merged) spatial inertia; the free-flyer root becomes a ``<freejoint>``;
  the end-effector and sensor frames become sites;
- buoyancy: each joint body with displaced volume V gets a jointless *carrier* body at its
  centre of buoyancy b (the volume-weighted centroid of its hydro bodies: the buoyancy forces
  are parallel, so their sum is exactly rho V g at b). The carrier is a point mass
  m_c = f m taken out of the body's inertia (I_body - I_point(m_c, b): body + carrier have
  exactly the body's spatial inertia, so M and the weight are unchanged) with
  ``gravcomp = rho V / m_c``: MuJoCo's gravity compensation pushes it up by
  gravcomp m_c g = rho V g at b, the buoyancy force;
- the paper's spring f = k (p - p0) (isotropic k) is a spatial tendon from the end-effector
  site to an anchor site with zero rest length.

What differs (MuJoCo's fluid model is another, approximate model):

- the water acts through MuJoCo's ellipsoid model (``fluidshape="ellipsoid"``) on one geom
  per collision shape (box, cylinder, sphere; a mesh as its oriented bounding box) with
  water's density and viscosity: blunt and slender drag, angular drag, Kutta and Magnus
  lift, viscous resistance and the velocity terms of added mass. It has no added-mass
  *acceleration* term (nothing enters M), and its coefficients come from the shapes, not
  from the URDF's damping matrices. A body with mass but no collision shape gets MuJoCo's
  inertia-box fluid model instead (carriers: a point mass, whose box is of zero size);
- a uniform current is MuJoCo's ``opt.wind`` (the medium's velocity), set by the caller;
- joint limits are written but not enforced (``limited="false"``), as in uvms-pin's
  simulator; contacts are disabled;
- fins (gz-sim's LiftDrag, `uvms_pin.physics.fins`) have no counterpart: the twin has their
  links, not their lift and drag (a `ModelWarning` names them).
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.checks import number_fields
from uvms_pin.errors import ModelError, ModelWarning, ParameterError
from uvms_pin.hydro.mesh import load_mesh_geometry
from uvms_pin.model.resources import resolve_resource
from uvms_pin.model.urdf.read import read_numbers, read_origin
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.format import numbers_text

__all__ = ["MUJOCO_DEFAULT_FLUID_COEFFICIENTS", "MjcfOptions", "uvms_to_mjcf"]

#: MuJoCo's defaults of ``fluidcoef``: blunt drag, slender drag, angular drag, Kutta lift,
#: Magnus lift (MuJoCo XML reference, geom/fluidcoef).
MUJOCO_DEFAULT_FLUID_COEFFICIENTS = (0.5, 0.25, 1.5, 1.0, 1.0)
#: Dynamic viscosity of sea water at 20 degC, salinity 35 g/kg [Pa s] (ITTC 7.5-02-01-03).
SEA_WATER_VISCOSITY_PA_S = 1.08e-3
SPRING_ANCHOR_SITE = "spring_anchor"
SPRING_TENDON = "spring"
_CARRIER_SUFFIX = "/buoyancy"
#: Significant digits of every number written: 17 make any double round-trip exactly.
_EXACT_DIGITS = 17


@dataclass(frozen=True)
class MjcfOptions:
    """What the MJCF adds to the UVMS.

    Attributes:
        timestep_s: MuJoCo's time step h [s].
        integrator: MuJoCo's integrator ("RK4", "Euler", "implicit", "implicitfast").
        viscosity_Pa_s: dynamic viscosity of the water [Pa s] (density: the UVMS's).
        fluid_coefficients: ``fluidcoef`` of every geom (5 numbers, see above).
        carrier_mass_fraction: f in m_c = f m (0 < f < 1), the mass moved to a carrier
            (halved for a body whose inertia would not stay physical).
        spring_stiffness_N_m: k of the end-effector spring [N/m]; 0 = no spring.
        spring_anchor_world_m: p0, the spring's anchor in the world [m] (needed if k > 0).
    """

    timestep_s: float = 5e-4
    integrator: str = "RK4"
    viscosity_Pa_s: float = SEA_WATER_VISCOSITY_PA_S
    fluid_coefficients: tuple[float, ...] = MUJOCO_DEFAULT_FLUID_COEFFICIENTS
    carrier_mass_fraction: float = 0.25
    spring_stiffness_N_m: float = 0.0
    spring_anchor_world_m: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        number_fields(self)
        checks = (
            (self.timestep_s > 0.0 and math.isfinite(self.timestep_s), "timestep_s > 0"),
            (self.integrator in ("RK4", "Euler", "implicit", "implicitfast"), "a known integrator"),
            (self.viscosity_Pa_s >= 0.0 and math.isfinite(self.viscosity_Pa_s), "viscosity >= 0"),
            (
                len(self.fluid_coefficients) == 5
                and all(math.isfinite(c) for c in self.fluid_coefficients),
                "5 finite fluid_coefficients",
            ),
            (0.0 < self.carrier_mass_fraction < 1.0, "0 < carrier_mass_fraction < 1"),
            (
                self.spring_stiffness_N_m >= 0.0 and math.isfinite(self.spring_stiffness_N_m),
                "spring_stiffness_N_m >= 0",
            ),
        )
        for ok, what in checks:
            if not ok:
                raise ParameterError(f"MjcfOptions: need {what}, got {self}")
        if self.spring_stiffness_N_m > 0.0:
            anchor = np.asarray(
                self.spring_anchor_world_m if self.spring_anchor_world_m is not None else [],
                dtype=float,
            )
            if anchor.shape != (3,) or not np.all(np.isfinite(anchor)):
                raise ParameterError(
                    "MjcfOptions: a spring needs spring_anchor_world_m (3 finite numbers), "
                    f"got {self.spring_anchor_world_m}"
                )


def uvms_to_mjcf(
    uvms: UVMS,
    urdf_text: str,
    options: MjcfOptions = MjcfOptions(),
    *,
    base_dir: str | Path = ".",
    package_dirs: Sequence[str | Path] = (),
) -> str:
    """The MJCF text of ``uvms`` (see the module docstring for what is the same and not).

    Args:
        uvms: the loaded system (inertias, joints, armature, volumes, frames).
        urdf_text: the URDF it was loaded from, for the collision shapes of the fluid geoms
            (e.g. ``Path(uvms.source).read_text()``, or ``MountResult.urdf_text``).
        options: time step, integrator, water and spring.
        base_dir, package_dirs: where relative and ``package://`` mesh paths are found.

    Raises:
        ModelError: the URDF cannot be read, a joint is neither revolute nor prismatic, a
            body with volume has no mass, or a carrier leaves a non-physical inertia.
    """
    try:
        urdf = ET.fromstring(urdf_text)
    except ET.ParseError as exc:
        raise ModelError(f"urdf_text is not well-formed XML ({exc})") from exc
    model = uvms.model
    if uvms.fins:
        names = ", ".join(f"'{f.name}'" for f in uvms.fins)
        warnings.warn(
            f"the fins {names} have no MuJoCo counterpart: the twin has their links, not "
            "their lift and drag",
            ModelWarning,
            stacklevel=2,
        )
    root = ET.Element("mujoco", model=urdf.get("name", "uvms"))
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false")
    option = ET.SubElement(
        root,
        "option",
        timestep=numbers_text(options.timestep_s, _EXACT_DIGITS),
        integrator=options.integrator,
        density=numbers_text(uvms.water_density_kg_m3, _EXACT_DIGITS),
        viscosity=numbers_text(options.viscosity_Pa_s, _EXACT_DIGITS),
        gravity=numbers_text(model.gravity.linear, _EXACT_DIGITS),
    )
    ET.SubElement(option, "flag", contact="disable")
    world = ET.SubElement(root, "worldbody")
    axes = _joint_axes(model)
    bodies = {0: world}
    for j in range(1, model.njoints):
        bodies[j] = _joint_body(uvms, j, bodies[model.parents[j]], axes[j], options)
    _add_fluid_geoms(uvms, urdf, bodies, options, Path(base_dir), package_dirs)
    # a model without an end-effector or a sensor frame (a jaw rig, a bare vehicle) has no site
    frames = (uvms.ee_frame_id, uvms.sensor_frame_id)
    for frame_id in dict.fromkeys(f for f in frames if f is not None):
        frame = model.frames[frame_id]
        _placed(bodies[frame.parentJoint], "site", frame.placement, name=frame.name)
    if options.spring_stiffness_N_m > 0.0:
        _spring(root, world, model.frames[uvms.ee_frame_id].name, options)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


# ---- bodies, joints, inertias -----------------------------------------------------------


def _joint_axes(model: pin.Model) -> dict[int, tuple[str, np.ndarray]]:
    """(MuJoCo joint type, axis in the joint frame) of every 1-DoF joint, from its motion
    subspace (the LOCAL Jacobian column of its own DoF: [axis; 0] slides, [0; axis] hinges)."""
    data = model.createData()
    pin.computeJointJacobians(model, data, pin.neutral(model))
    out: dict[int, tuple[str, np.ndarray]] = {1: ("free", np.zeros(3))}
    for j in range(2, model.njoints):
        joint = model.joints[j]
        column = pin.getJointJacobian(model, data, j, pin.LOCAL)[:, joint.idx_v]
        linear, angular = column[:3], column[3:]
        if joint.nv == 1 and np.allclose(linear, 0.0, atol=1e-12):
            out[j] = ("hinge", angular)
        elif joint.nv == 1 and np.allclose(angular, 0.0, atol=1e-12):
            out[j] = ("slide", linear)
        else:
            raise ModelError(
                f"joint '{model.names[j]}' ({joint.shortname()}) has no MJCF equivalent here: "
                "only the free-flyer root and revolute or prismatic joints are exported"
            )
    if model.joints[1].shortname() != "JointModelFreeFlyer":
        raise ModelError("the root joint must be a free-flyer to export MJCF")
    return out


def _body_name(model: pin.Model, j: int) -> str:
    """The link carried by joint j (its first BODY frame), else the joint's name."""
    for frame in model.frames:
        if frame.parentJoint == j and frame.type == pin.FrameType.BODY:
            return frame.name
    return model.names[j]


def _joint_body(
    uvms: UVMS, j: int, parent: ET.Element, axis: tuple[str, np.ndarray], options: MjcfOptions
) -> ET.Element:
    model = uvms.model
    name = _body_name(model, j)
    body = _placed(parent, "body", model.jointPlacements[j], name=name)
    kind, direction = axis
    if kind == "free":
        ET.SubElement(body, "freejoint", name=model.names[j])
    else:
        idx = model.joints[j].idx_v
        idx_q = model.joints[j].idx_q
        joint = ET.SubElement(
            body,
            "joint",
            name=model.names[j],
            type=kind,
            axis=numbers_text(direction, _EXACT_DIGITS),
            armature=numbers_text(model.armature[idx], _EXACT_DIGITS),
            limited="false",
        )
        if model.joints[j].nq == 1:  # a continuous joint (cos, sin) has no range
            limits = [model.lowerPositionLimit[idx_q], model.upperPositionLimit[idx_q]]
            joint.set("range", numbers_text(limits, _EXACT_DIGITS))
    inertia = model.inertias[j]
    volume = float(uvms.volume_per_joint_m3[j])
    if volume > 0.0:
        inertia = _add_carrier(uvms, j, body, name, inertia, volume, options)
    _inertial(body, inertia)
    return body


def _add_carrier(
    uvms: UVMS,
    j: int,
    body: ET.Element,
    name: str,
    inertia: pin.Inertia,
    volume_m3: float,
    options: MjcfOptions,
) -> pin.Inertia:
    """Add the buoyancy carrier of joint j's body; return the inertia the body keeps.

    The carrier takes the largest mass f m / 2^k (k = 0 .. 40) that leaves the body a
    physical inertia (a centre of buoyancy far from the centre of mass limits it)."""
    if inertia.mass <= 0.0:
        raise ModelError(f"body '{name}' displaces {volume_m3} m^3 but has no mass to export")
    center = uvms.center_of_buoyancy_per_joint_m[j]
    for halvings in range(41):
        carrier_kg = options.carrier_mass_fraction * inertia.mass / 2.0**halvings
        kept = inertia - pin.Inertia(carrier_kg, center, np.zeros((3, 3)))
        if _physical(kept.inertia):
            break
    else:
        raise ModelError(f"body '{name}': its inertia is not physical (MuJoCo rejects it)")
    buoyancy_kg = uvms.water_density_kg_m3 * volume_m3
    carrier = ET.SubElement(
        body,
        "body",
        name=name + _CARRIER_SUFFIX,
        pos=numbers_text(center, _EXACT_DIGITS),
        gravcomp=numbers_text(buoyancy_kg / carrier_kg, _EXACT_DIGITS),
    )
    ET.SubElement(
        carrier,
        "inertial",
        pos="0 0 0",
        mass=numbers_text(carrier_kg, _EXACT_DIGITS),
        diaginertia="0 0 0",
    )
    return kept


def _physical(rotational_inertia: np.ndarray) -> bool:
    """Positive definite and A + B >= C for the principal moments (MuJoCo's compiler check)."""
    a, b, c = np.linalg.eigvalsh(rotational_inertia)
    return bool(a > 0.0 and a + b >= c * (1.0 + 1e-12))


def _inertial(body: ET.Element, inertia: pin.Inertia) -> None:
    i = inertia.inertia
    full = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]
    ET.SubElement(
        body,
        "inertial",
        pos=numbers_text(inertia.lever, _EXACT_DIGITS),
        mass=numbers_text(inertia.mass, _EXACT_DIGITS),
        fullinertia=numbers_text(full, _EXACT_DIGITS),
    )


# ---- fluid geoms from the collision shapes ----------------------------------------------


def _add_fluid_geoms(
    uvms: UVMS,
    urdf: ET.Element,
    bodies: dict[int, ET.Element],
    options: MjcfOptions,
    base_dir: Path,
    package_dirs: Sequence[str | Path],
) -> None:
    """One ellipsoid-fluid geom per collision shape, in the body of the joint carrying it."""
    model = uvms.model
    for link in urdf.findall("link"):
        name = link.get("name", "")
        collisions = link.findall("collision")
        if not collisions or not model.existFrame(name, pin.FrameType.BODY):
            continue
        frame = model.frames[model.getFrameId(name, pin.FrameType.BODY)]
        for k, collision in enumerate(collisions):
            placement = frame.placement * read_origin(collision.find("origin"), "urdf_text", name)
            kind, size, local = _shape(collision, name, base_dir, package_dirs)
            _placed(
                bodies[frame.parentJoint],
                "geom",
                placement * local,
                name=f"{name}/collision[{k}]",
                type=kind,
                size=numbers_text(size, _EXACT_DIGITS),
                fluidshape="ellipsoid",
                fluidcoef=numbers_text(options.fluid_coefficients, _EXACT_DIGITS),
                contype="0",
                conaffinity="0",
            )


def _shape(
    collision: ET.Element, link: str, base_dir: Path, package_dirs: Sequence[str | Path]
) -> tuple[str, np.ndarray, pin.SE3]:
    """(MuJoCo geom type, size, placement in the collision frame) of a URDF shape."""
    geometry = collision.find("geometry")
    shape = None if geometry is None or len(geometry) == 0 else geometry[0]
    where = "urdf_text"
    if shape is None:
        raise ModelError("<collision> has no <geometry> shape", path=where, link=link)
    if shape.tag == "box":
        return "box", 0.5 * read_numbers(shape.get("size"), 3, "<box size>", where, link), _EYE
    if shape.tag == "cylinder":
        radius = read_numbers(shape.get("radius"), 1, "<cylinder radius>", where, link)[0]
        length = read_numbers(shape.get("length"), 1, "<cylinder length>", where, link)[0]
        return "cylinder", np.array([radius, 0.5 * length]), _EYE
    if shape.tag == "sphere":
        return "sphere", read_numbers(shape.get("radius"), 1, "<sphere radius>", where, link), _EYE
    if shape.tag == "mesh":
        filename = shape.get("filename", "")
        resolved = resolve_resource(filename, base_dir, package_dirs)
        if resolved is None:
            raise ModelError(f"collision mesh '{filename}' not found", path=where, link=link)
        scale = read_numbers(shape.get("scale", "1 1 1"), 3, "<mesh scale>", where, link)
        mesh = load_mesh_geometry(resolved, scale)
        half = np.maximum(0.5 * mesh.obb_extents_m, 5e-5)
        return "box", half, pin.SE3(mesh.obb_rotation, mesh.obb_center_m)
    raise ModelError(f"collision <{shape.tag}> has no MJCF equivalent", path=where, link=link)


_EYE = pin.SE3.Identity()


# ---- sites, spring, formatting ----------------------------------------------------------


def _spring(root: ET.Element, world: ET.Element, ee_site: str, options: MjcfOptions) -> None:
    ET.SubElement(
        world,
        "site",
        name=SPRING_ANCHOR_SITE,
        pos=numbers_text(options.spring_anchor_world_m, _EXACT_DIGITS),
    )
    tendon = ET.SubElement(ET.SubElement(root, "tendon"), "spatial")
    tendon.attrib.update(
        name=SPRING_TENDON,
        stiffness=numbers_text(options.spring_stiffness_N_m, _EXACT_DIGITS),
        springlength="0 0",
    )
    ET.SubElement(tendon, "site", site=ee_site)
    ET.SubElement(tendon, "site", site=SPRING_ANCHOR_SITE)


def _placed(parent: ET.Element, tag: str, placement: pin.SE3, **attrib: str) -> ET.Element:
    """A child element at ``placement`` (pos, and quat w x y z) in its parent's frame."""
    xyzw = pin.Quaternion(placement.rotation).coeffs()
    element = ET.SubElement(parent, tag, **attrib)
    element.set("pos", numbers_text(placement.translation, _EXACT_DIGITS))
    element.set("quat", numbers_text([xyzw[3], xyzw[0], xyzw[1], xyzw[2]], _EXACT_DIGITS))
    return element
