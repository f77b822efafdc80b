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

The compiled system of bodies holds free objects only: a system with a fixture is stepped
by the Python integrator (`COMPILED_REFUSAL`, said once in `why_not_compiled_system`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.rows import JOINT_IMPULSE_UNIT, ConstraintRows
from uvms_pin.physics.constraints.single_joint import single_joint_step
from uvms_pin.physics.constraints.step import ConstrainedVelocity, default_settings
from uvms_pin.physics.dynamics import forward_dynamics
from uvms_pin.physics.world.fixture import Fixture

__all__ = [
    "COMPILED_REFUSAL",
    "FIXTURE_FRICTION",
    "FIXTURE_JOINTS",
    "FIXTURE_LIMITS",
    "STICKING_RATE",
    "accelerations",
    "blocks",
    "constraints",
    "joint_ids",
    "system_model",
    "with_fixtures",
]

#: why a system with a fixture is not one compiled call a period
COMPILED_REFUSAL = "a fixture with joints (type = \"urdf\"): the compiled system holds free objects only"

#: the rate [rad/s or m/s] a sticking fixture joint may keep after the solve: the ADMM
#: solver's tolerance is on its residual sigma - G lambda, which leaves a joint of inverse
#: inertia G a rate error of about G times it (a valve handle of 6.6e-3 kg m^2: 150 times)
STICKING_RATE = 1.0e-10
#: the iterations the tight solve may take (a plain stick: about 40)
TIGHT_ITERATIONS = 300

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
        model = fixture.uvms.model
        for j, system_joint in zip(range(1, model.njoints), own, strict=True):
            q = model.joints[j].idx_q
            low, high = model.lowerPositionLimit[q], model.upperPositionLimit[q]
            if np.isfinite(low) and np.isfinite(high) and max(-low, high) < 1e300:
                limited.append(system_joint)
            if model.friction[model.joints[j].idx_v] > 0.0:
                rubbing.append(system_joint)
                coulomb.append(float(model.friction[model.joints[j].idx_v]))
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
        forward_dynamics(
            f.uvms, q, v, f.viscous_torque(v), tau_ext=tau, **water
        )
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
    after ``blocks``) with the fixtures' joints: their rows act on their own coordinates
    only (the bodies meet through smooth contact forces; M is block diagonal), so the
    others' sets (``sets`` but ``fixture_sets``) are solved as without fixtures, and each
    fixture of one joint (``blocks``: its part of v and its system joints) by its exact
    step (`single_joint_step`: no creep below its friction, the friction and a limit on one
    coordinate no harder); the fixtures of several joints by the solver, to the tolerance
    `STICKING_RATE` / max_j G_jj (`_held`)."""
    others = [c for c in sets if all(c is not f for f in fixture_sets)]
    single = all(len(joints) <= 1 for _, joints in blocks)
    if not single:
        return _held(solve, mass_matrix, [p for p, _ in blocks], model, mass_matrix, v_free, q,
                     sets, period_s, **kw)  # fmt: skip
    out = solve(model, mass_matrix, v_free, q, others, period_s, **kw)
    return _joined(out, _single_joints(fixture_sets, blocks, model, mass_matrix, v_free, q,
                                       period_s))  # fmt: skip


def _single_joints(fixture_sets, blocks, model, mass_matrix, v_free, q, period_s):
    """(system joint, its velocity index, v+, the friction's and the limits' impulses) of
    each fixture joint some friction or a reachable limit acts on (`single_joint_step`)."""
    limits = next((c for c in fixture_sets if isinstance(c, JointLimits)), None)
    friction = next((c for c in fixture_sets if isinstance(c, JointCoulombFriction)), None)
    rubbing = {} if friction is None else dict(zip(friction.joint_ids, friction.coulomb_Nm))
    limited = () if limits is None else limits.joint_ids
    out = []
    for part, joints in blocks:
        if not joints:
            continue  # a fixture without a moving joint
        joint = joints[0]
        at = model.joints[joint].idx_q
        gaps = (q[at] - model.lowerPositionLimit[at], model.upperPositionLimit[at] - q[at])
        if joint not in limited:
            gaps = (np.inf, np.inf)
        k = part.start
        step = single_joint_step(float(v_free[k]), float(mass_matrix[k, k]),
                                 float(rubbing.get(joint, 0.0)), gaps, period_s)  # fmt: skip
        if joint in rubbing or step.limit_impulse != 0.0:
            out.append((joint, k, step))
    return out


def _joined(out: ConstrainedVelocity, joints: list) -> ConstrainedVelocity:
    """``out`` with the fixture joints' exact steps: their rates, impulses (the set
    `FIXTURE_JOINTS`: friction and limit per joint, one row each) and rows (e_j, acting on
    the joint: its body moves from q0 with v+)."""
    if not joints:
        return out
    velocity, generalized = out.velocity.copy(), out.generalized_impulse.copy()
    nv = velocity.size
    jacobian, impulses = np.zeros((len(joints), nv)), np.zeros((len(joints), 2))
    for row, (_, k, step) in enumerate(joints):
        velocity[k] = step.velocity
        generalized[k] += step.friction_impulse + step.limit_impulse
        jacobian[row, k] = 1.0
        impulses[row] = (step.friction_impulse, step.limit_impulse)
    rows = ConstraintRows(
        FIXTURE_JOINTS, JOINT_IMPULSE_UNIT, (), (), jacobian, np.zeros(len(joints)),
        np.zeros(len(joints), dtype=bool), tuple(f"joint {j}" for j, _, _ in joints),
    )  # fmt: skip
    return dataclasses.replace(
        out, velocity=velocity, generalized_impulse=generalized, rows=(*out.rows, rows),
        impulses={**out.impulses, FIXTURE_JOINTS: impulses.reshape(-1)},
        units={**out.units, FIXTURE_JOINTS: JOINT_IMPULSE_UNIT},
    )  # fmt: skip


def _held(solve, mass_matrix: np.ndarray, v_slices, *args, **kw) -> ConstrainedVelocity:
    """``solve`` to the tolerance `STICKING_RATE` / max_j G_jj, G_jj = (M^-1)_jj each
    fixture joint's inverse inertia (``v_slices``: the fixtures' parts of v), so that a
    joint held by stiction keeps no rate beyond `STICKING_RATE` (not the default
    tolerance's 1e-8 G); a period that does not reach it in `TIGHT_ITERATIONS` (a joint at
    its limit and held by its friction: two rows on one coordinate) is the default's."""
    inverse = [np.diag(np.linalg.inv(mass_matrix[p, p])) for p in v_slices if p.stop > p.start]
    largest = max((float(np.max(g)) for g in inverse), default=1.0)
    tolerance = min(1.0e-8, STICKING_RATE / max(largest, 1.0))
    tight = solve(*args, settings=default_settings(tolerance, TIGHT_ITERATIONS), **kw)
    return tight if tight.converged else solve(*args, **kw)
