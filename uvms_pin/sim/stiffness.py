"""Stable at its step, or refused before the run: the explicit stiff modes of a run
(`uvms_pin.sim.stiff_modes`) against its fixed-step integrator.

A fixed step h integrates the mode y' = A y (y = (x, x_dot), A its `StiffMode.rate_matrix`)
as y+ = Phi(h) y (`uvms_pin.sim.integrators.FixedStep.linear_step`: RK4's Phi = R(h A) with
R the degree-4 Taylor polynomial, stable while |R(h lambda)| <= 1 for both rates lambda;
semi-implicit Euler's own matrix). The mode is stable while Phi's spectral radius is <= 1;
its largest stable step h* is where it first exceeds 1 (for an undamped mode
h* omega = 2 sqrt(2) with RK4, 2 with semi-implicit Euler; for a strongly damped one
h* c / m_eff = 2.785 with RK4). `check_stiff_modes` raises a `StiffModeError` naming the mode
whose h* is below the run's step, before anything is integrated, and otherwise gives the
record a rollout keeps (``metadata["stiff_modes"]``): the stiffest mode and its margin
h* / h. An adaptive integrator chooses its own step: nothing is checked, and the record
says so.
"""

from __future__ import annotations

import cmath
import math
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import StiffModeError
from uvms_pin.sim.integrators import FixedStep, Integrator
from uvms_pin.sim.stiff_modes import (
    Body,
    StiffMode,
    body_mobility,
    contact_modes,
    environment_mode,
    stop_modes,
    working_depth_m,
)
from uvms_pin.sim.system import System, SystemState

__all__ = ["check_stiff_modes", "largest_stable_step_s", "system_modes"]

#: the spectral radius a stable step may reach (an undamped mode under semi-implicit Euler
#: keeps exactly 1, rounding aside)
_RADIUS_SLACK = 1e-9


def _spectral_radius(phi: np.ndarray) -> float:
    """max |mu| of a 2 x 2 matrix's eigenvalues mu (mu^2 - tr mu + det = 0)."""
    trace, det = phi[0, 0] + phi[1, 1], phi[0, 0] * phi[1, 1] - phi[0, 1] * phi[1, 0]
    root = cmath.sqrt(trace * trace / 4.0 - det)
    return max(abs(trace / 2.0 + root), abs(trace / 2.0 - root))


def is_stable(integrator: FixedStep, step_s: float, mode: StiffMode) -> bool:
    """Whether one step of ``step_s`` [s] keeps ``mode`` bounded (spectral radius <= 1)."""
    phi = integrator.linear_step(step_s, mode.rate_matrix)
    return _spectral_radius(phi) <= 1.0 + _RADIUS_SLACK


def largest_stable_step_s(
    integrator: FixedStep, mode: StiffMode, above_s: float = math.inf
) -> float:
    """h* [s]: the step at which ``mode`` turns unstable (inf if it never does), to 1e-12
    relative: doubling from 1e-3 / |lambda|_max, then bisection (the stable steps of a mode
    with Re lambda <= 0 are an interval [0, h*] for the shipped integrators). Once a stable
    step exceeds ``above_s`` the search stops there and returns inf: h* > above_s is all a
    caller looking for the least h* needs (the same steps are tried until then, so an h*
    below it is the same number)."""
    fastest = float(np.max(np.abs(mode.rates)))
    if fastest == 0.0:
        return math.inf
    low, high = 0.0, 1e-3 / fastest
    while is_stable(integrator, high, mode):
        low, high = high, 2.0 * high
        if high > 1e6 / fastest or low > above_s:
            return math.inf
    while high - low > 1e-12 * high:
        middle = 0.5 * (low + high)
        low, high = (middle, high) if is_stable(integrator, middle, mode) else (low, middle)
        if low > above_s:
            return math.inf
    return low


def _stiffest(integrator: FixedStep, modes: list[StiffMode]) -> tuple[int, float]:
    """(k, h*_k) of the first mode with the least h* (np.argmin's choice over every mode's
    `largest_stable_step_s`). The modes are searched fastest first (the likely least h*),
    each only until its stable steps pass the least h* so far (it cannot be the least
    then): some fifty stability tests a mode become a few."""
    order = sorted(range(len(modes)), key=lambda k: -float(np.max(np.abs(modes[k].rates))))
    best_k, best = None, math.inf
    for k in order:
        limit = largest_stable_step_s(integrator, modes[k], best)
        if best_k is None or limit < best or (limit == best and k < best_k):
            best_k, best = k, limit
    return best_k, best


def _robot_bodies(system: System, data: pin.Data, inverse: np.ndarray) -> list[Body]:
    world, uvms = system.plant.world, system.plant.uvms
    depth = working_depth_m(uvms.net_buoyancy_N, world.law)
    out = []
    for b, name in enumerate(world.body_names):
        pieces = [p for p in world.pieces if p.body == b]
        mobility = body_mobility(uvms.model, data, inverse, pieces)
        out.append(Body(f"link '{name}'", mobility, depth))
    return out


def _object_bodies(system: System, state: SystemState, inverse: np.ndarray) -> list[Body]:
    law, layout = system.plant.world.law, system.layout
    out = []
    for k, obj in enumerate(system.objects):
        model = obj.uvms.model
        data = model.createData()
        pin.computeJointJacobians(model, data, state.q[layout.q_slices[k + 1]])
        part = layout.v_slices[k + 1]
        mobility = body_mobility(model, data, inverse[part, part], list(obj.pieces))
        depth = working_depth_m(obj.uvms.net_buoyancy_N, law)
        out.append(Body(f"free object '{obj.name}'", mobility, depth))
    return out


def _fixture_bodies(
    system: System, state: SystemState, inverse: np.ndarray
) -> tuple[list[Body], list[str]]:
    """Each fixture's links that move (a joint >= 1 carries their pieces), their mobility
    through the fixture's own joints (its block of M^-1), and the fixtures whose root link
    touches (fixed: a contact there is one with the fixed world). A link's working depth is
    the least (its weight goes to its joint)."""
    law, layout = system.plant.world.law, system.layout
    first = 1 + len(system.objects)
    links, rooted = [], []
    for k, fixture in enumerate(system.fixtures):
        model = fixture.uvms.model
        data = model.createData()
        pin.computeJointJacobians(model, data, state.q[layout.q_slices[first + k]])
        part = layout.v_slices[first + k]
        if any(p.joint_id == 0 for p in fixture.pieces):
            rooted.append(fixture.name)
        for joint in sorted({p.joint_id for p in fixture.pieces} - {0}):
            pieces = [p for p in fixture.pieces if p.joint_id == joint]
            mobility = body_mobility(model, data, inverse[part, part], pieces)
            name = f"link on joint '{model.names[joint]}' of fixture '{fixture.name}'"
            links.append(Body(name, mobility, working_depth_m(0.0, law)))
    return links, rooted


def _self_bodies(system: System, data: pin.Data, inverse: np.ndarray) -> list[Body]:
    """The arm's links that can touch their vehicle, each relative to it."""
    world, uvms = system.plant.world, system.plant.uvms
    model, depth = uvms.model, working_depth_m(uvms.net_buoyancy_N, world.law)
    out = []
    for b, name in enumerate(world.body_names):
        pieces = [
            p
            for p in world.pieces
            if p.body == b and p.joint_id > 1 and model.parents[p.joint_id] != 1
        ]
        if pieces:
            mobility = body_mobility(model, data, inverse, pieces, relative_to=1)
            out.append(Body(f"link '{name}'", mobility, depth))
    return out


def _world_modes(
    system: System, state: SystemState, data: pin.Data, inverse: np.ndarray
) -> list[StiffMode]:
    world = system.plant.world
    law = world.law
    robot_inverse = inverse[system.layout.v_slices[0], system.layout.v_slices[0]]
    robot = _robot_bodies(system, data, robot_inverse)
    objects = _object_bodies(system, state, inverse)
    modes: list[StiffMode] = []
    if world.objects:
        fixed = ", ".join(f"'{o.name}'" for o in world.objects)
        for body in [*robot, *objects]:
            modes += contact_modes(
                f"{body.name} against the fixed world ({fixed})", body, None, law
            )
    if world.moving_contact == "rigid":  # constraints: no spring between moving bodies
        return modes
    for body in robot:
        for obj in objects:
            modes += contact_modes(f"{body.name} against the {obj.name}", body, obj, law)
    links, rooted = _fixture_bodies(system, state, inverse)
    for body in [*robot, *objects]:
        for link in links:
            modes += contact_modes(f"{body.name} against the {link.name}", body, link, law)
        for name in rooted:  # the fixture's fixed root link: a moving pair all the same
            modes += contact_modes(f"{body.name} against fixture '{name}'s base", body, None,
                                   law, moving=True)  # fmt: skip
    for i, first in enumerate(objects):
        for other in objects[i + 1 :]:
            modes += contact_modes(f"{first.name} against the {other.name}", first, other, law)
    if world.self_collision:
        for link in _self_bodies(system, data, robot_inverse):
            modes += contact_modes(f"{link.name} against its own vehicle", link, None, law)
    return modes


def system_modes(system: System, state: SystemState, time_s: float = 0.0) -> list[StiffMode]:
    """Every explicit stiff mode of ``system`` at ``state`` (`uvms_pin.sim.stiff_modes`)."""
    plant = system.plant
    if plant.joint_stops is None and plant.contact is None and plant.world is None:
        return []  # nothing stiff: no mass matrix to invert
    inverse = np.linalg.inv(system.mass_matrix(time_s, state.q))
    robot = system.layout.v_slices[0]
    robot_inverse = inverse[robot, robot]
    model = plant.uvms.model
    data = model.createData()
    q, _ = system.robot_state(state.q, state.v)
    pin.computeJointJacobians(model, data, q)
    modes: list[StiffMode] = []
    if plant.joint_stops is not None:
        modes += stop_modes(plant.joint_stops, robot_inverse, model.armature)
    if plant.contact is not None:
        frame = plant.uvms.ee_frame_id
        pin.updateFramePlacements(model, data)
        jac = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:3]
        mode = environment_mode(plant.contact, jac @ robot_inverse @ jac.T)
        modes += [] if mode is None else [mode]
    if plant.world is not None:
        modes += _world_modes(system, state, data, inverse)
    return modes


def check_stiff_modes(system: System, state: SystemState, integrator: Integrator) -> dict[str, Any]:
    """The record of the run's stiff modes at ``state`` under ``integrator``: the stiffest
    (the least largest stable step h*) and its margin h* / h.

    Raises:
        StiffModeError: a mode is unstable at the integrator's step (the least stable one
            named, with k, c, m_eff, the step and h*).
    """
    name = type(integrator).__name__
    if not isinstance(integrator, FixedStep):
        reason = "an adaptive integrator chooses its own step"
        return {"checked": False, "integrator": name, "reason": reason}
    if integrator.linear_step(1.0, np.eye(2)) is None:
        reason = "the integrator gives no linear step map (FixedStep.linear_step)"
        return {"checked": False, "integrator": name, "reason": reason}
    modes = system_modes(system, state)
    step_s = float(integrator.step_s)
    record: dict[str, Any] = {"checked": True, "integrator": name, "step_s": step_s}
    if not modes:
        return {**record, "modes": 0, "stiffest": None, "margin": None}
    k, limit = _stiffest(integrator, modes)
    stiffest = modes[k]
    if not is_stable(integrator, step_s, stiffest) or limit < step_s:
        raise StiffModeError(stiffest, name, step_s, limit)
    finite = math.isfinite(limit)
    return {
        **record,
        "modes": len(modes),
        "stiffest": {**stiffest.record(), "largest_stable_step_s": limit if finite else None},
        "margin": limit / step_s if finite else None,
    }
