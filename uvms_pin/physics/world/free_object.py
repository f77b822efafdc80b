"""A free object of the world: a rigid body that moves when pushed (a box on the seafloor,
a sphere, a pipe section), its own floating body beside the UVMS.

Its model is a bare vehicle (a UVMS without an arm) generated from its shape, loaded as any
model is (`uvms_pin.model.urdf.load.load_uvms`): the one link carries the shape as its
``<collision>`` geometry and no ``<hydrodynamics>``, so its buoyancy (the shape's volume),
added mass and damping are derived from the shape exactly as a link's are
(`uvms_pin.model.urdf.collision`), and its collision pieces are the shape's
(`uvms_pin.physics.world.robot_geometry`). The mass is ``mass_kg``, or ``density_kg_m3``
times the volume; the inertia is that of the homogeneous solid about its centre of mass:

    box a x b x c:      I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2)
    sphere r:           I = 2/5 m r^2 (each axis)
    cylinder r, L (z):  I = diag(m (3 r^2 + L^2)/12, same, m r^2 / 2)
    mesh:               the closed mesh's (or its convex hull's) volume integrals

The object's frame is its shape's centre (a mesh's: the file's origin), placed by its pose
q = [p (3); quaternion x, y, z, w] with the body velocity [v; w] (LOCAL), as a vehicle's.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import trimesh

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.hydro.mesh import load_mesh_geometry
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.world.contact_law import check_friction
from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.robot_geometry import RobotPiece, robot_pieces

__all__ = ["FreeObject", "free_object", "solid_mass_properties"]


@dataclass(frozen=True)
class FreeObject:
    """One free object.

    Attributes:
        name: for logs and views. kind: "box", "sphere", "cylinder" or "mesh".
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
        check_friction(self.friction_static, self.friction_kinetic, f"object '{self.name}'")
        if self.uvms.nq != 7 or self.uvms.nv != 6:
            raise ParameterError(f"free object '{self.name}' must be a single floating body")
        q0 = finite_vector(f"object '{self.name}' pose", self.q0, 7)
        norm = float(np.linalg.norm(q0[3:]))
        if norm == 0.0:
            raise ParameterError(f"object '{self.name}': a zero quaternion")
        q0[3:] /= norm
        object.__setattr__(self, "q0", q0)
        object.__setattr__(self, "v0", finite_vector(f"object '{self.name}' v0", self.v0, 6))
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


def _box_inertia(size: np.ndarray, mass: float) -> np.ndarray:
    a, b, c = size
    return mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def solid_mass_properties(
    kind: str, sizes: dict[str, Any], mass_kg: float | None, density_kg_m3: float | None
) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass [kg], centre of mass in the shape's frame (3,) [m], inertia about it (3, 3)
    [kg m^2]) of a homogeneous solid given its mass or its density."""
    if kind == "mesh":
        geometry = load_mesh_geometry(Path(sizes["path"]), tuple(sizes.get("scale", (1.0,) * 3)))
        mesh = trimesh.Trimesh(geometry.vertices_m, geometry.triangles, process=False)
        volume = float(geometry.volume_m3)
        center = np.asarray(mesh.center_mass, dtype=float)
        unit_inertia = np.asarray(mesh.moment_inertia, dtype=float) / float(mesh.volume)
    else:
        volume, unit_inertia = _primitive_unit(kind, sizes)
        center = np.zeros(3)
    mass = float(mass_kg) if mass_kg is not None else float(density_kg_m3) * volume
    if not (math.isfinite(mass) and mass > 0.0):
        raise ParameterError(f"a free {kind} needs a positive mass, got {mass}")
    return mass, center, mass * unit_inertia


def _primitive_unit(kind: str, sizes: dict[str, Any]) -> tuple[float, np.ndarray]:
    """(volume [m^3], inertia of unit mass about the centre (3, 3) [m^2])."""
    if kind == "box":
        size = np.asarray(sizes["size_m"], dtype=float)
        return float(np.prod(size)), np.diag(_box_inertia(size, 1.0))
    if kind == "sphere":
        r = float(sizes["radius_m"])
        return 4.0 / 3.0 * math.pi * r**3, np.eye(3) * 0.4 * r * r
    if kind == "cylinder":
        r, length = float(sizes["radius_m"]), float(sizes["length_m"])
        side = (3.0 * r * r + length * length) / 12.0
        return math.pi * r * r * length, np.diag([side, side, 0.5 * r * r])
    raise ParameterError(f"a free object cannot be a {kind}")


def _collision_xml(kind: str, sizes: dict[str, Any]) -> str:
    if kind == "box":
        return '<box size="{} {} {}"/>'.format(*map(repr, map(float, sizes["size_m"])))
    if kind == "sphere":
        return f'<sphere radius="{float(sizes["radius_m"])!r}"/>'
    if kind == "cylinder":
        r, length = float(sizes["radius_m"]), float(sizes["length_m"])
        return f'<cylinder radius="{r!r}" length="{length!r}"/>'
    scale = " ".join(repr(float(s)) for s in sizes.get("scale", (1.0,) * 3))
    return f'<mesh filename="{Path(sizes["path"]).resolve()}" scale="{scale}"/>'


def _urdf(name: str, kind: str, sizes: dict[str, Any], mass, center, inertia) -> str:
    i = np.asarray(inertia, dtype=float).tolist()
    mass = float(mass)
    return "\n".join(
        [
            f'<robot name="{name}">',
            f'  <link name="{name}">',
            "    <inertial>",
            '      <origin xyz="{} {} {}"/>'.format(*map(repr, map(float, center))),
            f'      <mass value="{mass!r}"/>',
            f'      <inertia ixx="{i[0][0]!r}" iyy="{i[1][1]!r}" izz="{i[2][2]!r}" '
            f'ixy="{i[0][1]!r}" ixz="{i[0][2]!r}" iyz="{i[1][2]!r}"/>',
            "    </inertial>",
            f"    <collision><geometry>{_collision_xml(kind, sizes)}</geometry></collision>",
            "  </link>",
            "</robot>",
        ]
    )


def _plain(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    return value.tolist() if isinstance(value, np.ndarray) else value


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
    ``density_kg_m3`` (exactly one), in water of ``water_density_kg_m3``."""
    if (mass_kg is None) == (density_kg_m3 is None):
        raise ParameterError(f"free object '{name}': give mass_kg or density_kg_m3 (one)")
    mass, center, inertia = solid_mass_properties(kind, sizes, mass_kg, density_kg_m3)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{name}.urdf"
        path.write_text(_urdf(name, kind, sizes, mass, center, inertia))
        uvms = load_uvms(path, water_density_kg_m3=water_density_kg_m3)
    position = finite_vector(f"object '{name}' position_world_m", pose[0], 3)
    rpy = finite_vector(f"object '{name}' rpy_rad", pose[1], 3)
    q0 = np.concatenate([position, pin.Quaternion(pin.rpy.rpyToMatrix(rpy)).coeffs()])
    params = {
        **{k: _plain(v) for k, v in sizes.items()},
        "rpy_rad": rpy.tolist(),
    }
    v0 = np.zeros(6) if velocity_body is None else velocity_body
    return FreeObject(name, kind, uvms, q0, v0, friction[0], friction[1], params)
