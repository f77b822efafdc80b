"""A robot in the water: a UVMS (or a bare vehicle), the water around it, what it touches and
what pushes it.

`Plant.acceleration` is the robot's right-hand side; the controller is not part of it (it
sees only a `Measurement`). What moves with the robot (free objects) and how a control period
is stepped belong to the system of bodies (`uvms_pin.sim.system.System`).

With ``backend="core"`` (default) the right-hand side runs in the compiled core: the plant's
counterpart (`src/uvms_core/plant.hpp`, built in `uvms_pin.sim.compiled.plant`) mirrors its
flow, contact, disturbance, joint stops, joint friction, the model's fins
(`uvms_pin.physics.fins`) and world, rebuilt when a run starts (`attach`) or on first use;
when one part has none (e.g. a disturbance written in Python) the plant computes on the Python reference and says so once with a `CoreFallbackWarning`. The
world contacts' friction state (`friction`, a `FrictionMemory`) stays on this plant for both
backends: the compiled calls read it and write it back.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector, flag, number
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.flow import FlowField, SumFlow, UniformCurrent
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import Backend, Fallback, backend_named
from uvms_pin.physics.configuration import checked_configuration
from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.contact import ContactModel
from uvms_pin.physics.disturbance import Disturbance
from uvms_pin.physics.dynamics import forward_dynamics
from uvms_pin.physics.fins import fin_generalized_force, fin_wrenches_world
from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.physics.surface import wet_state
from uvms_pin.physics.world.world import ContactForces, FrictionMemory, World
from uvms_pin.sim.actuation import Actuation, Unlimited
from uvms_pin.sim.compiled.plant import plant_to_core

#: a plant's optional parts and their kinds
_PARTS = {
    "contact": ContactModel,
    "flow": FlowField,
    "joint_friction": JointFriction,
    "world": World,
    "joint_stops": JointStops,
    "joint_limits": JointLimits,
    "joint_coulomb": JointCoulombFriction,
}


@dataclass
class Plant:
    """A UVMS, the water around it, what it touches and what pushes it.

    Attributes:
        uvms: the loaded model.
        current_world_m_s: constant uniform current (3,) [m/s].
        contact: compliant environment at the end-effector, or None.
        disturbance: body wrench on the vehicle as a function of time, or None.
        actuation: thrusters and joint limits between the commanded and applied tau.
        flow: waves, sea states or varying currents (`uvms_pin.flow`), added to the
            uniform current; None for none.
        backend: "core" (compiled, default) or "python" (the reference implementation).
        free_surface: the water has a top, z = 0 or the waves' elevation, and each body is
            cut by it (`uvms_pin.physics.surface`): it floats, surfaces, leaves the water.
            The default. False: water without a top (every body wholly wet wherever it is).
        stop_at_surface: end the run (SimulationError) when a body's centre of buoyancy
            rises above the surface: for models meant for submerged bodies only.
        joint_friction: viscous and Coulomb friction of the arm's joint drives, a
            generalized force in the dynamics (`uvms_pin.physics.joint_friction`); None: none.
        world: fixed objects every body's collision geometry touches (the seafloor, rocks,
            structures; `uvms_pin.physics.world`), or None.
        joint_stops: compliant stops at the arm joints' limits, or None (no stops).
        joint_limits: the arm joints' limits as constraints solved implicitly once a control
            period (`uvms_pin.physics.constraints`: a joint stops at its limit whatever its
            inertia), or None; not with ``joint_stops``.
        joint_coulomb: the arm joints' Coulomb friction as constraints solved implicitly
            once a control period (`uvms_pin.physics.constraints.joint_friction`: a joint
            loaded below its friction torque does not move), or None; ``joint_friction``
            then carries only the viscous part.
    """

    uvms: UVMS
    current_world_m_s: np.ndarray = field(default_factory=lambda: np.zeros(3))
    contact: ContactModel | None = None
    disturbance: Disturbance | None = None
    actuation: Actuation = field(default_factory=Unlimited)
    flow: FlowField | None = None
    backend: str = "core"
    free_surface: bool = True
    stop_at_surface: bool = False
    joint_friction: JointFriction | None = None
    world: World | None = None
    joint_stops: JointStops | None = None
    joint_limits: JointLimits | None = None
    joint_coulomb: JointCoulombFriction | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.uvms, UVMS):
            raise ParameterError(f"uvms must be a UVMS (uvms_pin.load_uvms), got {self.uvms!r}")
        for key, kind in _PARTS.items():
            part = getattr(self, key)
            if part is not None and not isinstance(part, kind):
                raise ParameterError(f"{key} must be a {kind.__name__} (or None), got {part!r}")
        if not isinstance(self.actuation, Actuation):
            raise ParameterError(f"actuation must be an Actuation, got {self.actuation!r}")
        if self.disturbance is not None and not callable(self.disturbance):
            raise ParameterError(
                f"disturbance must be a function of time [s] (or None), got {self.disturbance!r}"
            )
        self.free_surface = flag("free_surface", self.free_surface)
        self.stop_at_surface = flag("stop_at_surface", self.stop_at_surface)
        self.current_world_m_s = finite_vector("current_world_m_s", self.current_world_m_s, 3)
        if self.contact is not None:
            self.uvms.require_ee_frame("a contact environment (at the end-effector)")
        if (
            self.joint_friction is not None
            and self.joint_friction.viscous_Nms.size != self.uvms.nv - 6
        ):
            raise ParameterError(
                f"joint friction for {self.joint_friction.viscous_Nms.size} joints, the model has {self.uvms.nv - 6}"
            )
        if self.world is not None and self.world.uvms is not self.uvms:
            raise ParameterError("the plant's world was built for another UVMS")
        if self.joint_limits is not None and self.joint_stops is not None:
            raise ParameterError(
                "the joints' limits are either compliant stops (joint_stops) or constraints "
                "(joint_limits), not both"
            )
        self._backend: Backend = backend_named(self.backend)
        self._ee_data = self.uvms.model.createData()
        self._world_data = self.uvms.model.createData()
        self._fin_data = self.uvms.model.createData()
        self.friction = FrictionMemory()  # the world contacts' state (anchors)
        self.water = water_of(self.current_world_m_s, self.flow)

    def record(self) -> dict[str, Any]:
        """The world this plant simulates, as plain data (a rollout saves it; figures and
        replays draw it): water density, the uniform current, the whole flow and the
        contact (as attached)."""
        return {
            "water_density_kg_m3": float(self.uvms.water_density_kg_m3),
            "current_world_m_s": self.current_world_m_s.tolist(),
            "flow": None if self.water is None else self.water.record(),
            "contact": None if self.contact is None else self.contact.record(),
            "free_surface": bool(self.free_surface),
            "world": None if self.world is None else self.world.record(),
            "joint_stops": None if self.joint_stops is None else self.joint_stops.record(),
            "joint_limits": None if self.joint_limits is None else self.joint_limits.record(),
            **(
                {}
                if self.joint_coulomb is None
                else {"joint_coulomb_Nm": self.joint_coulomb.coulomb_Nm.tolist()}
            ),
        }

    def check_submerged(self, time_s: float, q: np.ndarray) -> None:
        """With ``stop_at_surface``: raise SimulationError when a body's centre of buoyancy
        is above the free surface (z = 0, or the waves' elevation there)."""
        if not self.stop_at_surface:
            return
        model, data = self.uvms.model, self._ee_data
        pin.forwardKinematics(model, data, q)
        for body in self.uvms.hydro_bodies:
            if body.params.volume_m3 <= 0.0:
                continue
            cob = data.oMi[body.joint_id].act(
                body.placement_in_joint.act(body.params.center_of_buoyancy_m)
            )
            eta = 0.0 if self.water is None else self.water.surface_elevation(time_s, cob[:2])
            eta = float(np.asarray(eta).reshape(-1)[0])
            if cob[2] > eta:
                raise SimulationError(
                    f"link '{body.name}' reached the free surface at t = {time_s:.6g} s: its "
                    f"centre of buoyancy is {cob[2] - eta:.3g} m above the surface "
                    f"(eta = {eta:.3g} m) and the run stops there ([water] stop_at_surface)"
                )

    def wet_fractions(self, time_s: float, q: np.ndarray) -> np.ndarray:
        """Each hull's wet fraction f in [0, 1] at (t, q) (``uvms.surface_bodies`` order):
        1 deep, 0 out of the water; all 1 without a free surface."""
        bodies = self.uvms.surface_bodies
        if not self.free_surface:
            return np.ones(len(bodies))
        data = self._ee_data
        pin.forwardKinematics(self.uvms.model, data, q)
        state = wet_state(self.uvms, data, self.water, time_s)
        return np.ones(len(bodies)) if state is None else state.fraction.copy()

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_compiled", None)  # a C++ object: rebuilt on first use after unpickling
        return state

    @property
    def compiled(self) -> Any | None:
        """The compiled plant (`uvms_pin.sim.compiled.plant`), or None: the Python reference
        computes (warned once when the core was asked for)."""
        if "_compiled" not in self.__dict__:
            compiled = self._backend.counterpart(lambda core: plant_to_core(self, core))
            if isinstance(compiled, Fallback):
                compiled.warn("this plant", stacklevel=4)
                compiled = None
            self._compiled = compiled
        return self._compiled

    def ee_state(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """End-effector position, linear velocity (world) and its LOCAL_WORLD_ALIGNED Jacobian."""
        model, data, fid = self.uvms.model, self._ee_data, self.uvms.ee_frame_id
        try:
            pin.forwardKinematics(model, data, q, v)
        except (TypeError, ValueError):  # Pinocchio's: the wrong input named first
            _check_state(self.uvms, 0.0, q, v, np.zeros(model.nv))
            raise
        position = pin.updateFramePlacement(model, data, fid).translation.copy()
        velocity = pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear.copy()
        return position, velocity, data

    def attach(self, q0: np.ndarray) -> None:
        """Anchor the environment at the initial end-effector position, anchor the friction of
        every world contact at t = 0 where it is, and take the current and flow as they are
        now (the compiled plant is rebuilt from them)."""
        if self.contact is not None:
            position, _, _ = self.ee_state(q0, np.zeros(self.uvms.nv))
            self.contact.attach(position)
        self.friction.clear()
        # what touches at t = 0 sticks where it is (a body placed on the seafloor stays)
        self.settle(q0, np.zeros(self.uvms.nv))
        self.water = water_of(self.current_world_m_s, self.flow)
        self.__dict__.pop("_compiled", None)

    def contact_wrench(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """lambda (6,): the wrench the end-effector exerts on the environment, world axes."""
        if self.contact is None:
            return np.zeros(6)
        compiled = self.compiled
        if compiled is not None:
            return compiled.contact_wrench(q, v)
        position, velocity, _ = self.ee_state(q, v)
        return self.contact.wrench_on_environment_world(position, velocity)

    def world_forces(self, q: np.ndarray, v: np.ndarray) -> ContactForces | None:
        """The world's contact points and forces at (q, v) (None without a world)."""
        if self.world is None:
            return None
        if not self.world.objects:  # a world of moving bodies alone: nothing fixed to touch
            return ContactForces.none()
        pin.forwardKinematics(self.uvms.model, self._world_data, q, v)
        return self.world.forces(self._world_data, self.friction)

    def external_torque(
        self, q: np.ndarray, v: np.ndarray, extra_torque: np.ndarray | None = None
    ) -> np.ndarray:
        """The fixed world's contact forces and the joint stops as generalized forces (nv,),
        plus ``extra_torque``: what the system of bodies adds (the moving contacts: free
        objects, the arm against its vehicle)."""
        out = np.zeros(self.uvms.nv) if extra_torque is None else np.array(extra_torque)
        forces = self.world_forces(q, v)
        if forces is not None:
            out += self.world.generalized_force(q, self._world_data, forces)
        if self.joint_stops is not None:
            out += self.joint_stops.torque(q, v)
        return out

    def settle(self, q: np.ndarray, v: np.ndarray) -> None:
        """After a control period: the friction's anchors move (`World.commit`)."""
        forces = self.world_forces(q, v)
        if forces is not None:
            self.world.commit(forces, self.friction)

    def disturbance_wrench(self, time_s: float) -> np.ndarray:
        return (
            np.zeros(6)
            if self.disturbance is None
            else np.asarray(self.disturbance(time_s), dtype=float)
        )

    # ---- dynamics -----------------------------------------------------------------------
    def acceleration(
        self,
        time_s: float,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        contact_world: np.ndarray | None = None,
        extra_torque: np.ndarray | None = None,
    ) -> np.ndarray:
        """zeta_dot of  M zeta_dot + h + J_c^T lambda + delta = tau + [0; tau_f(v)] + tau_world
        + tau_stop (docs/physics.md; tau_f the joint drives' friction). With a world the
        contact at the anchors of ``friction``, compiled with the rest on the core;
        ``extra_torque`` as in `external_torque` (given: the Python reference computes, as
        for the moving contacts of a system of bodies)."""
        try:
            compiled = self.compiled
            if compiled is not None and extra_torque is None:
                if self.world is None:
                    return compiled.acceleration(time_s, q, v, tau, contact_world)
                if contact_world is None:
                    return compiled.acceleration_in_world(time_s, q, v, tau, self.friction)
            number("time_s", time_s)  # (the core's own check: its argument's type)
            model = self.uvms.model
            tau_ext = np.zeros(model.nv)
            if self.joint_friction is not None:
                tau_ext[6:] += self.joint_friction.torque_Nm(v[6:])
            if self.contact is not None:
                if contact_world is None:
                    contact_world = self.contact_wrench(q, v)
                jac = pin.computeFrameJacobian(
                    model, self._ee_data, q, self.uvms.ee_frame_id, pin.LOCAL_WORLD_ALIGNED
                )
                tau_ext -= jac.T @ contact_world
            if self.disturbance is not None:
                # the free-flyer's LOCAL Jacobian is [I 0]: a body wrench maps to tau[:6] directly
                tau_ext[:6] -= self.disturbance_wrench(time_s)
            if self.world is not None or self.joint_stops is not None or extra_torque is not None:
                tau_ext += self.external_torque(q, v, extra_torque)
            if self.uvms.fins:  # lift and drag (the compiled plant's: src/uvms_core/fins.hpp)
                wrenches = fin_wrenches_world(
                    self.uvms, self._fin_data, q, v, self.water, time_s, bool(self.free_surface)
                )
                tau_ext += fin_generalized_force(self.uvms, self._fin_data, q, wrenches)
            return forward_dynamics(
                self.uvms,
                q,
                v,
                tau,
                tau_ext=tau_ext,
                flow=self.water,
                time_s=time_s,
                backend=self.backend,
                free_surface=self.free_surface,
            )
        except (TypeError, ValueError):  # the core's, Pinocchio's: a wrong input named first
            _check_state(self.uvms, time_s, q, v, tau)
            raise

    def acceleration_derivatives(
        self, time_s: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(da/dq, da/dv, da/dtau) of `acceleration` (`uvms_pin.sim.plant_derivatives`)."""
        from uvms_pin.sim.plant_derivatives import acceleration_derivatives

        return acceleration_derivatives(
            self, time_s, q, v, tau, compiled=self.compiled, scratch=self._world_data
        )


def _check_state(uvms: UVMS, time_s: float, q, v, tau) -> None:
    """ParameterError naming the first of ``time_s``, ``q``, ``v``, ``tau`` that is not what
    `Plant.acceleration` takes (called after the core or Pinocchio refused a call: nothing is
    checked on the way of every call)."""
    number("time_s", time_s)
    checked_configuration("q", q, uvms.model)  # (a quaternion off the unit sphere named)
    finite_vector("v", v, uvms.nv)
    finite_vector("tau", tau, uvms.nv)


def water_of(current_world_m_s: np.ndarray, flow: FlowField | None) -> FlowField | None:
    """The one flow the bodies see: the uniform current and ``flow`` (None: still water)."""
    fields = [UniformCurrent(current_world_m_s)] if np.any(current_world_m_s) else []
    fields += [flow] if flow is not None else []
    if not fields:
        return None
    return fields[0] if len(fields) == 1 else SumFlow(tuple(fields))


def has_moving_contacts(world: World | None) -> bool:
    """A world in which more than the robot moves (free objects, fixtures with joints) or the
    arm can hit its own vehicle: its contacts are the system of bodies' (`uvms_pin.sim.system`)."""
    return world is not None and bool(world.free or world.fixtures or world.self_collision)


def checked_start(
    model: pin.Model, q0: np.ndarray, v0: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Copies of a starting state (q0 (nq,), v0 (nv,)) with the vehicle's quaternion
    normalised; a ParameterError for a wrong size or a non-finite value."""
    q0 = finite_vector("q0", q0, model.nq).copy()
    v0 = finite_vector("v0", v0, model.nv).copy()
    norm = np.linalg.norm(q0[3:7])
    if not norm > 1e-6:  # no orientation to normalise (a quaternion of zeros: NaN)
        raise ParameterError(f"q0's quaternion q0[3:7] = {q0[3:7].tolist()} is not a rotation")
    q0[3:7] /= norm
    return q0, v0
