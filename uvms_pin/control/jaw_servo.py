"""The jaw as a force-limited position servo, and the arm's controller beside it.

Each jaw joint i (a finger) follows its target with a saturated PD law,

    tau_i = clip(k_i (q_target,i - q_i) - d_i qdot_i, -F_max r_i, +F_max r_i),

with F_max the grip force [N] and r_i the finger's lever: the distance from a revolute
joint's axis to the finger body's centre of mass [m] (1 for a prismatic finger, whose tau
is a force already). A finger stopped by an object before its target presses it with
F_max at that point: the servo is then saturated. The stiffness k_i = F_max r_i / (0.05
travel) saturates the servo 5 % of the joint's travel away from its target, the damping
d_i = 2 sqrt(k_i I_i) critically damps the free finger (I_i its inertia about its joint,
from the composite rigid-body inertia at the closed position, `JawServo.for_model`). Sampled
every T [s] (a control period), the law is held over T: d_i T / I_i must stay well below 2,
so with a period k_i is capped at I_i / (4 T^2) (then d_i = I_i / T): a light finger gets a
softer servo that saturates further from its target, not a loop that diverges.

The target is the jaw's closed position (each joint's lower limit) from ``close_at_s`` until
``open_at_s`` and its open position (upper limit) otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.checks import number_fields
from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement, read_only
from uvms_pin.errors import ParameterError
from uvms_pin.model.jaw import JawJoints, slice_if_consecutive
from uvms_pin.results.signal import Signal, component_label

__all__ = ["JawSchedule", "JawServo", "WithJaw"]

#: the servo saturates this fraction of a joint's travel away from its target
SATURATION_TRAVEL_FRACTION = 0.05


@dataclass(frozen=True)
class JawSchedule:
    """When the jaw is closed: from ``close_at_s`` until ``open_at_s`` [s] (None: never
    opened again); open before and after."""

    close_at_s: float = 0.0
    open_at_s: float | None = None

    def __post_init__(self) -> None:
        number_fields(self)
        opened = math.inf if self.open_at_s is None else self.open_at_s
        if not (math.isfinite(self.close_at_s) and self.close_at_s >= 0.0):
            raise ParameterError(f"close_at_s must be finite and >= 0, got {self.close_at_s}")
        if not opened > self.close_at_s:
            raise ParameterError(
                f"open_at_s ({self.open_at_s}) must come after close_at_s ({self.close_at_s})"
            )

    def closed(self, time_s: float) -> bool:
        opened = math.inf if self.open_at_s is None else self.open_at_s
        return self.close_at_s <= time_s < opened


@dataclass(frozen=True)
class JawServo:
    """Force-limited position servo of each jaw joint (module docstring).

    Attributes:
        jaw: the jaw joints. max_force_N: each finger's grip force F_max [N].
        lever_m: r_i per joint [m] (1 for prismatic). stiffness, damping: k_i, d_i per joint.
        schedule: when the jaw is closed.
    """

    jaw: JawJoints
    max_force_N: float
    lever_m: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    schedule: JawSchedule

    @classmethod
    def for_model(
        cls,
        model: pin.Model,
        jaw: JawJoints,
        max_force_N: float,
        schedule: JawSchedule,
        period_s: float | None = None,
    ) -> JawServo:
        """The servo of ``jaw`` in ``model``: levers, gains from the fingers' inertias
        (capped for a law sampled every ``period_s``; None: continuous)."""
        if not (math.isfinite(max_force_N) and max_force_N > 0.0):
            raise ParameterError(f"max_force_N must be positive, got {max_force_N}")
        lever = np.array([_lever_m(model, j) for j in jaw.joint_ids])
        travel = jaw.upper - jaw.lower
        stiffness = max_force_N * lever / (SATURATION_TRAVEL_FRACTION * travel)
        inertia = _joint_inertias(model, jaw)
        if period_s is not None:
            # k <= I / (4 T^2): T * T, the same bits as T**2, is inf past the float range
            # where ** raised OverflowError
            stiffness = np.minimum(stiffness, inertia / (4.0 * period_s * period_s))
        return cls(
            jaw, float(max_force_N), lever, stiffness, 2.0 * np.sqrt(stiffness * inertia), schedule
        )

    def target(self, time_s: float) -> np.ndarray:
        """Each jaw joint's target [rad or m]: closed (lower limit) or open (upper)."""
        return self.jaw.lower if self.schedule.closed(time_s) else self.jaw.upper

    def torque(self, time_s: float, q_jaw: np.ndarray, v_jaw: np.ndarray) -> np.ndarray:
        """tau per jaw joint [N m or N]: the saturated PD law toward `target`."""
        return self._law(self.target(time_s), q_jaw, v_jaw)

    def torques(self, times_s: np.ndarray, q_jaw: np.ndarray, v_jaw: np.ndarray) -> np.ndarray:
        """`torque` of several jaws at once: row i at ``times_s[i]`` [s] from ``q_jaw[i]``,
        ``v_jaw[i]`` (N, jaw joints) -> (N, jaw joints) [N m or N]."""
        closed = np.array([self.schedule.closed(float(t)) for t in times_s], dtype=bool)
        target = np.where(closed[:, None], self.jaw.lower, self.jaw.upper)
        return self._law(target, q_jaw, v_jaw)

    def signal(self, q_jaw: np.ndarray, tau_jaw: np.ndarray, units: Sequence[str]) -> Signal:
        """The jaw's log (``jaw.<joint>_rad``, ``jaw.<joint>_grip_N``): each joint's position
        ``q_jaw`` in ``units`` ("rad" or "m" per joint) and the force its torque ``tau_jaw``
        presses with at the finger's lever, |tau_i| / r_i [N]; the joints by their
        `component_label`."""
        names = [component_label(n) for n in self.jaw.names]
        return Signal(
            np.concatenate([q_jaw, np.abs(tau_jaw) / self.lever_m]),
            [*names, *(f"{n}_grip" for n in names)],
            [*units, *("N",) * len(names)],
        )

    def _law(self, target: np.ndarray, q_jaw: np.ndarray, v_jaw: np.ndarray) -> np.ndarray:
        limit = self.max_force_N * self.lever_m
        raw = self.stiffness * (target - q_jaw) - self.damping * v_jaw
        # minimum(maximum()) is np.clip without its per-call dispatch cost (the same bits)
        return np.minimum(np.maximum(raw, -limit), limit)


class WithJaw(Controller):
    """The arm's controller (built on the model with its jaw locked, `uvms_pin.model.
    jaw_locked`) beside the jaw's servo: the arm's controller sees q and v without the jaw's
    entries and commands the vehicle and arm joints; the servo commands the jaw.

    Logged (`signals`): ``jaw.<joint>_rad`` (or ``_m``), each jaw joint's position, and
    ``jaw.<joint>_grip_N``, the force its servo presses with at the finger's lever,
    |tau_i| / r_i [N].
    """

    def __init__(self, arm: Controller, servo: JawServo, nv: int, prismatic: tuple[bool, ...]):
        self.arm = arm
        self.servo = servo
        self._tau = np.zeros(nv)
        self._jaw_tau = np.zeros(servo.jaw.count)
        self._jaw_q = np.zeros(servo.jaw.count)
        self._unit = tuple("m" if p else "rad" for p in prismatic)
        # where the arm's and the jaw's entries are in q and v: slices when consecutive
        jaw = servo.jaw
        self._arm_q, self._arm_v = map(slice_if_consecutive, (jaw.arm_q_index, jaw.arm_v_index))
        self._jaw_q_at, self._jaw_v_at = map(slice_if_consecutive, (jaw.q_index, jaw.v_index))

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        q, v = measurement.q, measurement.v
        # views of the measurement's frozen arrays, or an index array's copies frozen: the
        # arm's measurement keeps them as they are
        arm_measurement = Measurement(
            time_s,
            read_only(q[self._arm_q]),
            read_only(v[self._arm_v]),
            measurement.wrench_world,
            measurement.images,
        )
        tau = self._tau.copy()
        tau[self._arm_v] = self.arm.compute(time_s, arm_measurement)
        self._jaw_q = q[self._jaw_q_at]  # frozen (a view of the measurement's) or a copy
        self._jaw_tau = self.servo.torque(time_s, self._jaw_q, v[self._jaw_v_at])
        tau[self._jaw_v_at] = self._jaw_tau
        return tau

    def reset(self) -> None:
        self.arm.reset()

    def signals(self) -> dict[str, np.ndarray | Signal]:
        jaw = self.servo.signal(self._jaw_q, self._jaw_tau, self._unit)
        return {**self.arm.signals(), "jaw": jaw}

    def funnel_margin(self) -> float:
        return self.arm.funnel_margin()

    def set_funnel_extension(self, enabled: bool) -> None:
        self.arm.set_funnel_extension(enabled)


def _lever_m(model: pin.Model, joint_id: int) -> float:
    """A revolute joint's distance from its axis to its body's centre of mass [m]; 1 for a
    prismatic joint (its tau is the finger's force)."""
    joint = model.joints[joint_id]
    data = model.createData()
    q = pin.neutral(model)
    pin.forwardKinematics(model, data, q)
    axis = _motion_axis(model, data, joint_id)
    if np.linalg.norm(axis.angular) < 0.5:  # prismatic: a pure translation
        return 1.0
    com = model.inertias[joint_id].lever
    w = axis.angular / np.linalg.norm(axis.angular)
    radial = com - np.dot(com, w) * w
    lever = float(np.linalg.norm(radial))
    if lever < 1e-4:
        raise ParameterError(
            f"jaw joint '{model.names[joint_id]}': its body's centre of mass is on the joint "
            f"axis ({lever:.2g} m away), so its grip force has no lever; give the finger's "
            f"inertial origin (joint {joint.shortname()})"
        )
    return lever


def _motion_axis(model: pin.Model, data: pin.Data, joint_id: int) -> pin.Motion:
    """The joint's unit motion in its own frame (its motion subspace's one column)."""
    jac = pin.computeJointJacobian(model, data, pin.neutral(model), joint_id)
    col = model.joints[joint_id].idx_v
    world_axis = pin.Motion(jac[:, col])
    return data.oMi[joint_id].actInv(world_axis)


def _joint_inertias(model: pin.Model, jaw: JawJoints) -> np.ndarray:
    """Each jaw joint's inertia about its own motion: M[i, i] at the closed position [kg m^2
    or kg], the joint's armature included (CRBA adds it to M's diagonal: added again, a jaw
    with a motor's reflected inertia counted it twice); the water's added mass not included:
    a lower bound."""
    q = pin.neutral(model)
    q[jaw.q_index] = jaw.lower
    mass = pin.crba(model, model.createData(), q)
    return np.array([mass[i, i] for i in jaw.v_index])
