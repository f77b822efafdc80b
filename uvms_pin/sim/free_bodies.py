"""The free objects of a world in the plant: their states, and their integration with the
UVMS's as one system.

The system's state stacks the UVMS's (q, zeta) and each free object's (pose (7,), body
velocity (6,)); its configuration space is that of a Pinocchio model made of the UVMS's
joints and one free-flyer per object (used only to integrate on the manifold, so that the
plant's integrators step the whole system with their own rules). Each stage evaluates

    zeta_dot   = FD_uvms(q, zeta, tau + tau_contact,uvms)
    nu_dot_o   = FD_o(q_o, nu_o, tau_contact,o)                 (each object o)

with every contact force between two moving bodies exchanged equal and opposite
(`uvms_pin.physics.world.moving`) and the water (current, waves, free surface) the same for
all. The objects' friction anchors move once a control period, as the UVMS's do.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.physics.dynamics import forward_dynamics
from uvms_pin.physics.world.moving import MovingContacts, State
from uvms_pin.sim.integrators import Integrator

__all__ = ["FreeBodies"]

#: why a run with free objects integrates in Python (its metadata says so)
PYTHON_PATH = (
    "free objects: the system (UVMS and objects) is integrated by the Python integrator "
    "around the compiled dynamics (the compiled plant has no free objects yet)"
)


def _system_model(uvms_model: pin.Model, n_objects: int) -> pin.Model:
    """The UVMS's joints and ``n_objects`` free-flyers under the universe (integration only)."""
    model = pin.Model(uvms_model)
    for k in range(n_objects):
        model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"free_object_{k}")
    return model


class FreeBodies:
    """The free objects' states and the moving contacts, for one plant (a
    `uvms_pin.sim.plant.Plant`: its UVMS, world, water and dynamics)."""

    def __init__(self, plant: Any):
        world = plant.world
        self.plant = plant
        self.objects = world.free
        self.moving = MovingContacts.of(world)
        self.model = _system_model(plant.uvms.model, len(self.objects))
        self.uvms_data = plant.uvms.model.createData()
        self.datas = [o.uvms.model.createData() for o in self.objects]
        self.states: list[State] = []
        self.reset()

    def reset(self) -> None:
        """Every object back at its initial state, every anchor forgotten."""
        self.states = [(o.q0.copy(), o.v0.copy()) for o in self.objects]
        self.moving.clear()

    # ---- the contacts at a state ------------------------------------------------------
    def _kinematics(self, q: np.ndarray, v: np.ndarray, states: list[State]) -> None:
        pin.forwardKinematics(self.plant.uvms.model, self.uvms_data, q, v)
        for obj, data, (q_o, v_o) in zip(self.objects, self.datas, states, strict=True):
            pin.forwardKinematics(obj.uvms.model, data, q_o, v_o)

    def found(self, q: np.ndarray, v: np.ndarray, states: list[State] | None = None):
        """The moving contacts at (q, zeta) and the objects' states (now's by default)."""
        states = self.states if states is None else states
        self._kinematics(q, v, states)
        return self.moving.contacts(self.uvms_data, self.datas)

    def torques(self, q, v, states: list[State] | None = None):
        """(tau on the UVMS (nv,), tau on each object (6,)) of the moving contacts."""
        states = self.states if states is None else states
        found = self.found(q, v, states)
        return self.moving.generalized(q, self.uvms_data, states, self.datas, found)

    def near(self, q: np.ndarray, v: np.ndarray, horizon_s: float) -> bool:
        """Some moving pair may touch within ``horizon_s`` (the UVMS's own, without objects)."""
        self._kinematics(q, v, self.states)
        return self.moving.near(self.uvms_data, self.datas, horizon_s)

    def wrenches(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.moving.wrenches(self.found(q, v))

    def settle(self, q: np.ndarray, v: np.ndarray) -> None:
        """After a control period: the friction anchors move."""
        found = self.found(q, v)
        self.moving.commit(self.uvms_data, self.datas, found)

    # ---- the system ---------------------------------------------------------------------
    def _split(self, q_sys: np.ndarray, v_sys: np.ndarray):
        nq, nv = self.plant.uvms.nq, self.plant.uvms.nv
        states = [
            (q_sys[nq + 7 * k : nq + 7 * (k + 1)], v_sys[nv + 6 * k : nv + 6 * (k + 1)])
            for k in range(len(self.objects))
        ]
        return q_sys[:nq], v_sys[:nv], states

    def acceleration(self, t: float, q_sys, v_sys, tau: np.ndarray) -> np.ndarray:
        """The system's acceleration (nv + 6 n_objects,) with ``tau`` on the UVMS."""
        plant = self.plant
        q, v, states = self._split(q_sys, v_sys)
        tau_uvms, tau_objects = self.torques(q, v, states)
        out = [plant.acceleration(t, q, v, tau, extra_torque=tau_uvms)]
        for obj, (q_o, v_o), tau_o in zip(self.objects, states, tau_objects, strict=True):
            out.append(
                forward_dynamics(
                    obj.uvms, q_o, v_o, np.zeros(6), tau_ext=tau_o, flow=plant.water,
                    time_s=t, backend=plant.backend, free_surface=plant.free_surface,
                )
            )  # fmt: skip
        return np.concatenate(out)

    def advance(
        self, integrator: Integrator, t0: float, q0, v0, tau: np.ndarray, t1: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The UVMS's (q, zeta) at t1; the objects' states move with it."""
        q_sys = np.concatenate([q0, *[s[0] for s in self.states]])
        v_sys = np.concatenate([v0, *[s[1] for s in self.states]])
        q_sys, v_sys = integrator.advance(
            self.model, lambda t, q, v: self.acceleration(t, q, v, tau), t0, q_sys, v_sys, t1
        )
        q1, v1, states = self._split(q_sys, v_sys)
        self.states = [(q_o.copy(), v_o.copy()) for q_o, v_o in states]
        return q1.copy(), v1.copy()

    # ---- what a run logs ------------------------------------------------------------------
    def state_columns(self) -> tuple[list[str], list[str]]:
        """(component names, units) of the logged ``free_objects`` signal: per object its
        position (world) [m], quaternion (x, y, z, w), body velocity [m/s] and angular
        velocity [rad/s]."""
        parts = [
            ("x", "m"), ("y", "m"), ("z", "m"), ("qx", ""), ("qy", ""), ("qz", ""), ("qw", ""),
            ("u", "m/s"), ("v", "m/s"), ("w", "m/s"), ("p", "rad/s"), ("q", "rad/s"),
            ("r", "rad/s"),
        ]  # fmt: skip
        labels = [re.sub(r"\W", "_", o.name) for o in self.objects]
        names = [f"{label}_{c}" for label in labels for c, _ in parts]
        return names, [u for _ in self.objects for _, u in parts]

    def state_values(self) -> np.ndarray:
        """The objects' states now, in the order of `state_columns`."""
        return np.concatenate([np.concatenate(s) for s in self.states])

    def record(self) -> dict[str, Any]:
        return {"integration": PYTHON_PATH} if self.objects else {}
