"""What only a blown-up integration gives: a non-finite state or an absurd speed, and the
numerical errors that mean the same; and what a divergence message says about where it
came from (`divergence_context`)."""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.errors import SimulationError
from uvms_pin.results.status import RunStatus

#: A speed this large [m/s or rad/s] only comes out of a blown-up integration.
DIVERGED_SPEED = 1e4

#: What numerical code raises on a blown-up state (a singular chart Jacobian or mass
#: matrix, an overflow): reported as a SimulationError with the partial rollout kept.
NUMERICAL_FAILURES = (np.linalg.LinAlgError, FloatingPointError, OverflowError, ZeroDivisionError)


def diverged(q: np.ndarray, v: np.ndarray) -> bool:
    """True for a state only a blown-up integration gives: non-finite, or a speed above
    `DIVERGED_SPEED`."""
    # one reduction each: a sum is NaN or inf if any entry is, and v . v bounds every v_i^2
    # (NaN fails the test); the exact test only when they do not settle it (a sum beyond
    # 1e308, a speed past half the bound: the margin keeps v . v's rounding out of it)
    if math.isfinite(float(q.sum())) and float(v @ v) < (0.5 * DIVERGED_SPEED) ** 2:
        return False
    return not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))) or bool(
        np.max(np.abs(v)) > DIVERGED_SPEED
    )


#: What no UVMS meets, per quantity: a water speed [m/s], a force or moment [N, N m] (its
#: thrusters make tens to hundreds), a speed [m/s or rad/s]. Past these, a quantity is named
#: as the likely cause of a divergence.
_IMPLAUSIBLE = {"water": 20.0, "wrench": 1e5, "speed": 100.0}
_VEHICLE_WRENCH = (("fx", "N"), ("fy", "N"), ("fz", "N"), ("mx", "N m"), ("my", "N m"), ("mz", "N m"))  # fmt: skip


def _labels(uvms) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """(name, unit) of each velocity and each generalized force component."""
    arm = uvms.arm_joints
    linear = [arm_kind == "prismatic" for arm_kind in arm.kinds]
    velocity = [("vehicle u", "m/s"), ("vehicle v", "m/s"), ("vehicle w", "m/s"),
                ("vehicle p", "rad/s"), ("vehicle q", "rad/s"), ("vehicle r", "rad/s")]  # fmt: skip
    velocity += [(n, "m/s" if lin else "rad/s") for n, lin in zip(arm.names, linear, strict=True)]
    force = [(f"vehicle {n}", u) for n, u in _VEHICLE_WRENCH]
    force += [(n, "N" if lin else "N m") for n, lin in zip(arm.names, linear, strict=True)]
    return velocity, force


#: A joint torque at least this fraction of the joint's effort limit is "at its limit".
AT_EFFORT_LIMIT = 0.9


def implausible_motion(
    uvms, time_s: np.ndarray, v: np.ndarray, v0: np.ndarray, tau: np.ndarray | None = None
) -> tuple[float, str] | None:
    """(when, why) a run that stayed finite is not physics, or None: the first logged sample (times
    ``time_s`` (T,) [s], velocities ``v`` (T, nv)) at which a velocity of the UVMS, the
    vehicle's or an arm joint's, is past what no UVMS reaches (100 m/s or rad/s), in a run
    that started below it (``v0``). Joint limits and damping keep such a motion bounded, so
    nothing diverges; most often it is a sampled control loop unstable at its control
    period (a derivative gain k_d with k_d T / I > 2 on a light link of inertia I sampled
    every T), else a step too coarse for a stiff setting. With the applied generalized
    forces ``tau`` (T, nv): of a joint whose torque reached its effort limit (the URDF's,
    `AT_EFFORT_LIMIT` of it) up to that sample, that too is said: a torque held at the limit
    drives a light joint there, the simulated drive keeping it at any speed (a real
    drive's falls to zero at its no-load speed, about the URDF's velocity limit)."""
    bound = _IMPLAUSIBLE["speed"]
    if len(v) == 0 or np.max(np.abs(v0)) > bound:
        return None
    past = np.abs(v) > bound
    if not past.any():
        return None
    row = int(np.argmax(past.any(axis=1)))
    k = int(np.argmax(np.abs(v[row])))
    name, unit = _labels(uvms)[0][k]
    at = (
        f"the motion left physics at t = {time_s[row]:.6g} s: {name} at {v[row, k]:.3g} {unit}, "
        f"past the {bound:g} m/s or rad/s no UVMS reaches (bounded by its limits, not "
        "diverged)"
    )
    driven = None if tau is None or k < 6 else _driven_at_its_limit(uvms, tau[: row + 1], k)
    return float(time_s[row]), (
        f"{at}: most often the control loop is unstable at its control period (a "
        "derivative gain too large for a light link's inertia at this period: shorten "
        "control.period_s or lower the gains), else the step is too coarse"
        + ("" if driven is None else f"; {driven}")
    )


def _driven_at_its_limit(uvms, tau: np.ndarray, k: int) -> str | None:
    """What drove velocity ``k`` (an arm joint's) when its applied torques ``tau`` (T, nv)
    reached its effort limit, or None."""
    effort = float(uvms.model.effortLimit[k])
    peak = float(np.max(np.abs(tau[:, k])))
    if not (math.isfinite(effort) and effort > 0.0 and peak >= AT_EFFORT_LIMIT * effort):
        return None
    _, unit = _labels(uvms)[1][k]
    speed = float(uvms.model.velocityLimit[k])
    limit = (
        f" (this joint's URDF velocity limit: {speed:g})"
        if math.isfinite(speed) and speed > 0.0
        else ""
    )
    return (
        f"its drive applied up to {peak:.3g} {unit}, at its effort limit ({effort:.3g} "
        f"{unit}): a torque held there (a saturated loop's, random actions at their bounds) "
        "drives a light joint this fast too, the simulated drive keeping it at any speed "
        f"where a real one's falls to zero at its no-load speed{limit}"
    )


def stop_if_implausible(uvms, rollout, v0: np.ndarray) -> None:
    """Raise a SimulationError (``rollout`` attached, its status the stop and its reason)
    when the rollout's motion is `implausible_motion`."""
    found = implausible_motion(uvms, rollout.time_s, rollout.v, v0, rollout.tau)
    if found is not None:
        time_s, reason = found
        error = SimulationError(reason)
        error.rollout = rollout
        rollout.set_status(RunStatus(type(error).__name__, reason, time_s))
        raise error


def divergence_context(
    plant, span_s: tuple[float, float], q: np.ndarray, v: np.ndarray, tau
) -> str:
    """What stands out in the state and inputs of a diverged interval ``span_s`` (the state
    at its start): each quantity far outside what any vehicle meets (the water's speed at
    the vehicle, the applied generalized force, the disturbance, the contact wrench, a
    velocity; the time-varying ones over the interval), with its value and where; else the
    largest velocity component. One clause, for the divergence message."""
    velocity_labels, force_labels = _labels(plant.uvms)
    found: list[tuple[float, str]] = []

    def largest(values, labels, scale: float, what: str) -> None:
        values = np.atleast_2d(np.asarray(values, dtype=float))  # (times, components)
        if values.size == 0:
            return
        row, k = np.unravel_index(
            int(np.argmax(np.abs(np.nan_to_num(values, nan=np.inf)))), values.shape
        )
        value = values[row, k]
        if not abs(value) <= scale:  # NaN included
            name, unit = labels[k]
            found.append((abs(value) / scale, f"{what} {name} = {value:.3g} {unit}"))

    times = (span_s[0], 0.5 * (span_s[0] + span_s[1]), span_s[1])
    if plant.water is not None:
        at = np.asarray(q[:3], dtype=float)[None]
        speeds = [[float(np.linalg.norm(plant.water.velocity(t, at)[0]))] for t in times]
        largest(speeds, [("at the vehicle", "m/s")], _IMPLAUSIBLE["water"], "water speed")
    if tau is not None:
        largest(tau, force_labels, _IMPLAUSIBLE["wrench"], "applied generalized force")
    disturbance = [plant.disturbance_wrench(t) for t in times]
    largest(disturbance, force_labels, _IMPLAUSIBLE["wrench"], "disturbance")
    if plant.contact is not None:
        wrench_labels = [(n.removeprefix("vehicle "), u) for n, u in force_labels[:6]]
        largest(plant.contact_wrench(q, v), wrench_labels, _IMPLAUSIBLE["wrench"],
                "contact wrench (world)")  # fmt: skip
    largest(v, velocity_labels, _IMPLAUSIBLE["speed"], "velocity")
    t0 = span_s[0]
    if found:
        found.sort(reverse=True)
        return f"from t = {t0:.6g} s: " + ", ".join(text for _, text in found[:3])
    singular = singular_mass(plant.uvms, q)
    if singular:
        return f"at t = {t0:.6g} s {singular}"
    k = int(np.argmax(np.abs(v)))
    name, unit = velocity_labels[k]
    return (
        f"at t = {t0:.6g} s every input was in a physical range; the largest velocity "
        f"was {name} = {v[k]:.3g} {unit}"
    )


def singular_mass(uvms, q: np.ndarray) -> str:
    """ "the mass matrix is singular ..." naming the least-massive degree of freedom at
    ``q`` (finite), or "" (positive definite)."""
    from uvms_pin.physics.dynamics import mass_matrix

    labels = _labels(uvms)[0]  # by velocity
    mass = mass_matrix(uvms, q, backend="python")  # q: the last state reached, finite
    eigenvalues, vectors = np.linalg.eigh(mass)
    if eigenvalues[0] > 1e-12 * max(eigenvalues[-1], 1e-300):
        return ""
    k = int(np.argmax(np.abs(vectors[:, 0])))
    return (
        f"the mass matrix is singular (smallest eigenvalue {eigenvalues[0]:.3g}), along "
        f"{labels[k][0]} mostly: a body without inertia about that motion (a link with no "
        "mass, added mass or armature)"
    )
