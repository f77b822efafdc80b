"""A fixture of the world: an articulated body whose root is fixed (a subsea panel with a
valve handle, a hot-stab receptacle), its joints moved by what touches it.

``[[world.objects]] type = "urdf"``: a URDF whose root link is welded to the world at
``position_world_m`` and ``rpy_rad`` (Pinocchio's model of the file, fixed base, placed
there); its revolute and prismatic joints move, each from its ``joint_positions_rad``
entry (0 by default). A fixed joint merges its links (Pinocchio's rule); a floating,
planar or continuous joint is refused.

Its dynamics, in the system of bodies beside the robot and the free objects
(`uvms_pin.sim.system`), for its joint coordinates q_f:

    M_f(q_f) qdd_f + h_f(q_f, qd_f) = -D qd_f + tau_contact          [N m or N]

with M_f, h_f the rigid bodies' (masses from the URDF's ``<inertial>``) and, only for a
link whose URDF has a ``<hydrodynamics>`` element (`uvms_pin.model.urdf.hydrodynamics`),
its buoyancy, added mass and damping; no coefficient is derived from the collision shapes
(a link without the element is dry: its weight alone). D = diag(``<dynamics damping>``)
is the viscous torque; ``<dynamics friction>`` c_j is Coulomb friction with stiction, a
joint friction constraint (`uvms_pin.physics.constraints.joint_friction`), and ``<limit>``
the joint-limit constraints (`uvms_pin.physics.constraints.joint_limits`), both solved
implicitly with the period's other constraints. Its links touch the robot and the free
objects by their ``<collision>`` shapes (`uvms_pin.physics.world.moving`), as the robot's
own links do (a box or mesh as its convex hull: model a bore by several boxes).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.native_stderr import captured_native_stderr
from uvms_pin.model.resources import shipped_path
from uvms_pin.model.urdf.bodies import hydro_bodies
from uvms_pin.model.urdf.collision import collision_piece
from uvms_pin.model.urdf.hydrodynamics import hydro_elements_by_link
from uvms_pin.model.urdf.read import read_urdf_root
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.world.kind import invalid, solid_placement
from uvms_pin.physics.world.robot_geometry import RobotPiece, coal_of
from uvms_pin.results.signal import Signal, component_label

__all__ = ["FIXTURE_TYPE", "MOVING_JOINTS", "Fixture", "fixture", "fixture_path"]

#: the ``type`` of a fixture in ``[[world.objects]]``
FIXTURE_TYPE = "urdf"

#: URDF joint type -> the unit of its coordinate: the joints a fixture simulates
MOVING_JOINTS = {"revolute": "rad", "prismatic": "m"}

#: joint types a fixture keeps rigid (merged by Pinocchio)
_RIGID_JOINTS = ("fixed",)


@dataclass(frozen=True)
class Fixture:
    """One fixture (built by `fixture`).

    Attributes:
        name: for logs and views. path: its URDF file.
        uvms: its articulated body: Pinocchio's fixed-base model of the URDF placed at its
            pose (joint 0 the world), hydrodynamics from ``<hydrodynamics>`` elements only.
        q0: its joints' initial positions (nq,) [rad or m]. v0: their rates (zeros).
        joint_names: the moving joints (model order). joint_units: "rad" or "m" each.
        pieces: its links' collision shapes. piece_names: ``<fixture>.<link>`` of each.
        friction_static, friction_kinetic: mu_s >= mu_k >= 0 against it.
        params: what it was made from, as plain data.
    """

    name: str
    path: str
    uvms: UVMS
    q0: np.ndarray
    joint_names: tuple[str, ...]
    joint_units: tuple[str, ...]
    pieces: tuple[RobotPiece, ...]
    piece_names: tuple[str, ...]
    friction_static: float = 0.6
    friction_kinetic: float = 0.5
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def v0(self) -> np.ndarray:
        return np.zeros(self.uvms.nv)

    @property
    def joint_ids(self) -> tuple[int, ...]:
        """Its moving joints in its own model (1..njoints-1)."""
        return tuple(range(1, self.uvms.model.njoints))

    @property
    def limits(self) -> tuple[np.ndarray, np.ndarray]:
        """(q_min, q_max) (nv,) [rad or m]: the URDF's ``<limit>`` of each joint that has
        both (finite), else (-inf, inf): no limit."""
        model = self.uvms.model
        at = [model.joints[j].idx_q for j in self.joint_ids]
        low, high = model.lowerPositionLimit[at], model.upperPositionLimit[at]
        limited = np.isfinite(low) & np.isfinite(high) & (np.maximum(-low, high) < 1e300)
        return np.where(limited, low, -np.inf), np.where(limited, high, np.inf)

    @property
    def damping(self) -> np.ndarray:
        """D (nv,) [N m s/rad or N s/m], the URDF's ``<dynamics damping>``."""
        return np.array(self.uvms.model.damping, dtype=float)

    @property
    def coulomb(self) -> np.ndarray:
        """c (nv,) [N m or N], the URDF's ``<dynamics friction>``."""
        return np.array(self.uvms.model.friction, dtype=float)

    def viscous_torque(self, v: np.ndarray) -> np.ndarray:
        """-D v (nv,) [N m or N]: the joints' viscous friction at their rates ``v``."""
        return -self.damping * np.asarray(v, dtype=float)

    def signal(self, q: np.ndarray) -> Signal:
        """Its joints' positions at ``q``, logged as ``<name>.<joint>_rad`` (or ``_m``)."""
        labels = [component_label(j) for j in self.joint_names]
        return Signal(np.asarray(q, dtype=float), labels, self.joint_units)

    def record(self) -> dict[str, Any]:
        """Plain data: what a rollout keeps and the views draw."""
        return {
            "name": self.name,
            "type": FIXTURE_TYPE,
            "path": self.path,
            "joints": list(self.joint_names),
            "friction_static": float(self.friction_static),
            "friction_kinetic": float(self.friction_kinetic),
            **self.params,
        }


def fixture_path(entry: str | Path, base_dir: Path) -> Path:
    """The URDF of a fixture: ``entry`` relative to ``base_dir`` (the scenario's folder),
    else to the shipped ``models/`` folder; `invalid` (key ``path``) when neither exists."""
    path = Path(entry)
    candidates = [path] if path.is_absolute() else [Path(base_dir) / path]
    if not path.is_absolute():
        try:
            candidates.append(shipped_path("models") / path)
        except FileNotFoundError:  # an install without its models
            pass
    for candidate in candidates:
        if candidate.is_file():
            return candidate.resolve()  # recorded by the run: read again from anywhere
    looked = " or ".join(str(c) for c in candidates)
    raise ParameterError(f"no URDF file at {looked}")


def fixture(
    name: str,
    path: str | Path,
    pose: tuple[Sequence[float], Sequence[float]],
    *,
    joint_positions: Mapping[str, float] | Sequence[float] | None = None,
    water_density_kg_m3: float,
    friction: tuple[float, float] = (0.6, 0.5),
) -> Fixture:
    """The fixture of the URDF ``path`` with its root at ``pose`` = (position (3,) [m],
    roll-pitch-yaw (3,) [rad]), its joints at ``joint_positions`` (joint name -> value, or
    one value per moving joint in the file's order; None: all 0) [rad or m].

    Raises:
        ParameterError: naming the object, the key (``.key``: ``path`` or
            ``joint_positions_rad``) and the file: a file that is not there, a joint a
            fixture cannot move (floating, planar, continuous), an unknown joint, a position
            outside its limits, a moving body without mass.
    """
    where = str(path)
    if not Path(path).is_file():
        raise invalid(name, "path", f"has no URDF file at {where}")
    try:
        root = read_urdf_root(Path(path))
        units = _moving_joints(root, where)
        model = _placed_model(Path(path), pose)
        links = {link.get("name"): link for link in root.findall("link")}
        bodies = hydro_bodies(
            model, links, hydro_elements_by_link(root, links, where), water_density_kg_m3,
            where, derive_missing=False, allow_dry_links=True, base_dir=Path(path).parent,
            package_dirs=(),
        )  # fmt: skip
        pieces, piece_names = _pieces(model, links, name, where, Path(path).parent)
    except ModelError as exc:
        raise invalid(name, "path", str(exc)) from exc
    uvms = UVMS(model, tuple(bodies), float(water_density_kg_m3), None, None, where)
    names = tuple(model.names[j] for j in range(1, model.njoints))
    q0 = _initial(name, where, model, names, joint_positions)
    _check_masses(name, where, model, q0)
    params = {
        "position_world_m": [float(x) for x in pose[0]],
        "rpy_rad": [float(x) for x in pose[1]],
        "joint_positions": dict(zip(names, q0.tolist(), strict=True)),
    }
    return Fixture(
        name, where, uvms, q0, names, tuple(units[n] for n in names), pieces, piece_names,
        float(friction[0]), float(friction[1]), params,
    )  # fmt: skip


def _moving_joints(root: ET.Element, where: str) -> dict[str, str]:
    """Each moving joint's unit by name; ModelError for a joint a fixture cannot hold."""
    out = {}
    for joint in root.findall("joint"):
        kind, joint_name = joint.get("type"), joint.get("name")
        if kind in MOVING_JOINTS:
            out[joint_name] = MOVING_JOINTS[kind]
        elif kind not in _RIGID_JOINTS:
            raise ModelError(
                f"joint '{joint_name}' is {kind}: a fixture's root is fixed in the world and "
                f"its joints are {', '.join(MOVING_JOINTS)} or fixed",
                path=where,
            )
    return out


def _placed_model(path: Path, pose: tuple[Sequence[float], Sequence[float]]) -> pin.Model:
    """Pinocchio's fixed-base model of ``path`` with its root link at ``pose``."""
    try:
        with captured_native_stderr() as urdfdom:
            model = pin.buildModelFromUrdf(str(path))
    except Exception as exc:  # Pinocchio raises ValueError/RuntimeError for bad URDFs
        detail = f" (urdfdom: {urdfdom.text})" if urdfdom.text else ""
        raise ModelError(
            f"Pinocchio could not build the model: {exc}{detail}", path=str(path)
        ) from exc
    placement = solid_placement({"position_world_m": pose[0], "rpy_rad": pose[1]})
    return pin.appendModel(pin.Model(), model, 0, placement)


def _pieces(
    model: pin.Model, links: dict[str, ET.Element], name: str, where: str, base_dir: Path
) -> tuple[tuple[RobotPiece, ...], tuple[str, ...]]:
    """Every ``<collision>`` shape of every link, on the joint that carries the link."""
    pieces, names = [], []
    for link_name, link in links.items():
        collisions = link.findall("collision")
        if not collisions:
            continue
        frame = model.frames[model.getFrameId(link_name, pin.BODY)]
        for collision in collisions:
            hull = collision_piece(collision, where, link_name, base_dir)
            shape, corners = coal_of(hull.shape, link_name)
            pieces.append(
                RobotPiece(
                    body=len(names),
                    joint_id=int(frame.parentJoint),
                    placement_in_joint=frame.placement * pin.SE3(hull.rotation, hull.translation_m),
                    shape=shape,
                    corners_m=corners,
                    bound_radius_m=float(hull.shape.bounding_radius_m),
                )
            )
            names.append(f"{name}.{link_name}")
    return tuple(pieces), tuple(names)


def _initial(
    name: str,
    where: str,
    model: pin.Model,
    joints: tuple[str, ...],
    given: Mapping[str, float] | Sequence[float] | None,
) -> np.ndarray:
    """The joints' initial positions (nq,) from ``given``, checked against the limits."""
    key = "joint_positions_rad"
    q0 = np.zeros(model.nq)
    if isinstance(given, Mapping):
        for joint, value in given.items():
            if joint not in joints:
                known = ", ".join(joints) or "none"
                raise invalid(name, key, f"names joint '{joint}', not a moving joint of {where} "
                              f"({known})")  # fmt: skip
            q0[joints.index(joint)] = float(value)
    elif given is not None:
        values = np.asarray(given, dtype=float).reshape(-1)
        if values.size != len(joints):
            raise invalid(name, key, f"needs {len(joints)} values (the moving joints of "
                          f"{where}: {', '.join(joints)}), got {values.size}")  # fmt: skip
        q0[:] = values
    if not np.all(np.isfinite(q0)):
        raise invalid(name, key, f"has a non-finite value: {q0.tolist()}")
    low, high = model.lowerPositionLimit, model.upperPositionLimit
    outside = [j for k, j in enumerate(joints) if not low[k] - 1e-12 <= q0[k] <= high[k] + 1e-12]
    if outside:
        k = joints.index(outside[0])
        raise invalid(name, key, f"puts joint '{outside[0]}' of {where} at {q0[k]:.6g}, outside "
                      f"its limits [{low[k]:.6g}, {high[k]:.6g}]")  # fmt: skip
    return q0


def _check_masses(name: str, where: str, model: pin.Model, q0: np.ndarray) -> None:
    """Every moving joint carries inertia: M(q0) positive definite."""
    if model.nv == 0:
        return
    mass = pin.crba(model, model.createData(), q0)
    mass = np.triu(mass) + np.triu(mass, 1).T
    try:
        np.linalg.cholesky(mass)
    except np.linalg.LinAlgError as exc:
        light = [model.names[j] for j in range(1, model.njoints) if mass[j - 1, j - 1] <= 0.0]
        what = f" (joint {', '.join(repr(j) for j in light)})" if light else ""
        raise invalid(
            name, "path", f"{where}: a moving body has no inertia{what}: give its link an "
            "<inertial>"
        ) from exc  # fmt: skip
