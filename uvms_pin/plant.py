"""The simulated world: a UVMS in water, with an environment and disturbances.

`Plant.acceleration` is the right-hand side of the closed loop; the controller is not part
of it (it sees only a `Measurement`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.actuation import Actuation, Unlimited
from uvms_pin.dynamics import forward_dynamics
from uvms_pin.environment import ContactModel, Disturbance
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.flow import FlowField, SumFlow, UniformCurrent
from uvms_pin.model import UVMS


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
    """

    uvms: UVMS
    current_world_m_s: np.ndarray = field(default_factory=lambda: np.zeros(3))
    contact: ContactModel | None = None
    disturbance: Disturbance | None = None
    actuation: Actuation = field(default_factory=Unlimited)
    flow: FlowField | None = None

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

    def ee_state(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """End-effector position, linear velocity (world) and its LOCAL_WORLD_ALIGNED Jacobian."""
        model, data, fid = self.uvms.model, self._ee_data, self.uvms.ee_frame_id
        pin.forwardKinematics(model, data, q, v)
        position = pin.updateFramePlacement(model, data, fid).translation.copy()
        velocity = pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear.copy()
        return position, velocity, data

    def attach(self, q0: np.ndarray) -> None:
        """Anchor the environment at the initial end-effector position."""
        if self.contact is not None:
            position, _, _ = self.ee_state(q0, np.zeros(self.uvms.nv))
            self.contact.attach(position)

    def contact_wrench(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """lambda (6,): the wrench the end-effector exerts on the environment, world axes."""
        if self.contact is None:
            return np.zeros(6)
        position, velocity, _ = self.ee_state(q, v)
        return self.contact.wrench_on_environment_world(position, velocity)

    def disturbance_wrench(self, time_s: float) -> np.ndarray:
        return (
            np.zeros(6)
            if self.disturbance is None
            else np.asarray(self.disturbance(time_s), dtype=float)
        )

    def acceleration(
        self,
        time_s: float,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        contact_world: np.ndarray | None = None,
    ) -> np.ndarray:
        """zeta_dot of  M zeta_dot + h + J_c^T lambda + delta = tau  (docs/physics.md)."""
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
            self.uvms, q, v, tau, tau_ext=tau_ext, flow=self._flow, time_s=time_s
        )
