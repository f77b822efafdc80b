"""The fixtures of a system of bodies (`uvms_pin.physics.world.fixture`): their joints in the
system's model, their constraints and their smooth dynamics.

A fixture's joints follow the robot's and the free objects' in the state (`Layout`) and in
the system's Pinocchio model (`system_model`, each joint under the world at its placed
pose, with its URDF limits). Per fixture f, over a period:

- smooth: qdd_f = FD_f(q_f, qd_f, -D_f qd_f + tau_contact,f) (`accelerations`);
- after it, with the robot's joint limits and the free objects' contacts, solved
  implicitly (`constraints`): its joints' limits (`JointLimits`, rows when a limit can be
  reached within the period) and their Coulomb friction with stiction
  (`JointCoulombFriction`, a row per joint with c_j > 0, |lambda_j| <= c_j h).

The compiled system of bodies (src/uvms_core/system.hpp) holds the fixtures, built from their
``limits``, ``damping`` and ``coulomb``: their joints' dynamics and their exact step
(src/uvms_core/joint_box.hpp); with rigid moving contacts, the same choice as `with_fixtures`
(a rigid contact acting on a fixture's joints brings its limits and friction into the one
solve, src/uvms_core/moving_constraints.hpp).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from uvms_pin.physics.constraints.joint_box import joint_box_step
from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.rows import JOINT_IMPULSE_UNIT, ConstraintRows
from uvms_pin.physics.constraints.step import ConstrainedVelocity
from uvms_pin.physics.dynamics import forward_dynamics
from uvms_pin.physics.world.fixture import Fixture

__all__ = [
    "FIXTURE_FRICTION",
    "FIXTURE_JOINTS",
    "FIXTURE_LIMITS",
    "accelerations",
    "blocks",
    "constraints",
    "joint_ids",
    "system_model",
    "with_fixtures",
]

#: the names of the fixtures' constraint sets (their impulses in a solved period)
FIXTURE_LIMITS, FIXTURE_FRICTION = "fixture_limits", "fixture_friction"
#: ... and of their joints' exact steps (`with_fixtures`)
FIXTURE_JOINTS = "fixture_joints"


def system_model(model: pin.Model, fixtures: Sequence[Fixture]) -> pin.Model:
    """``model`` (the robot's joints and the free objects' free-flyers) with every
    fixture's joints appended, named ``<fixture>.<joint>``, with their URDF limits and
    bodies (each fixture's model is placed in the world already: its root joints hang
    from the universe)."""
    out = pin.Model(model)
    for fixture in fixtures:
        own = fixture.uvms.model
        ids = [0]
        for j in range(1, own.njoints):
            joint = own.joints[j]
            q, v = slice(joint.idx_q, joint.idx_q + joint.nq), slice(joint.idx_v, joint.idx_v + 1)
            added = out.addJoint(
                ids[own.parents[j]], joint, own.jointPlacements[j], f"{fixture.name}.{own.names[j]}",
                own.effortLimit[v], own.velocityLimit[v], own.lowerPositionLimit[q],
                own.upperPositionLimit[q],
            )  # fmt: skip
            out.appendBodyToJoint(added, own.inertias[j], pin.SE3.Identity())
            ids.append(added)
    return out


def joint_ids(first: int, fixtures: Sequence[Fixture]) -> list[tuple[int, ...]]:
    """Each fixture's joints in the system's model, whose first fixture joint is ``first``."""
    out, at = [], first
    for fixture in fixtures:
        n = fixture.uvms.model.njoints - 1
        out.append(tuple(range(at, at + n)))
        at += n
    return out


def blocks(
    first: int, first_v: int, fixtures: Sequence[Fixture]
) -> list[tuple[slice, tuple[int, ...]]]:
    """(its part of the system's v, its system joints) of every fixture, the first fixture
    joint being system joint ``first`` at velocity index ``first_v``."""
    out, at = [], first_v
    for own in joint_ids(first, fixtures):
        out.append((slice(at, at + len(own)), own))
        at += len(own)
    return out


def constraints(first: int, fixtures: Sequence[Fixture]) -> tuple:
    """The fixtures' joint limits and Coulomb friction as constraint sets of the system's
    model (``first``: the system joint of the first fixture joint), each only when some
    joint has one."""
    ids = joint_ids(first, fixtures)
    limited, rubbing, coulomb = [], [], []
    for fixture, own in zip(fixtures, ids, strict=True):
        lower, _ = fixture.limits
        friction = fixture.coulomb
        for i, system_joint in enumerate(own):
            if np.isfinite(lower[i]):
                limited.append(system_joint)
            if friction[i] > 0.0:
                rubbing.append(system_joint)
                coulomb.append(float(friction[i]))
    out: list = []
    if limited:
        out.append(JointLimits(tuple(limited), name=FIXTURE_LIMITS))
    if rubbing:
        out.append(JointCoulombFriction(tuple(rubbing), np.array(coulomb), FIXTURE_FRICTION))
    return tuple(out)


def accelerations(
    fixtures: Sequence[Fixture],
    states: Sequence[tuple[np.ndarray, np.ndarray]],
    contact_torques: Sequence[np.ndarray],
    water: dict,
) -> list[np.ndarray]:
    """Each fixture's joint accelerations (nv_f,) [rad/s^2 or m/s^2] at its (q_f, qd_f) of
    ``states`` with its contacts' generalized force ``contact_torques`` and its viscous
    friction -D qd_f (`Fixture.viscous_torque`); ``water``: the keyword arguments of
    `forward_dynamics` (flow, time, backend, free surface)."""
    return [
        forward_dynamics(f.uvms, q, v, f.viscous_torque(v), tau_ext=tau, **water)
        for f, (q, v), tau in zip(fixtures, states, contact_torques, strict=True)
    ]


def with_fixtures(
    solve: Callable[..., ConstrainedVelocity],
    fixture_sets: tuple,
    blocks: Sequence[tuple[slice, tuple[int, ...]]],
    model: pin.Model,
    mass_matrix: np.ndarray,
    v_free: np.ndarray,
    q: np.ndarray,
    sets: Sequence,
    period_s: float,
    **kw,
) -> ConstrainedVelocity:
    """The period's constraint step (``solve``: `step.constrained_velocity`, its arguments
    after ``blocks``) with the fixtures' joints: their rows (friction and limits) act on
    their own coordinates only (the bodies meet through smooth contact forces; M is block
    diagonal over the bodies), so the other sets (``sets`` but ``fixture_sets``) are
    solved as without fixtures, and each fixture's joints (``blocks``: its part of v and
    its system joints) by their exact step (`joint_box_step`: no creep below their
    friction; a joint's friction and its limit on one coordinate no harder than either).
    When a row of the other sets acts on a fixture (a rigid contact between a robot's link
    and a fixture's), everything is solved at once by ``solve``."""
    others = [c for c in sets if all(c is not f for f in fixture_sets)]
    out = solve(model, mass_matrix, v_free, q, others, period_s, **kw)
    if _touches_fixtures(out, blocks):  # a row of another set on a fixture (a rigid contact)
        return solve(model, mass_matrix, v_free, q, sets, period_s, **kw)  # all in one solve
    limits = next((c for c in fixture_sets if isinstance(c, JointLimits)), None)
    friction = next((c for c in fixture_sets if isinstance(c, JointCoulombFriction)), None)
    rubbing = (
        {} if friction is None else dict(zip(friction.joint_ids, friction.coulomb_Nm, strict=True))
    )
    limited = () if limits is None else limits.joint_ids
    # the speeds a limit is reached at, as the rows are selected (`step.constrained_velocity`):
    # the smooth step's end, and its start and mean (``least_speed``)
    least = kw.get("least_speed")
    speed = np.abs(v_free) if least is None else np.maximum(np.abs(v_free), np.abs(least))
    margin = 0.0 if limits is None else limits.margin
    steps = []
    for part, joints in blocks:
        if not joints:
            continue  # a fixture without a moving joint
        at = np.array([model.joints[j].idx_q for j in joints])
        lower = np.where(
            [j in limited for j in joints], q[at] - model.lowerPositionLimit[at], np.inf
        )
        upper = np.where(
            [j in limited for j in joints], model.upperPositionLimit[at] - q[at], np.inf
        )
        coulomb = np.array([rubbing.get(j, 0.0) for j in joints])
        step = joint_box_step(v_free[part], mass_matrix[part, part], coulomb, (lower, upper),
                              period_s)  # fmt: skip
        # a limit the period can reach is a row even when it pushes nothing at the end: the
        # joint then moves from q0 with v+, inside its limits, not by the smooth step's end,
        # which may have swung through the limit and back within a long period
        reach = period_s * speed[part] + margin
        near = (lower <= reach) | (upper <= reach)
        steps += [
            (joint, part.start + i, step.velocity[i], step.friction_impulse[i],
             step.limit_impulse[i])
            for i, joint in enumerate(joints)
            if joint in rubbing or step.limit_impulse[i] != 0.0 or near[i]
        ]  # fmt: skip
    return _joined(out, steps)


def _touches_fixtures(out: ConstrainedVelocity, blocks) -> bool:
    """Some row ``out`` solved acts on a fixture's coordinates: the fixtures' joints are
    then not apart from the other constraints."""
    columns = [k for part, _ in blocks for k in range(part.start, part.stop)]
    return bool(columns) and any(np.any(b.jacobian[:, columns] != 0.0) for b in out.rows)


def _joined(out: ConstrainedVelocity, joints: list) -> ConstrainedVelocity:
    """``out`` with the fixture joints' exact steps, each (system joint, velocity index, v+,
    friction impulse, limit impulse): their rates, impulses (the set `FIXTURE_JOINTS`: the
    friction's and the limits' per joint) and rows (e_j: the joint's body moves from q0
    with v+)."""
    if not joints:
        return out
    velocity, generalized = out.velocity.copy(), out.generalized_impulse.copy()
    jacobian, impulses = np.zeros((len(joints), velocity.size)), np.zeros((len(joints), 2))
    for row, (_, k, rate, friction, limit) in enumerate(joints):
        velocity[k] = rate
        generalized[k] += friction + limit
        jacobian[row, k] = 1.0
        impulses[row] = (friction, limit)
    rows = ConstraintRows(
        FIXTURE_JOINTS, JOINT_IMPULSE_UNIT, (), (), jacobian, np.zeros(len(joints)),
        np.zeros(len(joints), dtype=bool), tuple(f"joint {j[0]}" for j in joints),
    )  # fmt: skip
    return dataclasses.replace(
        out, velocity=velocity, generalized_impulse=generalized, rows=(*out.rows, rows),
        impulses={**out.impulses, FIXTURE_JOINTS: impulses.reshape(-1)},
        units={**out.units, FIXTURE_JOINTS: JOINT_IMPULSE_UNIT},
    )  # fmt: skip
