"""How a system of bodies crosses one control period, chosen once per integrator.

- compiled: the compiled plant's one call for the whole period (RK4, semi-implicit Euler):
  without a world; or with fixed objects (a bound test first: nothing within reach, the period
  runs without them; else with the contacts, and their anchors move at its end);
- compiled system (free objects, fixtures): the compiled system's one call for the whole
  period (src/uvms_core/system.hpp): the robot, every free object, every fixture's joints,
  every moving contact and the anchors' move at its end, then the joint limits (and joint
  Coulomb friction), the objects' rigid contacts and the fixtures' joints' exact step; the
  friction memories are the Python system's, read and written back by the call;
- guarded (the arm against its own vehicle, compiled plant): the compiled call while no pair,
  fixed or moving, can touch over the period, else the integrated step;
- integrated: the integrator's own loop around the system's right-hand side (the Python
  reference, an integrator without a compiled counterpart, a part the core cannot do:
  `why_not_compiled_system` names it), the anchors moved at the period's end.

This is the one place the step is made: the constraints solved implicitly come after the
smooth dynamics, for every body at once (`constrained`: the joint limits and Coulomb
friction, the rigid contacts and the attachments, `constraint_sets`). The compiled plant solves the joint
limits itself at the end of its call (src/uvms_core/joint_limits.hpp, the same step); the
integrated step is followed by the Python reference's solve.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any, Protocol

import numpy as np
import pinocchio as pin

from uvms_pin.errors import SimulationError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.moving import contacts_of_core
from uvms_pin.physics.constraints.rows import ConstraintRows
from uvms_pin.physics.constraints.step import (
    ConstrainedVelocity,
    StalledSolves,
    constrained_velocity,
    default_settings,
    free_body_configuration,
)
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.integrators import Integrator
from uvms_pin.sim.pipeline import Pipeline, RunParts, why_not_compiled
from uvms_pin.sim.system.fixtures import with_fixtures


class Stepped(Protocol):
    """What a period step needs of a system of bodies (`uvms_pin.sim.system.System`)."""

    plant: Any
    model: pin.Model
    objects: tuple
    moving: Any
    compiled: Any  # the compiled system of bodies (free objects, fixtures), or its Fallback
    compiled_allowed: bool
    layout: Any  # where each body sits in the state (`uvms_pin.sim.system.state.Layout`)
    object_contacts: Any  # the free objects' rigid contacts with the fixed world, or None
    fixtures: tuple  # the fixtures (`uvms_pin.physics.world.fixture`), after the objects
    fixture_constraints: tuple  # their joint limits and friction (`sim.system.fixtures`)
    fixture_blocks: list  # each one's part of v and its joints (`fixtures.blocks`)
    moving_constraints: Any  # the rigid contacts between moving bodies, or None
    attachments: Any  # the free objects held by the robot's links, or None
    stalled: StalledSolves  # the run's solves accepted after stalling (`step`)

    def friction_memories(self) -> list: ...

    def acceleration(self, time_s: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray): ...

    def settle(self, q: np.ndarray, v: np.ndarray) -> None: ...

    def clear(self, q: np.ndarray, v: np.ndarray, horizon_s: float) -> bool: ...

    def mass_matrix(self, time_s: float, q: np.ndarray) -> np.ndarray: ...


#: A free object whose velocity the period's impulses changed by at most this [m/s, rad/s]
#: keeps the smooth step's end (`_end`): the compiled PGS leaves an unloaded contact at
#: exactly 0, the reference's ADMM at its tolerance
PUSHED_M_S = 1e-9

#: (t0, q0, v0, tau, t1) -> (q1, v1), the system's state at t1
PeriodStep = Callable[[float, np.ndarray, np.ndarray, np.ndarray, float], tuple]

__all__ = [
    "PeriodStep",
    "Stepped",
    "constraint_sets",
    "integrated_step",
    "period_step",
    "why_not_compiled_system",
]


def period_step(system: Stepped, integrator: Integrator) -> PeriodStep:
    """The period step of ``system`` with ``integrator`` (see the module docstring), with the
    robot's joint limits as constraints solved implicitly at its end (`constrained`)."""
    return _step(system, integrator)


def why_not_compiled_system(system: Stepped, integrator: Integrator | None) -> str | None:
    """Why the period of ``system`` (with free objects or fixtures) is not one compiled call, or None
    (``integrator`` None: not asked): the pipeline's one list of reasons
    (`uvms_pin.sim.pipeline`, `Pipeline.SYSTEM`)."""
    return why_not_compiled(RunParts(system, integrator=integrator), Pipeline.SYSTEM)


def constraint_sets(system: Stepped) -> tuple:
    """The constraints solved implicitly at the end of ``system``'s period: the robot's
    joint limits and joint Coulomb friction, the free objects' rigid contacts with the fixed
    world, the rigid contacts between moving bodies, the attachments and the fixtures'
    joint limits and friction (each when there is one)."""
    plant = system.plant
    sets = (plant.joint_limits, plant.joint_coulomb, system.object_contacts)
    sets += (system.moving_constraints, system.attachments, *system.fixture_constraints)
    return tuple(s for s in sets if s is not None)


def constrained(system: Stepped, smooth: PeriodStep) -> PeriodStep:
    """``smooth`` followed by the constraints' implicit velocity step over the period
    (`uvms_pin.physics.constraints.step`): the smooth dynamics reach (q_free, v_free); the
    impulses give v+ = v_free + M^-1 J^T lambda, M(q0) the mass matrix with the added mass
    (block diagonal over the bodies); each body some solved row acts on moves from q0 with
    v+ (`_configuration`), the others keep q_free (a period in which nothing can reach a
    limit or a surface is the smooth step's)."""
    sets = constraint_sets(system)
    # a sticking joint creeps at the solver's tolerance on the rows' velocities: 1e-10 rad/s
    # keeps it below 1e-9 rad a second (the default 1e-8 let a held finger creep 7e-8 m)
    settings = None if system.plant.joint_coulomb is None else default_settings(1e-10)

    def step(t0, q0, v0, tau, t1):
        q_free, v_free = smooth(t0, q0, v0, tau, t1)
        if not (np.all(np.isfinite(q_free)) and np.all(np.isfinite(v_free))):
            return q_free, v_free  # diverged: the loop names the divergence
        mass = system.mass_matrix(t0, q0)
        # the smooth step's own speeds: its start and its mean over the period (RK4's end
        # may cross a limit that its end velocity would not reach)
        travelled = np.abs(pin.difference(system.model, q0, q_free)) / (t1 - t0)
        solve = constrained_velocity
        if system.fixtures:  # their joints' own exact steps (`uvms_pin.sim.system.fixtures`)
            own = system.fixture_constraints
            solve = partial(with_fixtures, constrained_velocity, own, system.fixture_blocks)
        v_start = _objects_moved(system, v_free, q_free, q0)
        solved = solve(
            system.model, mass, v_start, q0, sets, t1 - t0,
            least_speed=np.maximum(np.abs(v0), travelled), settings=settings,
        )  # fmt: skip
        if not solved.accepted:
            raise SimulationError(
                f"the constraint solve did not converge between t = {t0:.6g} s and {t1:.6g} s "
                f"({solved.iterations} iterations, residual {solved.residual:.3g} m/s, above "
                f"the {solved.acceptable_residual:.3g} m/s a stalled solve may keep)"
            )
        if not solved.converged:  # stalled in a cycle below the acceptable residual
            system.stalled.add(solved.residual)
        _settle_contacts(system, solved, t1 - t0)
        return _end(system, q0, (q_free, v_free), solved, t1 - t0, solved.velocity - v_start)

    return step


def _settle_contacts(system: Stepped, solved: ConstrainedVelocity, period_s: float) -> None:
    """The rigid contacts of the period solved: their mean forces kept for the logs
    (`MovingContacts.rigid_forces`, `MovingContacts.rigid_pair_forces`), their sliding
    patches for the next period's cone."""
    if system.object_contacts is not None:
        found = _solved_forces(system, system.object_contacts, solved, period_s)
        moving = system.moving.moving
        moving.rigid_forces = found
        for world, forces, memory in zip(
            moving.object_worlds, found, moving.object_memory, strict=True
        ):
            if world is not None:
                world.commit(forces, memory)
    if system.moving_constraints is not None:
        found = _solved_forces(system, system.moving_constraints, solved, period_s)
        system.moving.moving.rigid_pair_forces = found
        system.moving_constraints.commit(found)


def _solved_forces(system: Stepped, contacts: Any, solved: ConstrainedVelocity, period_s: float):
    """``contacts``' forces (its ``forces``) of the period ``solved`` (none: no row)."""
    rows = next((b for b in solved.rows if b.name == contacts.name), None)
    if rows is None:
        rows = ConstraintRows.empty(contacts.name, "N s", system.layout.nv)
    impulse = solved.impulses.get(contacts.name, np.zeros(0))
    return contacts.forces(rows, impulse, solved.velocity, period_s)


def _objects_moved(system: Stepped, v: np.ndarray, q_from: np.ndarray, q_to: np.ndarray):
    """``v`` (nv,) with each free object's body velocity at its pose in ``q_from`` expressed
    in its frame at ``q_to`` (the same world velocity: R_to^T R_from [v_lin; w]). The smooth
    step ends with the body velocity of the pose q_free; the rows act at q0 (their
    Jacobian is for the body velocity there): the two frames differ by the rotation over
    the period, w h, which, left out, turns a rolling sphere's velocity a little each period
    (it then rolls 4 % fast and gains energy)."""
    layout = system.layout
    out = np.array(v, dtype=float)
    free = slice(1, 1 + len(system.objects))  # the fixtures' joints have no frame to turn
    for at, part in zip(layout.q_slices[free], layout.v_slices[free], strict=True):
        turn = _rotation(q_to[at]).T @ _rotation(q_from[at])
        out[part] = np.concatenate([turn @ v[part][:3], turn @ v[part][3:]])
    return out


def _rotation(pose: np.ndarray) -> np.ndarray:
    return pin.Quaternion(pose[3:7]).normalized().matrix()


def _end(
    system: Stepped,
    q0: np.ndarray,
    smooth: tuple[np.ndarray, np.ndarray],
    solved: ConstrainedVelocity,
    h: float,
    change: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(q, v) at the period's end: a body some solved row acts on moves from its q0 with v+
    (the robot by `constrained_configuration`, q0 (+) h v+; a free object by
    `free_body_configuration`, its body velocity then expressed at its new pose; a fixture's
    revolute and prismatic joints by q0 + h v+); a body no row acts on, and a free object
    the impulses did not move (``change`` = v+ - v_free, at most `PUSHED_M_S` on each of its
    coordinates: its rows selected, its contacts not closing), keeps the smooth step's end
    ``smooth`` = (q_free, v_free) (all of them when nothing was solved). The semi-implicit
    step from q0 is first order: a box tumbling within reach of the seabed without touching
    it gained 2 mJ in 15 periods by it (it moves with its end velocity over the period: its
    height off by g h^2 / 2 a period)."""
    q_free, v_free = smooth
    if not solved.rows:
        return np.asarray(q_free, dtype=float), np.asarray(v_free, dtype=float)
    acting = np.any(np.vstack([b.jacobian for b in solved.rows]) != 0.0, axis=0)
    q, v = np.array(q_free, dtype=float), np.array(v_free, dtype=float)
    layout, v_plus = system.layout, solved.velocity
    for k, (at, part) in enumerate(zip(layout.q_slices, layout.v_slices, strict=True)):
        pushed = np.max(np.abs(change[part]), initial=0.0) > PUSHED_M_S
        if not np.any(acting[part]) or (0 < k <= len(system.objects) and not pushed):
            continue
        if k == 0:
            q[at] = pin.integrate(system.plant.uvms.model, q0[at], h * v_plus[part])
            v[part] = v_plus[part]
        elif k > len(system.objects):  # a fixture: revolute and prismatic joints, q+ = q + h v+
            q[at] = q0[at] + h * v_plus[part]
            v[part] = v_plus[part]
        else:
            q[at] = free_body_configuration(q0[at], v_plus[part], h)
            turn = _rotation(q[at]).T @ _rotation(q0[at])
            v[part] = np.concatenate([turn @ v_plus[part][:3], v_plus[part][3:]])
    return q, v


def integrated_step(system: Stepped, integrator: Integrator) -> PeriodStep:
    """The Python reference's period step: the integrator's own loop around the system's
    right-hand side, every anchor moved at its end (`Stepped.settle`), then the joint
    limits (`constrained`)."""

    def smooth(t0, q0, v0, tau, t1):
        q1, v1 = integrator.advance(
            system.model, lambda t, q, v: system.acceleration(t, q, v, tau), t0, q0, v0, t1
        )
        system.settle(q1, v1)
        return q1, v1

    return constrained(system, smooth) if constraint_sets(system) else smooth


def _step(system: Stepped, integrator: Integrator) -> PeriodStep:
    """The period step (see the module docstring): the compiled plant's call (its joint
    limits solved in it) or the integrated step (then `constrained` in Python)."""
    plant = system.plant
    compiled = plant.compiled
    step = None
    if compiled is not None:
        step = integrator_to_core(integrator, core_module())
        step = None if isinstance(step, Fallback) else step

    integrated = integrated_step(system, integrator)

    # the compiled plant is rebuilt when a run starts (its contact anchored anew): taken at
    # each period, the choice of step stays
    if system.objects or system.fixtures:
        moving = None if system.moving is None else system.moving.moving
        if why_not_compiled_system(system, integrator) is not None:
            if moving is not None:
                moving.rigid_source = None  # its own rigid contacts: `_settle_contacts`
            return integrated
        # the compiled system's rigid contacts of the last period, when asked
        moving.rigid_source = lambda: contacts_of_core(system.compiled.rigid_contacts())
        # the compiled system follows the compiled plant (rebuilt when a run starts)
        return lambda t0, q0, v0, tau, t1: system.compiled.advance(
            t0, q0, v0, tau, t1, step, system.friction_memories()
        )
    if step is not None and plant.world is None:
        return lambda t0, q0, v0, tau, t1: plant.compiled.advance(t0, q0, v0, tau, t1, step)
    if step is not None and system.moving is None:
        return lambda t0, q0, v0, tau, t1: plant.compiled.advance_in_world(
            t0, q0, v0, tau, t1, step, plant.friction
        )
    if compiled is None:
        return integrated

    def guarded(t0, q0, v0, tau, t1):
        if system.clear(q0, v0, t1 - t0) and step is not None:
            return plant.compiled.advance(t0, q0, v0, tau, t1, step)
        return integrated(t0, q0, v0, tau, t1)

    return guarded
