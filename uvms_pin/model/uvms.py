"""The static model of a UVMS: the Pinocchio model, per-body hydrodynamics, frames.

Pinocchio builds the rigid multibody with a free-flyer root and merges links attached by
fixed joints into their parent joint's body. Each link's hydrodynamic coefficients are a
`HydroBody` attached to the Pinocchio joint that carries the link, with the link's placement
in that joint's frame, so nothing is approximated when links are merged. A URDF file gives
one with `uvms_pin.model.urdf.load.load_uvms`.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.checks import Plausible
from uvms_pin.errors import ModelError
from uvms_pin.hydro.added_mass import added_mass_in_parent
from uvms_pin.hydro.hull import HullPiece
from uvms_pin.hydro.lift_drag import LiftDragParams
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.arm_joints import ArmJoints
from uvms_pin.model.hulls import SurfaceBodies

__all__ = ["DEFAULT_WATER_DENSITY_KG_M3", "UVMS", "Fin", "HydroBody"]

DEFAULT_WATER_DENSITY_KG_M3 = 1025.0  # sea water; a parameter of load_uvms, never hidden

#: What water's density is [kg/m^3]
WATER_DENSITY = Plausible(
    "kg/m^3",
    usual=(990.0, 1050.0),
    possible=(500.0, 15000.0),
    usual_text="fresh to sea water",
    impossible_text="no liquid is that light or dense (mercury: 13534 kg/m^3)",
    hints=("sea water is 1025 kg/m^3 (1.025 g/cm^3)",) * 2,
)
#: What a body of a UVMS is, on average: its mass over the water it displaces [kg/m^3]
BODY_DENSITY = Plausible(
    "kg/m^3",
    usual=(50.0, 15000.0),
    possible=(1.2, 22600.0),
    usual_text="what vehicles and arms are made of, foam to tungsten",
    impossible_text="no body in water is lighter than air (1.2 kg/m^3) or denser than osmium "
    "(22590 kg/m^3)",
    hints=("a <volume> in litres?", "a <mass> in grams?"),
)


@dataclass(frozen=True)
class HydroBody:
    """Hydrodynamic parameters of one link attached to one Pinocchio joint.

    Attributes:
        name: the URDF link (or ``link/collision[k]`` for a derived primitive).
        joint_id: index of the Pinocchio joint whose body carries this link.
        placement_in_joint: SE3 of the hydro frame (where the coefficients are given)
            relative to the joint frame.
        params: coefficients in the hydro frame.
        geometry: the shapes that displace the body's water, placed in the hydro frame (its
            collision geometry; the free surface cuts them). Empty: a body with volume is
            taken as a sphere of that volume at its centre of buoyancy.
    """

    name: str
    joint_id: int
    placement_in_joint: pin.SE3
    params: HydroParams
    geometry: tuple[HullPiece, ...] = ()

    @property
    def action_joint_to_body(self) -> np.ndarray:
        """X (6x6) with nu_body = X nu_joint."""
        return self.placement_in_joint.inverse().action


@dataclass(frozen=True)
class Fin:
    """A lifting surface on one link (gz-sim's ``LiftDrag``; `uvms_pin.hydro.lift_drag`).

    Attributes:
        name: the URDF link.
        joint_id: index of the Pinocchio joint whose body carries the link.
        placement_in_joint: SE3 of the link frame (where ``params`` are given) in the joint
            frame.
        params: the fin's coefficients, centre of pressure and directions, link frame.
        control_q_index: the index in q of the control joint whose angle changes the lift
            (``control_joint_rad_to_cl``), or None: the fin's own link turns with its joint.
    """

    name: str
    joint_id: int
    placement_in_joint: pin.SE3
    params: LiftDragParams
    control_q_index: int | None = None


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
        fins: the links' lifting surfaces (``<lift_drag>``), a force of the plant's
            (`uvms_pin.physics.fins`), not of `forward_dynamics`.
    """

    model: pin.Model
    hydro_bodies: tuple[HydroBody, ...]
    water_density_kg_m3: float
    ee_frame_id: int | None
    sensor_frame_id: int | None
    source: str = ""
    fins: tuple[Fin, ...] = ()
    data: pin.Data = field(init=False, repr=False)
    added_mass_per_joint: np.ndarray = field(init=False, repr=False)
    hydro_bodies_with_damping: tuple[HydroBody, ...] = field(init=False, repr=False)
    volume_per_joint_m3: np.ndarray = field(init=False, repr=False)
    center_of_buoyancy_per_joint_m: np.ndarray = field(init=False, repr=False)
    #: What the layers above build from this model once and keep with it (the compiled
    #: dynamics): derived, so neither compared, copied nor pickled.
    cache: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self.data = self.model.createData()
        self.cache = {}
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
        #: the bodies' hulls in their joints' frames, for a free surface
        self.surface_bodies = SurfaceBodies.of(self.hydro_bodies, damped, nj)

    def __getstate__(self) -> dict:
        return {**self.__dict__, "cache": {}}  # e.g. C++ objects: rebuilt on first use

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
    def arm_joints(self) -> ArmJoints:
        """The arm's joints: names, kinds, limits; q <-> one position per joint.

        Raises ModelError for an arm joint of more than one degree of freedom (a ball joint
        built in code: the dynamics take it, a scenario's one-angle-per-joint keys do not).
        """
        if "arm_joints" not in self.cache:
            self.cache["arm_joints"] = ArmJoints.of(self.model, self.source)
        return self.cache["arm_joints"]

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
                "without an arm? mount one with uvms_pin.mount_arm, or name the frame: "
                "[scenario] ee_frame = NAME in a scenario, load_uvms(..., ee_frame=NAME))",
                path=self.source or None,
            )
        return self.ee_frame_id

    def neutral_configuration(self) -> np.ndarray:
        """q at the origin, level, every arm joint at zero (clipped into its limits)."""
        q = pin.neutral(self.model)
        arm = self.arm_joints
        q[7:] = arm.configuration(arm.clip(np.zeros(arm.count)))
        return q

    def copy(self) -> UVMS:
        """An independent UVMS sharing the static parts (the Pinocchio model, the bodies'
        hydrodynamics and the arrays derived from them, all read-only) but with its own
        work buffer and its own `cache` (the compiled dynamics are built again)."""
        return self.with_model(self.model)

    def with_model(self, model: pin.Model) -> UVMS:
        """The same hydrodynamics and frames on another (e.g. re-scaled) Pinocchio model:
        what is derived from the hydrodynamics is shared when ``model`` has the same joints
        (it depends on nothing else), rebuilt otherwise."""
        if model.njoints != self.model.njoints or list(model.names) != list(self.model.names):
            return dataclasses.replace(self, model=model)
        out = copy.copy(self)
        out.model = model
        out.data = model.createData()
        out.cache = {}
        return out

    def with_hydro(self, transform: Callable[[HydroBody], HydroParams]) -> UVMS:
        """A UVMS whose every body's params are replaced by ``transform(body)``."""
        bodies = tuple(dataclasses.replace(b, params=transform(b)) for b in self.hydro_bodies)
        return dataclasses.replace(self, hydro_bodies=bodies)
