"""A free object of the world: a rigid body that moves when pushed (a box on the seafloor,
a sphere, a pipe section), its own floating body beside the UVMS.

Its model is a bare vehicle (a UVMS without an arm): one link, its rigid body loaded as any
model is (`uvms_pin.model.urdf.load.load_uvms`), with the hydrodynamic body its kind gives
(`uvms_pin.physics.world.kind.FreeShape`: for the shapes a URDF ``<collision>`` holds,
derived from the shape exactly as a link's are, `uvms_pin.model.urdf.collision`): its
buoyancy (the shape's volume), added mass, damping and hull, whose pieces are what it
touches by (`uvms_pin.physics.world.robot_geometry`). The mass is ``mass_kg``, or
``density_kg_m3`` times the volume; the inertia is that of the homogeneous solid about its
centre of mass (each kind's module gives it: a box's m/12 diag(b^2 + c^2, ...)).

The object's frame is its shape's centre (a mesh's: the file's origin), placed by its pose
q = [p (3); quaternion x, y, z, w] with the body velocity [v; w] (LOCAL), as a vehicle's.
"""

from __future__ import annotations

import math
import tempfile
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ModelWarning, ParameterError
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import BODY_DENSITY, UVMS
from uvms_pin.physics.world.kind import FreeShape
from uvms_pin.physics.world.objects import WorldObject, checked, object_kind
from uvms_pin.physics.world.robot_geometry import RobotPiece, robot_pieces

__all__ = [
    "FreeObject",
    "free_body",
    "free_mass",
    "free_object",
    "free_object_of",
    "solid_mass_properties",
]


@dataclass(frozen=True)
class FreeObject:
    """One free object.

    Attributes:
        name: for logs and views. kind: its ``type`` (a kind that can be free).
        uvms: its floating body (a bare vehicle: one link, hydrodynamics from its shape).
        q0: its initial pose (7,) [m; quaternion x, y, z, w]. v0: its body velocity (6,).
        friction_static, friction_kinetic: mu_s >= mu_k >= 0 against it.
        params: what it was made from (sizes, file, mass), as plain data.
    """

    name: str
    kind: str
    uvms: UVMS
    q0: np.ndarray
    v0: np.ndarray = field(default_factory=lambda: np.zeros(6))
    friction_static: float = 0.6
    friction_kinetic: float = 0.5
    params: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        names = [self.uvms.hydro_bodies[int(k)].name for k in self.uvms.surface_bodies.body_index]
        object.__setattr__(self, "pieces", robot_pieces(self.uvms, names))

    @property
    def mass_kg(self) -> float:
        return float(self.uvms.model.inertias[1].mass)

    def posed(self, data: pin.Data) -> list[WorldObject]:
        """Its collision pieces as world objects where ``data`` (after forward kinematics
        of its model) places them (the obstacles a UVMS touches)."""
        pieces: tuple[RobotPiece, ...] = self.pieces  # set in __post_init__
        return [
            WorldObject(
                f"{self.name}#{k}",
                self.kind,
                piece.shape,
                data.oMi[piece.joint_id] * piece.placement_in_joint,
                self.friction_static,
                self.friction_kinetic,
                piece.bound_radius_m,
            )
            for k, piece in enumerate(pieces)
        ]

    def record(self) -> dict[str, Any]:
        """Plain data: what the views draw (at its logged pose) and a rollout keeps."""
        rotation = pin.Quaternion(self.q0[3:]).matrix()
        return {
            "name": self.name,
            "type": self.kind,
            "free": True,
            "mass_kg": self.mass_kg,
            "position_world_m": self.q0[:3].tolist(),
            "rotation_world": rotation.tolist(),
            "friction_static": float(self.friction_static),
            "friction_kinetic": float(self.friction_kinetic),
            **self.params,
        }


def solid_mass_properties(
    kind: str, sizes: dict[str, Any], mass_kg: float | None, density_kg_m3: float | None
) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass [kg], centre of mass in the shape's frame (3,) [m], inertia about it (3, 3)
    [kg m^2]) of a homogeneous solid of a kind (`uvms_pin.physics.world.kind.FreeShape`)
    given its mass or its density."""
    volume, center, unit_inertia = _free_shape(kind).mass_properties(sizes)
    mass = float(mass_kg) if mass_kg is not None else float(density_kg_m3) * volume
    if not (math.isfinite(mass) and mass > 0.0):
        raise ParameterError(f"a free {kind} needs a positive mass, got {mass}")
    return mass, center, mass * unit_inertia


def free_mass(
    name: str, kind: str, params: dict[str, Any], mass_kg: float | None, density: float | None
) -> float:
    """The checked mass [kg] of a free object given its ``mass_kg`` or its density
    [kg/m^3] (exactly one): positive, and a mean density a body can have (refused or
    warned as a model's bodies are, `uvms_pin.model.uvms.BODY_DENSITY`)."""
    if (mass_kg is None) == (density is None):
        raise ParameterError(f"free object '{name}': give mass_kg or density_kg_m3 (one)")
    mass, _, _ = solid_mass_properties(kind, params, mass_kg, density)
    volume = _free_shape(kind).mass_properties(params)[0]
    what = f"free object '{name}': {mass:.4g} kg in {volume:.4g} m^3, a mean density of"
    refusal = BODY_DENSITY.refusal(mass / volume)
    if refusal is not None:
        raise ParameterError(f"{what} {refusal}")
    warning = BODY_DENSITY.warning(mass / volume)
    if warning is not None:
        warnings.warn(f"{what} {warning}", ModelWarning, stacklevel=3)
    return mass


def _free_shape(kind: str) -> FreeShape:
    free = object_kind(kind).free
    if free is None:
        raise ParameterError(f"a free object cannot be a {kind}")
    return free


def _urdf(name: str, mass: float, center, inertia) -> str:
    """The rigid body alone (its hydrodynamics are its kind's `HydroBody`)."""
    i = np.asarray(inertia, dtype=float).tolist()
    return "\n".join(
        [
            f'<robot name="{name}">',
            f'  <link name="{name}">',
            "    <inertial>",
            '      <origin xyz="{} {} {}"/>'.format(*map(repr, map(float, center))),
            f'      <mass value="{float(mass)!r}"/>',
            f'      <inertia ixx="{i[0][0]!r}" iyy="{i[1][1]!r}" izz="{i[2][2]!r}" '
            f'ixy="{i[0][1]!r}" ixz="{i[0][2]!r}" iyz="{i[1][2]!r}"/>',
            "    </inertial>",
            "  </link>",
            "</robot>",
        ]
    )


def free_body(
    name: str, kind: str, params: dict[str, Any], mass_kg: float, water_density_kg_m3: float
) -> UVMS:
    """The floating body of a free object of checked ``params`` and mass: its rigid body
    (the homogeneous solid's inertia) with its kind's hydrodynamic body."""
    mass, center, inertia = solid_mass_properties(kind, params, mass_kg, None)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{name}.urdf"
        path.write_text(_urdf(name, mass, center, inertia))
        rigid = load_uvms(path, water_density_kg_m3=water_density_kg_m3, allow_dry_links=True)
    body = _free_shape(kind).hydro_body(name, params, water_density_kg_m3)
    return replace(rigid, hydro_bodies=(body,))


def free_object_of(
    name: str,
    kind: str,
    params: dict[str, Any],
    mass_kg: float,
    water_density_kg_m3: float,
    friction: tuple[float, float],
    velocity_body: np.ndarray | None = None,
) -> FreeObject:
    """The free object of ``params`` as `ObjectKind.check` returned them (its pose among
    them), of ``mass_kg``, friction and initial body velocity checked by the caller."""
    uvms = free_body(name, kind, params, mass_kg, water_density_kg_m3)
    rotation = pin.rpy.rpyToMatrix(np.asarray(params["rpy_rad"], dtype=float))
    position = np.asarray(params["position_world_m"], dtype=float)
    quaternion = pin.Quaternion(rotation).coeffs()
    q0 = np.concatenate([position, quaternion / float(np.linalg.norm(quaternion))])
    v0 = np.zeros(6) if velocity_body is None else np.asarray(velocity_body, dtype=float)
    kept = {k: v for k, v in params.items() if k != "position_world_m"}
    return FreeObject(name, kind, uvms, q0, v0, friction[0], friction[1], kept)


def free_object(
    name: str,
    kind: str,
    sizes: dict[str, Any],
    pose: tuple[np.ndarray, np.ndarray],
    *,
    mass_kg: float | None = None,
    density_kg_m3: float | None = None,
    water_density_kg_m3: float,
    friction: tuple[float, float] = (0.6, 0.5),
    velocity_body: np.ndarray | None = None,
) -> FreeObject:
    """The free object of a shape (``sizes`` as for a fixed one, `objects.solid`) at
    ``pose`` = (position (3,) [m], roll-pitch-yaw (3,) [rad]), of ``mass_kg`` or
    ``density_kg_m3`` (exactly one), in water of ``water_density_kg_m3``: the one check
    of a free object given in code (a scenario's: `uvms_pin.scenario.objects`)."""
    _free_shape(kind)
    raw = {**sizes, "position_world_m": pose[0], "rpy_rad": pose[1]}
    params, mu = checked(name, kind, raw, friction)
    mass = free_mass(name, kind, params, mass_kg, density_kg_m3)
    v0 = None if velocity_body is None else finite_vector(f"object '{name}' v0", velocity_body, 6)
    return free_object_of(name, kind, params, mass, water_density_kg_m3, mu, v0)
