"""A system of bodies: the robot, the free objects and the fixtures of its world, stepped
together.

The state stacks the robot's (q, zeta), each free object's (pose (7,), body velocity (6,))
and each fixture's joints (q_f, qd_f) (`SystemState`, `Layout`); its configuration space is
that of a Pinocchio model made of the robot's joints, one free-flyer per object and the
fixtures' joints (used to integrate on the manifold, so that every integrator steps the
whole system with its own rules). The right-hand side is

    zeta_dot   = FD_robot(q, zeta, tau + tau_contact,robot)
    nu_dot_o   = FD_o(q_o, nu_o, tau_contact,o)                 (each object o)
    qdd_f      = FD_f(q_f, qd_f, -D_f qd_f + tau_contact,f)     (each fixture f)

with every contact force between two moving bodies exchanged equal and opposite
(`uvms_pin.physics.world.moving`) and the water (current, waves, free surface) the same for
all. A control period is crossed by one period step, chosen once per integrator
(`uvms_pin.sim.system.period`); the contacts' friction anchors move at its end.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.checks import flag
from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.moving import memories_of, search_compiled
from uvms_pin.physics.constraints.attachments import Attachments
from uvms_pin.physics.constraints.moving_contacts import MovingPairContacts
from uvms_pin.physics.constraints.object_contacts import ObjectWorldContacts
from uvms_pin.physics.constraints.step import StalledSolves
from uvms_pin.physics.dynamics import forward_dynamics, mass_matrix
from uvms_pin.sim.compiled.system import system_to_core
from uvms_pin.sim.integrators import Integrator
from uvms_pin.sim.plant import Plant, checked_start, has_moving_contacts
from uvms_pin.sim.system import fixtures as fixture_joints
from uvms_pin.sim.system.free_objects import FreeObjects
from uvms_pin.sim.system.period import PeriodStep, period_step
from uvms_pin.sim.system.state import Layout, SystemState
from uvms_pin.sim.system.system_log import SystemLog

__all__ = ["System"]


def _system_model(robot: pin.Model, n_objects: int) -> pin.Model:
    """The robot's joints and ``n_objects`` free-flyers under the universe (integration)."""
    model = pin.Model(robot)
    for k in range(n_objects):
        model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"free_object_{k}")
    return model


class System:
    """The robot ``plant`` and its world's free objects and fixtures.

    Attributes:
        plant: the robot in its water, with its environment and fixed world.
        moving: the moving contacts (`FreeObjects`), None when only the robot moves and its
            arm does not meet its vehicle.
        objects: the free objects (`uvms_pin.physics.world.FreeObject`), possibly none.
        fixtures: the fixtures (`uvms_pin.physics.world.fixture.Fixture`), after the objects
            in the state; fixture_constraints, fixture_blocks: their joints' limits and
            friction, and each one's part of v and its joints (`sim.system.fixtures`).
        layout: where each body sits in the state. model: the system's Pinocchio model.
        compiled_allowed: the period of a system with free objects may be one compiled call
            (`uvms_pin.sim.system.period`); False: the Python integrator steps it.
        object_contacts: the free objects' rigid contacts with the fixed world, solved with
            the joint limits at each period's end
            (`uvms_pin.physics.constraints.object_contacts`), or None.
        moving_constraints: the rigid contacts between moving bodies, solved with them
            (`uvms_pin.physics.constraints.moving_contacts`), or None.
        log: what a run records of it (`uvms_pin.sim.system.system_log.SystemLog`).
    """

    def __init__(self, plant: Plant, *, compiled: bool = True):
        if not isinstance(plant, Plant):
            raise ParameterError(f"plant must be a Plant, got {plant!r}")
        self.plant = plant
        self.compiled_allowed = flag(
            "compiled", compiled
        )  # False: free objects integrated in Python
        world = plant.world
        self.moving = FreeObjects(plant.uvms, world) if has_moving_contacts(world) else None
        self.objects: tuple = () if self.moving is None else tuple(self.moving.objects)
        self.fixtures: tuple = () if world is None else tuple(world.fixtures)
        if self.fixtures and compiled:  # integrated in Python: its contacts searched compiled
            search_compiled(self.moving.moving.sets, plant.backend)
        uvms = plant.uvms
        self.layout = Layout.of(
            [("robot", uvms.nq, uvms.nv), *[(o.name, 7, 6) for o in self.objects]]
            + [(f.name, f.uvms.nq, f.uvms.nv) for f in self.fixtures]
        )
        model = _system_model(uvms.model, len(self.objects)) if self.objects else uvms.model
        self.model = fixture_joints.system_model(model, self.fixtures) if self.fixtures else model
        # the fixtures' joint limits and friction, solved with the other constraints
        self.fixture_constraints = fixture_joints.constraints(model.njoints, self.fixtures)
        first_v = self.layout.v_slices[1 + len(self.objects)].start if self.fixtures else 0
        self.fixture_blocks = fixture_joints.blocks(model.njoints, first_v, self.fixtures)
        self.object_contacts = self._object_contacts()
        moving = None if self.moving is None else self.moving.moving
        self.moving_constraints = (
            MovingPairContacts(
                moving.sets,
                uvms.model.njoints,
                (len(self.objects), fixture_joints.joint_ids(model.njoints, self.fixtures)),
            )
            if moving is not None and moving.rigid_pairs and moving.sets
            else None
        )
        self.attachments = _attachments(world, self.objects, uvms.model.njoints)
        self._steps: dict[int, tuple[Integrator, PeriodStep]] = {}
        self._data = uvms.model.createData()  # the bound test's kinematics
        self.separations: list = []  # the objects' moves out of an overlap at the start
        self.stalled = StalledSolves()  # the run's constraint solves accepted after stalling
        self.log = SystemLog(self)

    def _object_contacts(self) -> ObjectWorldContacts | None:
        """The free objects' rigid contacts with the fixed world (`World.fixed_contact`
        "rigid"), None when they have none or touch it by the compliant law."""
        moving = None if self.moving is None else self.moving.moving
        if moving is None or not moving.rigid or not any(moving.object_worlds):
            return None
        first = self.plant.uvms.model.njoints  # each object's free-flyer (_system_model)
        joints = [first + k for k in range(len(self.objects))]
        return ObjectWorldContacts(moving.object_worlds, joints, moving.object_memory)

    # ---- the state ------------------------------------------------------------------------
    def initial_state(self, q0: np.ndarray, v0: np.ndarray) -> SystemState:
        """The state at t = 0: the robot at (q0, v0) (checked, its quaternion normalised),
        every free object where its scenario puts it (moved out of another body when its
        world asks so, the moves kept in `separations`; else InitialOverlapError). The robot's
        own start inside a fixed object is not checked here: a run checks it where it starts
        (`uvms_pin.sim.closed_loop.ClosedLoop.start`, the vector environments)."""
        q0, v0 = checked_start(self.plant.uvms.model, q0, v0)
        states = [] if self.moving is None else self.moving.initial_states()
        if self.objects or self.fixtures:  # none inside another body (`...world.overlap`)
            states, self.separations = self.moving.apart(q0, states)
        return self.layout.join([(q0, v0), *states])

    def robot_state(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The robot's (q, v) in the system's (q, v) (views; the arrays themselves when the
        robot moves alone)."""
        if len(self.layout.names) == 1:
            return q, v
        return q[self.layout.q_slices[0]], v[self.layout.v_slices[0]]

    def start(self, state: SystemState) -> None:
        """t = 0 at ``state``: the robot's environment anchored at its end-effector, the
        flow taken, what touches held where it is (`Plant.attach`), the moving contacts'
        anchors set afresh."""
        q, _ = self.robot_state(state.q, state.v)
        self.plant.attach(q)
        self.stalled = StalledSolves()
        if self.attachments is not None:  # each object held where it starts in its link
            self.attachments.place(self.model, state.q)
            held = self.__dict__.get("_compiled")  # the core's: placed at its first period
            if held is not None and not isinstance(held[1], Fallback):
                held[1].forget_attachments()
        if self.moving is not None:
            self.moving.reset()
            robot, *objects = self.layout.split(state.q, state.v)
            self.moving.settle(robot[0], np.zeros(self.plant.uvms.nv), objects)

    # ---- the compiled system ------------------------------------------------------------
    @property
    def compiled(self) -> Any:
        """The compiled system of bodies (`uvms_pin.sim.compiled.system`) of the compiled
        plant as it is now (rebuilt with it, when a run starts), or its `Fallback`; None
        without free objects or a compiled plant."""
        plant_core = self.plant.compiled
        if not (self.objects or self.fixtures) or plant_core is None:
            return None
        held = self.__dict__.get("_compiled")
        if held is None or held[0] is not plant_core:
            held = self._compiled = (plant_core, system_to_core(self, core_module()))
        return held[1]

    def friction_memories(self) -> list:
        """Every contact's friction state, as the compiled system reads and writes it: the
        plant's, each moving pair set's, each free object's against the fixed world."""
        return memories_of(self.plant.friction, self.moving.moving)

    # ---- the dynamics ---------------------------------------------------------------------
    def acceleration(
        self,
        time_s: float,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        *,
        contact_world: np.ndarray | None = None,
    ) -> np.ndarray:
        """The system's acceleration (nv,) with ``tau`` on the robot (``contact_world``:
        the robot's end-effector contact as the continuous loop measured it)."""
        plant = self.plant
        if self.moving is None:
            return plant.acceleration(time_s, q, v, tau, contact_world)
        (q_r, v_r), *bodies = self.layout.split(q, v)
        tau_robot, tau_bodies = self.moving.torques(q_r, v_r, bodies)
        out = [plant.acceleration(time_s, q_r, v_r, tau, contact_world, extra_torque=tau_robot)]
        n = len(self.objects)
        water = {"flow": plant.water, "time_s": time_s, "backend": plant.backend,
                 "free_surface": plant.free_surface}  # fmt: skip
        for obj, (q_o, v_o), tau_o in zip(self.objects, bodies[:n], tau_bodies[:n], strict=True):
            out.append(forward_dynamics(obj.uvms, q_o, v_o, np.zeros(6), tau_ext=tau_o, **water))
        out += fixture_joints.accelerations(self.fixtures, bodies[n:], tau_bodies[n:], water)
        return np.concatenate(out)

    def advance(
        self,
        integrator: Integrator,
        t0: float,
        q0: np.ndarray,
        v0: np.ndarray,
        tau: np.ndarray,
        t1: float,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The system's (q, v) at t1 from (q0, v0) at t0 with the robot's input ``tau``
        held (zero-order hold), by the period step of ``integrator``
        (`uvms_pin.sim.system.period`, chosen at its first use and kept)."""
        if self.attachments is not None:
            self.attachments.at(t0)
        held = self._steps.get(id(integrator))
        if held is None or held[0] is not integrator:
            held = self._steps[id(integrator)] = (integrator, period_step(self, integrator))
        return held[1](t0, q0, v0, tau, t1)

    def mass_matrix(self, time_s: float, q: np.ndarray) -> np.ndarray:
        """M(q) of the system (nv x nv): each body's, added mass included (wet fractions
        under the free surface at ``time_s``), block diagonal (the bodies meet only through
        their contacts)."""
        plant = self.plant
        water = {"free_surface": plant.free_surface, "flow": plant.water, "time_s": time_s}
        bodies = [plant.uvms, *(o.uvms for o in (*self.objects, *self.fixtures))]
        out = np.zeros((self.layout.nv, self.layout.nv))
        layout = self.layout
        for uvms, at, part in zip(bodies, layout.q_slices, layout.v_slices, strict=True):
            out[part, part] = mass_matrix(uvms, q[at], backend=plant.backend, **water)
        return out

    def clear(self, q: np.ndarray, v: np.ndarray, horizon_s: float) -> bool:
        """Nothing can touch over ``horizon_s`` from the robot's (q, v): no fixed object
        within reach (then no contact persists: the friction forgets its anchors) and no
        moving pair (a system of the robot alone)."""
        plant = self.plant
        if plant.world is None:
            return True
        compiled = plant.compiled
        if compiled is not None:
            clear = compiled.world_clear(q, v, horizon_s)
        else:
            pin.forwardKinematics(plant.uvms.model, self._data, q, v)
            clear = plant.world.clear(self._data, horizon_s)
        if self.moving is not None and self.moving.near(q, v, [], horizon_s):
            return False
        if clear:
            plant.friction.clear()
        return clear

    def settle(self, q: np.ndarray, v: np.ndarray) -> None:
        """After a control period, at the system's (q, v): every contact's anchors move."""
        (q_r, v_r), *objects = self.layout.split(q, v)
        self.plant.settle(q_r, v_r)
        if self.moving is not None:
            self.moving.settle(q_r, v_r, objects)

    def stalled_solves(self) -> StalledSolves:
        """The run's constraint solves accepted after stalling (`StalledSolves`): the Python
        step's and the compiled system's (rebuilt, so counted afresh, when a run starts; read
        only when the run built it: a Python-stepped run does not build one to read zeros)."""
        held = self.__dict__.get("_compiled")
        if held is None or held[0] is not self.plant.compiled or isinstance(held[1], Fallback):
            return self.stalled
        return self.stalled.merged(*held[1].stalled_solves)


def _attachments(world, objects: tuple, first_object_joint: int) -> Attachments | None:
    """The world's attachments (`uvms_pin.physics.constraints.attachments`) in the system's
    model (free object k on joint ``first_object_joint + k``), or None."""
    if world is None or not world.attachments:
        return None
    index = {o.name: k for k, o in enumerate(objects)}
    return Attachments(
        [(a, world.link_joint(a.link), first_object_joint + index[a.object_name])
         for a in world.attachments]
    )  # fmt: skip
