"""Several robots in one sea: a system of bodies holding one robot's system per robot.

Each robot is a `System` of its own (its `Plant`: its model, its hydrodynamics in the
shared water, its actuation, its fixed world, its joint limits) and a block of the state
(`Layout`, one block per robot, in order). The robots meet only through the contacts
between them (`uvms_pin.physics.world.between_robots`, every force equal and opposite):
there is no hydrodynamic interaction (no wake, no added mass of one robot felt by the
other): each robot's water is the undisturbed flow.

A control period is stepped in one of two ways, chosen at its start:

- apart (no pair of robots, nor another robot and an object, can touch over the period,
  `near`): each robot's system by its own period step (`System.advance`: its compiled call
  when it has one), the same as alone;
- together: the Python integrator around the system's right-hand side (each robot's
  acceleration with the contacts' generalized force added to its input tau: the dynamics
  are linear in it), every anchor moved at the period's end, then each robot's constraints
  solved implicitly (its joint limits: they act within the robot only). With the compiled
  backend the whole period is one core call (`uvms_pin.sim.compiled.robots`,
  `RobotsSystem.advance`: every robot's compiled system, the contacts between them added to
  their bodies, each system's anchors and constraints as its own compiled step does them;
  `together_reference` is the same period in Python around the compiled integration), the
  bound test (`near`) and the sensors' wrenches on the objects (`object_wrenches`) are the
  core's too, and the pair sets' contacts the logs read are found by the core
  (`uvms_pin.physics.compiled.moving.search_compiled`, the reference's arithmetic).

The world's free objects belong to the first robot's system (its moving contacts with them,
their contacts with each other and with the fixed world, as for a single robot); the other
robots touch them through pairs of their own (`uvms_pin.physics.world.between_robots`), and
their worlds hold no free object (`uvms_pin.sim.robots_loop` builds them so). The
first robot's system is then apart when no other robot can reach another robot or an object.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.moving import contacts_of_core, search_compiled
from uvms_pin.physics.world.between_robots import RobotContacts
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.overlap import robot_tolerance_m, robots_started_apart, tolerance_m
from uvms_pin.physics.world.world import World
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.compiled.robots import robots_to_core
from uvms_pin.sim.integrators import Integrator
from uvms_pin.sim.system.period import constrained, constraint_sets
from uvms_pin.sim.system.state import Layout, SystemState
from uvms_pin.sim.system.system import System

__all__ = ["Robots", "joined_model"]


def joined_model(models: Sequence[pin.Model], names: Sequence[str]) -> pin.Model:
    """One Pinocchio model with every joint of ``models`` in order, each robot's tree
    under the universe (a joint named ``robot/joint``): its configuration and velocity are
    the robots' stacked (what the integrator steps)."""
    out = pin.Model()
    for model, name in zip(models, names, strict=True):
        offset = out.njoints - 1
        for j in range(1, model.njoints):
            parent = model.parents[j]
            out.addJoint(
                0 if parent == 0 else parent + offset,
                model.joints[j],
                model.jointPlacements[j],
                f"{name}/{model.names[j]}",
            )
    return out


class Robots:
    """The systems of several robots (``systems``, one each, named ``names``) in one sea;
    the first robot's system may hold the world's free objects.

    Attributes:
        systems: each robot's own system of bodies. names: the robots' names.
        objects: the free objects (the first system's). contacts: the pairs between robots
            and between the other robots and the objects. layout: one block per robot's
            system (the first holds the objects after its robot). model: the joined model
            (`joined_model`).
    """

    def __init__(self, systems: Sequence[System], names: Sequence[str]):
        if len(systems) != len(names) or len(set(names)) != len(names):
            raise ParameterError(f"one distinct name per robot, got {list(names)}")
        for system, name in zip(systems[1:], names[1:], strict=True):
            if system.objects:
                raise ParameterError(
                    f"robot '{name}': the free objects are the first robot's system's; "
                    "the others' worlds hold none"
                )
        if any(system.fixtures for system in systems):
            # the robots' contacts and state name a robot's blocks, then the free objects'
            raise ParameterError(
                'fixtures ([[world.objects]] type = "urdf") are not simulated with several '
                "robots yet: use one robot, or leave the fixture out"
            )
        if any(
            system.moving is not None and system.moving.moving.rigid_pairs for system in systems
        ):
            # the contacts between robots, and the other robots' with the objects, are the
            # contact law's forces: only the first robot's pairs would be rigid rows
            raise ParameterError(
                '[world] moving_contact = "rigid" is not simulated with several robots yet: '
                "their contacts with each other and the others' with the objects are "
                "compliant, and a grasp rigid for one robot and compliant for the other "
                "loses what they hold; leave moving_contact compliant"
            )
        if any(system.attachments is not None for system in systems):
            raise ParameterError(
                "attached_to ([[world.objects]]) is not simulated with several robots yet: "
                "use one robot, or let the robots grasp the object"
            )
        self.systems = tuple(systems)
        self.names = tuple(names)
        self.objects = self.systems[0].objects
        plants = [s.plant for s in self.systems]
        worlds = [
            p.world if p.world is not None else World(p.uvms, [], ContactLaw()) for p in plants
        ]
        self.contacts = RobotContacts.of(worlds, self.names, self.objects)
        # what each side may start overlapping another by (`robots_started_apart`)
        self._tolerances = [robot_tolerance_m(w) for w in worlds] + [
            tolerance_m(o, worlds[0].law) for o in self.objects
        ]
        # integrated in Python (each robot's loop is): every stage's contact search is the
        # core's, unless the plants are the Python reference's
        first = self.systems[0].moving
        sets = [*self.contacts.sets, *(() if first is None else first.moving.sets)]
        search_compiled(sets, plants[0].backend)
        self.layout = Layout.of(
            [(n, s.layout.nq, s.layout.nv) for n, s in zip(names, self.systems, strict=True)]
        )
        self.model = joined_model([s.model for s in self.systems], self.names)
        self._datas = [side.model.createData() for side in self.contacts.sides]

    # ---- the state ------------------------------------------------------------------------
    def split(self, q: np.ndarray, v: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Each robot's system's (q, v), views."""
        return self.layout.split(q, v)

    def sides(self, q: np.ndarray, v: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """(q, v) of each robot, then of each free object, views."""
        parts = self.split(q, v)
        robots = [s.robot_state(*part) for s, part in zip(self.systems, parts, strict=True)]
        return [*robots, *self.systems[0].layout.split(*parts[0])[1:]]

    def check_apart(self, state: SystemState) -> None:
        """A run's start at ``state``: `InitialOverlapError` if two robots, or a robot and
        another's free object, start inside each other (`robots_started_apart`)."""
        datas = self._kinematics(state[0], np.zeros(self.layout.nv))
        robots_started_apart(self.contacts, datas, self._tolerances)

    def start(self, state: SystemState) -> None:
        """t = 0 at ``state`` (each robot's system started by its loop): the anchors of the
        contacts between robots (and objects) set afresh where they touch."""
        self.contacts.clear()
        q, _ = state
        zero = np.zeros(self.layout.nv)
        self.contacts.commit(self._kinematics(q, zero), self.contacts.found(self._datas))

    def _kinematics(self, q: np.ndarray, v: np.ndarray) -> list[pin.Data]:
        for side, data, (q_k, v_k) in zip(
            self.contacts.sides, self._datas, self.sides(q, v), strict=True
        ):
            pin.forwardKinematics(side.model, data, q_k, v_k)
        return self._datas

    # ---- the dynamics ---------------------------------------------------------------------
    def pushes(self, q: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """Each side's generalized force (nv_k,) of the contacts between robots and with
        the objects at (q, v): the robots', then the objects'."""
        datas = self._kinematics(q, v)
        found = self.contacts.found(datas)
        return self.contacts.generalized([p[0] for p in self.sides(q, v)], datas, found)

    def acceleration(
        self, time_s: float, q: np.ndarray, v: np.ndarray, taus: Sequence[np.ndarray]
    ) -> np.ndarray:
        """The accelerations (nv,) with ``taus`` (each robot's input) held: each robot's
        system's own right-hand side (`System.acceleration`) with the robot's contacts
        against the others added to its input, and an object's pushes by the other robots
        as M_o^-1 tau (the dynamics are linear in the input; M_o with the added mass)."""
        n = len(self.systems)
        pushes = self.pushes(q, v)
        parts = self.split(q, v)
        out = [
            system.acceleration(time_s, q_k, v_k, tau + push)
            for system, (q_k, v_k), tau, push in zip(
                self.systems, parts, taus, pushes[:n], strict=True
            )
        ]
        on_objects = pushes[n:]
        if any(np.any(p) for p in on_objects):
            first = self.systems[0]
            mass = first.mass_matrix(time_s, parts[0][0])
            for part, push in zip(first.layout.v_slices[1:], on_objects, strict=True):
                out[0][part] += np.linalg.solve(mass[part, part], push)
        return np.concatenate(out)

    def near(self, q: np.ndarray, v: np.ndarray, horizon_s: float) -> bool:
        """Some two robots, or a robot but the first and an object, may touch within
        ``horizon_s`` from (q, v): the core's bound test (`RobotsSystem.near`, the same
        arithmetic) with the compiled backend, else the reference's."""
        core = self._core()
        if core is not None:
            return core.near(q, v, horizon_s)
        return self.contacts.near(self.sides(q, v), lambda: self._kinematics(q, v), horizon_s)

    def advance(
        self, integrator: Integrator, t0: float, state: SystemState, taus: Sequence, t1: float
    ) -> SystemState:
        """The state at t1 from ``state`` at t0, each robot's input of ``taus`` (nv_k,)
        held: apart or together (see the module docstring)."""
        q0, v0 = state
        if not self.near(q0, v0, t1 - t0):
            self.contacts.clear()  # no contact persists: the friction forgets its anchors
            self._rigid_contacts_from(None)  # each system's own step keeps them
            return self.layout.join(
                [
                    system.advance(integrator, t0, q_k, v_k, tau, t1)
                    for system, (q_k, v_k), tau in zip(
                        self.systems, self.split(q0, v0), taus, strict=True
                    )
                ]
            )
        return self._together(integrator, t0, q0, v0, taus, t1)

    # ---- the compiled integration ---------------------------------------------------------
    @property
    def compiled(self) -> Any:
        """The core's integration of the robots together (`uvms_pin.sim.compiled.robots`)
        of the robots' compiled plants as they are now (rebuilt with them, when a run
        starts), or its `Fallback`: the Python backend, a plant the core cannot compile."""
        plants = tuple(s.plant.compiled for s in self.systems)
        held = self.__dict__.get("_compiled")
        if held is None or any(a is not b for a, b in zip(held[0], plants, strict=True)):
            if self.systems[0].plant.backend == "python":
                built = Fallback("the Python backend", asked=True)
            else:
                built = robots_to_core(self, core_module())
            held = self._compiled = (plants, built)
        return held[1]

    def _core(self) -> Any:
        """The core's `RobotsSystem`, or None (the Python backend, a plant the core cannot
        compile: `compiled`)."""
        built = self.compiled
        return None if isinstance(built, Fallback) else built[0]

    def _core_period(self, integrator) -> tuple[Any, Any] | None:
        """(the core's `RobotsSystem`, its FixedStep of ``integrator``) when a period is one
        core call, else None (no compiled system, an integrator the core has not)."""
        core = self._core()
        step = None if core is None else integrator_to_core(integrator, core_module())
        return None if step is None or isinstance(step, Fallback) else (core, step)

    def _core_memories(self) -> tuple[list, list]:
        """What a core call reads of the friction anchors: each robot's system's memories,
        then each pair set's between the sides."""
        return self._memories(), [s.memory for s in self.contacts.sets]

    def _memories(self) -> list[list]:
        """Each robot's system's friction memories, as its core system reads them."""
        return [
            [s.plant.friction] if s.moving is None else s.friction_memories() for s in self.systems
        ]

    def integration(self, integrator: Integrator) -> str | None:
        """Why the periods in which the robots touch are integrated by the Python
        integrator, or None: by one core call each."""
        built = self.compiled
        if isinstance(built, Fallback):
            return built.reason
        return _fallback_reason(integrator_to_core(integrator, core_module()))

    def _integrate(self, integrator, t0, q0, v0, taus, t1) -> SystemState:
        """The smooth step of the period with every body at once: one core call, or the
        Python integrator around `acceleration`."""
        core = self._core_period(integrator)
        if core is None:
            return integrator.advance(
                self.model, lambda t, q, v: self.acceleration(t, q, v, taus), t0, q0, v0, t1
            )
        system, step = core
        return system.integrate(t0, q0, v0, _floats(taus), t1, step, *self._core_memories())

    def _together(self, integrator, t0, q0, v0, taus, t1) -> SystemState:
        """The period integrated for every body at once (the contacts between robots and
        with the objects in the right-hand side), every anchor moved at its end, then each
        robot's system's constraints (its joint limits; the first's objects' rigid
        contacts with the fixed world): one core call (`RobotsSystem.advance`, the same
        steps) when the integration is compiled, else the reference below."""
        core = self._core_period(integrator)
        if core is None:
            return self.together_reference(integrator, t0, q0, v0, taus, t1)
        system, step = core
        q1, v1 = system.advance(t0, q0, v0, _floats(taus), t1, step, *self._core_memories())
        self._rigid_contacts_from(self.compiled[1][0])
        return SystemState(q1, v1)

    def together_reference(self, integrator, t0, q0, v0, taus, t1) -> SystemState:
        """The reference of `_together`'s period: `_integrate`, then in Python every anchor
        moved (each system's `System.settle`, the sets between the sides) and each system's
        constraints (`uvms_pin.sim.system.period.constrained`)."""
        q1, v1 = self._integrate(integrator, t0, q0, v0, taus, t1)
        ends = self.split(q1, v1)
        for system, (q_k, v_k) in zip(self.systems, ends, strict=True):
            system.settle(q_k, v_k)
        self.contacts.commit(self._kinematics(q1, v1), self.contacts.found(self._datas))
        out = []
        for system, start, end, tau in zip(
            self.systems, self.split(q0, v0), ends, taus, strict=True
        ):
            if constraint_sets(system):
                step = constrained(system, lambda *_, end=end: end)
                end = step(t0, start[0], start[1], tau, t1)
            out.append(end)
        return self.layout.join(out)

    def _rigid_contacts_from(self, core_system: Any) -> None:
        """Where the first system's logs read its objects' rigid contacts with the fixed
        world of the last period: the core's system that solved it (read when a sample is
        logged), or None: the reference's (`period._settle_contacts` keeps them)."""
        first = self.systems[0].moving
        if first is None or not first.moving.rigid:
            return
        if core_system is None:
            first.moving.rigid_source = None
        elif getattr(first.moving.rigid_source, "args", None) != (core_system,):
            first.moving.rigid_source = partial(_rigid_contacts, core_system)

    def contact_signals(self, q: np.ndarray, v: np.ndarray) -> list[dict[str, np.ndarray]]:
        """What each robot logs of its contacts with the other robots (and the objects) at
        (q, v): ``robot_contact``, per pair it is in (`contact_pair_names`), the force on it
        [N], the point [m], the moment [N m] (world axes), flattened; nothing for a robot
        without pairs."""
        if self.near(q, v, 0.0):
            found = self.contacts.found(self._kinematics(q, v))
            logged = [self.contacts.wrenches(k, found) for k in range(len(self.systems))]
        else:  # nothing within reach: no pair touches (the narrow phase skipped)
            logged = [
                np.zeros(9 * len(self.contact_pair_names(k))) for k in range(len(self.systems))
            ]
        return [{"robot_contact": wrenches} if len(wrenches) else {} for wrenches in logged]

    def object_wrenches(self, q: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """Each robot's wrench on the free objects at (q, v), (6,) world axes: the force
        [N] its pieces exert on them, summed, and its moment about the world's origin [N m]
        (sum of p x f + m over the pairs): the first robot's from its system's contacts
        (``world_contact``'s pairs with an object), the others' from their pairs with the
        objects (``robot_contact``). Zero for a robot touching none. With the compiled
        backend the core's (`RobotsSystem.object_wrenches`: the same sums)."""
        core = self._core()
        if core is not None:
            return list(core.object_wrenches(q, v, *self._core_memories()))
        return self.object_wrenches_reference(q, v)

    def object_wrenches_reference(self, q: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """`object_wrenches` by the reference's contacts (the logged pairs' wrenches)."""
        objects = {o.name for o in self.objects}
        first = self.systems[0]
        rows: list = [(None, [])]
        if first.moving is not None:  # its pairs with the objects are among its moving pairs
            (q_r, v_r), *states = first.layout.split(*self.split(q, v)[0])
            robot_pairs, _ = first.moving.wrenches(q_r, v_r, states)
            rows = [(robot_pairs, first.moving.moving.uvms_pair_names)]
        others = self.contact_signals(q, v)[1:]
        rows += [
            (own.get("robot_contact"), self.contact_pair_names(k))
            for k, own in enumerate(others, start=1)
        ]
        out = []
        for logged, names in rows:
            wrench = np.zeros(6)
            if logged is not None and len(names):
                pairs = np.asarray(logged).reshape(len(names), 9)
                held = [k for k, n in enumerate(names) if n.rsplit("|", 1)[-1] in objects]
                force_on_object = -pairs[held, :3]
                wrench[:3] = force_on_object.sum(axis=0)
                wrench[3:] = (np.cross(pairs[held, 3:6], force_on_object) - pairs[held, 6:9]).sum(
                    axis=0
                )
            out.append(wrench)
        return out

    def contact_pair_names(self, robot: int) -> list[str]:
        """``name/body|name/body`` (or ``name/body|object``) of every pair of robot
        ``robot`` (an index)."""
        return self.contacts.pair_names(robot)


def _floats(taus) -> list[np.ndarray]:
    """Each robot's input as a float array (what the core's calls take)."""
    return [np.asarray(tau, dtype=float) for tau in taus]


def _rigid_contacts(core_system: Any) -> tuple[list, list]:
    return contacts_of_core(core_system.rigid_contacts())


def _fallback_reason(built: Any) -> str | None:
    return built.reason if isinstance(built, Fallback) else None
