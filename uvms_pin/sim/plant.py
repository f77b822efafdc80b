"""The simulated world: a UVMS in water, with an environment and disturbances.

`Plant.acceleration` is the right-hand side of the closed loop; the controller is not part
of it (it sees only a `Measurement`). `Plant.advance` moves the plant over one control period
with the input held.

With ``backend="core"`` (default) both run in the compiled core (`uvms_pin.physics.compiled`): the whole
period (every integrator stage, contact, disturbance, held tau) is one C++ call. The core
knows the current, `LinearSpring`, `CompliantPlane` and `SinusoidalDisturbance`; a plant with
anything else (e.g. a disturbance written in Python) runs on the Python reference, and says
so once with a `CoreFallbackWarning`. The compiled plant reads the current, contact and
disturbance when it is built: at `attach` (the start of every simulation) or first use.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.flow import FlowField, SumFlow, UniformCurrent
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled import (
    CoreFallbackWarning,
    check_backend,
    compiled_flow,
    core_module,
    dynamics_of,
)
from uvms_pin.physics.dynamics import forward_dynamics
from uvms_pin.physics.environment import (
    CompliantPlane,
    ContactModel,
    Disturbance,
    LinearSpring,
    SinusoidalDisturbance,
)
from uvms_pin.sim.actuation import Actuation, Unlimited
from uvms_pin.sim.integrators import Chart, Integrator


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
    """

    uvms: UVMS
    current_world_m_s: np.ndarray = field(default_factory=lambda: np.zeros(3))
    contact: ContactModel | None = None
    disturbance: Disturbance | None = None
    actuation: Actuation = field(default_factory=Unlimited)
    flow: FlowField | None = None
    backend: str = "core"

    def __post_init__(self) -> None:
        c = np.asarray(self.current_world_m_s, dtype=float).reshape(-1)
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise ParameterError(
                f"current_world_m_s must be 3 finite numbers, got {self.current_world_m_s}"
            )
        self.current_world_m_s = c
        if self.contact is not None:
            self.uvms.require_ee_frame("a contact environment (at the end-effector)")
        if self.flow is not None and not isinstance(self.flow, FlowField):
            raise ParameterError(f"flow must be a FlowField, got {type(self.flow).__name__}")
        check_backend(self.backend)
        self._ee_data = self.uvms.model.createData()
        self._flow = self.water_flow

    @property
    def water_flow(self) -> FlowField | None:
        """The whole flow the bodies see: the uniform current plus ``flow``."""
        fields = [UniformCurrent(self.current_world_m_s)] if np.any(self.current_world_m_s) else []
        if self.flow is not None:
            fields.append(self.flow)
        if not fields:
            return None
        return fields[0] if len(fields) == 1 else SumFlow(tuple(fields))

    def check_submerged(self, time_s: float, q: np.ndarray) -> None:
        """Raise SimulationError when a body's centre of buoyancy is above the wave surface.

        Only for flows with a moving free surface (waves): the hydrodynamics here are those
        of a fully submerged body, so a body reaching the surface ends the run, reported.
        """
        if self.flow is None or not self.flow.has_free_surface:
            return
        model, data = self.uvms.model, self._ee_data
        pin.forwardKinematics(model, data, q)
        for body in self.uvms.hydro_bodies:
            if body.params.volume_m3 <= 0.0:
                continue
            cob = data.oMi[body.joint_id].act(
                body.placement_in_joint.act(body.params.center_of_buoyancy_m)
            )
            eta = float(self.flow.surface_elevation(time_s, cob[None, :2])[0])
            if cob[2] > eta:
                raise SimulationError(
                    f"link '{body.name}' reached the free surface at t = {time_s:.6g} s: its "
                    f"centre of buoyancy is {cob[2] - eta:.3g} m above the wave surface "
                    f"(eta = {eta:.3g} m); the model holds for submerged bodies only"
                )

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_compiled", None)  # a C++ object: rebuilt on first use after unpickling
        return state

    # ---- the compiled plant -----------------------------------------------------------
    def _unsupported(self) -> str | None:
        """What the core cannot represent, or None."""
        if self.contact is not None and type(self.contact) not in (LinearSpring, CompliantPlane):
            return f"contact model {type(self.contact).__name__}"
        if self.disturbance is not None and type(self.disturbance) is not SinusoidalDisturbance:
            return f"disturbance {self.disturbance!r}"
        if self.flow is not None and compiled_flow(self.flow) is None:
            return f"flow {self.flow!r}"
        return None

    def _build_compiled(self):
        """The compiled plant mirroring this one, or None (Python path)."""
        if self.backend != "core":
            return None
        unsupported = self._unsupported()
        if unsupported is not None:
            warnings.warn(
                f"the compiled core does not support the {unsupported}: this plant runs on "
                "the Python reference (slower)",
                CoreFallbackWarning,
                stacklevel=3,
            )
            return None
        # the compiled plant uses the end-effector frame for contact only, which a model
        # without one cannot have (checked above): frame 0 (the world) stands in
        ee_frame_id = self.uvms.ee_frame_id if self.uvms.has_end_effector else 0
        compiled = core_module().Plant(dynamics_of(self.uvms), ee_frame_id)
        compiled.set_flow(*compiled_flow(self._flow))  # the current plus any waves
        contact = self.contact
        if isinstance(contact, LinearSpring):
            if contact._anchor is None:
                return None  # not attached: the Python path raises the error
            compiled.set_spring(contact.stiffness_N_m, contact._anchor)
        elif isinstance(contact, CompliantPlane):
            if contact._point is None:
                return None
            compiled.set_plane(
                contact.normal_world,
                contact._point,
                float(contact.stiffness_N_m),
                float(contact.damping_N_s_m),
            )
        if self.disturbance is not None:
            d = self.disturbance
            compiled.set_sinusoidal_disturbance(d.amplitude, float(d.period_s), float(d.phase_rad))
        return compiled

    def _core(self):
        if "_compiled" not in self.__dict__:
            self._compiled = self._build_compiled()
        return self._compiled

    # ---- kinematics of the tip ----------------------------------------------------------
    def ee_state(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """End-effector position, linear velocity (world) and its LOCAL_WORLD_ALIGNED Jacobian."""
        model, data, fid = self.uvms.model, self._ee_data, self.uvms.ee_frame_id
        pin.forwardKinematics(model, data, q, v)
        position = pin.updateFramePlacement(model, data, fid).translation.copy()
        velocity = pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear.copy()
        return position, velocity, data

    def attach(self, q0: np.ndarray) -> None:
        """Anchor the environment at the initial end-effector position (and (re)build the
        compiled plant from the current fields)."""
        if self.contact is not None:
            position, _, _ = self.ee_state(q0, np.zeros(self.uvms.nv))
            self.contact.attach(position)
        self._flow = self.water_flow  # the current and flow as they are now, like the core
        self.__dict__.pop("_compiled", None)

    def contact_wrench(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """lambda (6,): the wrench the end-effector exerts on the environment, world axes."""
        if self.contact is None:
            return np.zeros(6)
        compiled = self._core()
        if compiled is not None:
            return compiled.contact_wrench(q, v)
        position, velocity, _ = self.ee_state(q, v)
        return self.contact.wrench_on_environment_world(position, velocity)

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
    ) -> np.ndarray:
        """zeta_dot of  M zeta_dot + h + J_c^T lambda + delta = tau  (docs/physics.md)."""
        compiled = self._core()
        if compiled is not None:
            return compiled.acceleration(time_s, q, v, tau, contact_world)
        model = self.uvms.model
        tau_ext = np.zeros(model.nv)
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
        return forward_dynamics(
            self.uvms,
            q,
            v,
            tau,
            tau_ext=tau_ext,
            flow=self._flow,
            time_s=time_s,
            backend=self.backend,
        )

    def chart(self) -> Chart | None:
        """The compiled local chart of the adaptive integrators, or None (Python path)."""
        compiled = self._core()
        return None if compiled is None else compiled.chart

    def advance(
        self,
        integrator: Integrator,
        t0: float,
        q0: np.ndarray,
        v0: np.ndarray,
        tau: np.ndarray,
        t1: float,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(q, v) at t1 from (q0, v0) at t0 with the input tau held (zero-order hold).

        One compiled call for the whole interval when the integrator has a compiled
        counterpart (RK4, semi-implicit Euler); the integrator's Python loop otherwise."""
        compiled = self._core()
        if compiled is not None:
            out = integrator.advance_held(compiled, t0, q0, v0, tau, t1)
            if out is not None:
                return out
        return integrator.advance(
            self.uvms.model, lambda t, q, v: self.acceleration(t, q, v, tau), t0, q0, v0, t1
        )
