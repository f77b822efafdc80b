"""The moving contacts of a system of bodies: the world's free objects (each a floating body
of its own), its fixtures' links (`uvms_pin.physics.world.fixture`) and, on request, the
arm against its own vehicle.

Each contact force between two moving bodies is exchanged equal and opposite
(`uvms_pin.physics.world.moving`); a free object meets the fixed objects as the robot does.
The bodies' states (free objects', then fixtures') are the system's (`uvms_pin.sim.system.SystemState`): passed in, never
kept here. What is kept is the contacts' friction state (their anchors), which moves once a
control period, as the robot's does.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.world.moving import MovingContacts, State
from uvms_pin.physics.world.overlap import (
    Overlap,
    overlaps,
    robot_clear_of_fixtures,
    separated,
)
from uvms_pin.physics.world.world import World
from uvms_pin.results.signal import component_label

__all__ = ["FreeObjects", "State"]

#: per object, the logged components and their units: position (world) [m], quaternion
#: (x, y, z, w), body velocity [m/s] and angular velocity [rad/s]
_STATE_COLUMNS = (
    ("x", "m"), ("y", "m"), ("z", "m"), ("qx", ""), ("qy", ""), ("qz", ""), ("qw", ""),
    ("u", "m/s"), ("v", "m/s"), ("w", "m/s"), ("p", "rad/s"), ("q", "rad/s"), ("r", "rad/s"),
)  # fmt: skip


class FreeObjects:
    """The free objects of ``world`` (possibly none, with self-collision only) and the
    moving contacts between them, the robot ``uvms`` and the fixed objects."""

    def __init__(self, uvms: UVMS, world: World):
        self.uvms = uvms
        self.objects = world.free
        self.moving = MovingContacts.of(world)
        self.bodies = self.moving.bodies  # the free objects, then the fixtures
        self.uvms_data = uvms.model.createData()
        self.datas = [o.uvms.model.createData() for o in self.bodies]

    def initial_states(self) -> list[State]:
        """Each body's state at t = 0 (copies): the free objects', then the fixtures'."""
        return [(o.q0.copy(), o.v0.copy()) for o in self.bodies]

    def apart(self, q: np.ndarray, states: list[State]) -> tuple[list[State], list[Overlap]]:
        """(the objects' states, the moves made) at the start with the robot at ``q``: no
        object deeper than the tolerance in another body, else refused or moved out as the
        world says (`uvms_pin.physics.world.overlap.separated`)."""

        def overlaps_at(states: list[State]) -> list[Overlap]:
            self._kinematics(q, np.zeros(self.uvms.nv), states)
            return overlaps(self.moving, self.uvms_data, self.datas)

        return separated(states, overlaps_at, self.moving.world.initial_overlap)

    def check_robot_clear(self, q: np.ndarray, states: list[State]) -> None:
        """`InitialOverlapError` if the robot at ``q`` starts inside a fixture's link, the
        bodies at ``states`` (`uvms_pin.physics.world.overlap.robot_clear_of_fixtures`)."""
        self._kinematics(q, np.zeros(self.uvms.nv), states)
        robot_clear_of_fixtures(self.moving, self.uvms_data, self.datas)

    def reset(self) -> None:
        """Every anchor forgotten."""
        self.moving.clear()

    # ---- the contacts at a state ------------------------------------------------------
    def _kinematics(self, q: np.ndarray, v: np.ndarray, states: list[State]) -> None:
        pin.forwardKinematics(self.uvms.model, self.uvms_data, q, v)
        for obj, data, (q_o, v_o) in zip(self.bodies, self.datas, states, strict=True):
            pin.forwardKinematics(obj.uvms.model, data, q_o, v_o)

    def found(self, q: np.ndarray, v: np.ndarray, states: list[State]):
        """The moving contacts at the robot's (q, zeta) and the objects' ``states``."""
        self._kinematics(q, v, states)
        return self.moving.contacts(self.uvms_data, self.datas)

    def torques(self, q: np.ndarray, v: np.ndarray, states: list[State]):
        """(tau on the robot (nv,), tau on each object (6,)) of the moving contacts."""
        found = self.found(q, v, states)
        return self.moving.generalized(q, self.uvms_data, states, self.datas, found)

    def near(self, q: np.ndarray, v: np.ndarray, states: list[State], horizon_s: float) -> bool:
        """Some moving pair may touch within ``horizon_s``."""
        self._kinematics(q, v, states)
        return self.moving.near(self.uvms_data, self.datas, horizon_s)

    def wrenches(self, q: np.ndarray, v: np.ndarray, states: list[State]):
        """(the robot's pairs' wrenches, the objects' pairs' wrenches), flattened."""
        return self.moving.wrenches(self.found(q, v, states))

    def settle(self, q: np.ndarray, v: np.ndarray, states: list[State]) -> None:
        """After a control period: the friction anchors move."""
        found = self.found(q, v, states)
        self.moving.commit(self.uvms_data, self.datas, found)

    # ---- what a run logs ------------------------------------------------------------------
    def state_columns(self) -> tuple[list[str], list[str]]:
        """(component names, units) of the logged ``free_objects`` signal, per object."""
        labels = [component_label(o.name) for o in self.objects]
        names = [f"{label}_{c}" for label in labels for c, _ in _STATE_COLUMNS]
        return names, [u for _ in self.objects for _, u in _STATE_COLUMNS]
