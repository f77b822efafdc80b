"""The controller of scenarios/object_recovery.toml: a timed sequence of phases that moves the
jaw through waypoints above a sample and a basket, the arm held in a fixed posture, the
vehicle carrying the jaw, and the jaw closed and opened at given times.

Phases: each a smooth move of the jaw's target from where it is to the next of
``waypoints_world_m``, in ``phase_durations_s`` (the first from where the jaw is at t = 0):
approach above the sample, descend around it, hold while the jaw closes, lift, transfer
above the basket, lower into it, hold while the jaw opens, rise. The law:

    p_target(t)  = p_k + s((t - t_k) / T_k) (p_k+1 - p_k)     s: a smooth 0 -> 1 ramp,
                                                                p_0 the jaw's place at t = 0
    e            = p_target - p_jaw
    f_world      = K_p e - K_d v_jaw + K_i int e dt              (PID on the jaw point, world;
                                                                e integrated within 2 cm of
                                                                the target, clipped to f_max)
    tau_vehicle  = [R^T f_world; -k_a log(R) - d_a omega]        (level attitude)
    tau_arm      = K_p,arm (q_arm,target - q_arm) - K_d,arm qdot_arm

with p_jaw the origin of the jaw's base frame (``jaw_frame``), from the measured
configuration by forward kinematics: the vehicle puts the jaw where the waypoints say
whatever the arm sags by, and the integral takes up what the vehicle's trim and a carried
sample's net weight leave. The sample's and the basket's places are the waypoints (known,
not perceived).

The jaw (``[gripper] by_controller = true``, so that this controller is built on the whole
model): each finger follows the force-limited servo law of `uvms_pin.control.jaw_servo`
(grip ``grip_N`` at the finger's lever, the gains of `JawServo.for_model` for the control
period ``period_s``) toward a target that moves from open to closed at ``jaw_speed_rad_s``
from ``jaw_close_at_s`` (the fingers meet the sample slowly rather than at the full-force
servo's speed), and back to open at ``jaw_open_at_s``. Logged as the servo's are:
``jaw.<joint>_rad`` and ``jaw.<joint>_grip_N``.

A scenario's own controller (``type = "object_recovery:ObjectRecovery"``).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller
from uvms_pin.control.jaw_servo import JawSchedule, JawServo
from uvms_pin.errors import ParameterError
from uvms_pin.model.jaw import JawJoints, slice_if_consecutive
from uvms_pin.results.signal import Signal

#: the position error below which the integral acts [m]
INTEGRATE_WITHIN_M = 0.02


def _smooth(x: float) -> float:
    s = min(max(x, 0.0), 1.0)
    return 3 * s**2 - 2 * s**3


@dataclass(frozen=True)
class SlowJawServo(JawServo):
    """The jaw's servo with a target that closes at ``speed`` [rad/s or m/s] (the servo's law
    and gains unchanged)."""

    speed: float = 0.3

    def target(self, time_s: float) -> np.ndarray:
        if not self.schedule.closed(time_s):
            return self.jaw.upper
        travel = self.speed * (time_s - self.schedule.close_at_s)
        return np.maximum(self.jaw.lower, self.jaw.upper - travel)


class ObjectRecovery(Controller):
    def __init__(
        self,
        uvms,
        waypoints_world_m: list[list[float]],
        phase_durations_s: list[float],
        arm_target_rad: list[float],
        kp_Nm_rad: list[float],
        kd_Nm_s_rad: list[float],
        jaw_close_at_s: float,
        jaw_open_at_s: float,
        grip_N: float = 10.0,
        jaw_speed_rad_s: float = 0.3,
        period_s: float = 0.002,
        position_gains: list[float] = (300.0, 150.0, 100.0),
        integral_limit_N: float = 20.0,
        attitude_gains: list[float] = (40.0, 20.0),
        jaw_frame: str = "alpha_jaw_base_link",
    ):
        # inf or nan: refused now, by name (the jaw opening at inf: never)
        finite_parameters("object_recovery", locals(), never=("jaw_open_at_s",))
        self.model = uvms.model
        self.data = self.model.createData()
        if not self.model.existFrame(jaw_frame):
            raise ParameterError(f"object_recovery: the model has no frame '{jaw_frame}'")
        self.frame_id = self.model.getFrameId(jaw_frame)
        self.waypoints = np.asarray(waypoints_world_m, dtype=float)
        self.durations = np.asarray(phase_durations_s, dtype=float)
        if self.waypoints.ndim != 2 or self.waypoints.shape[1] != 3:
            raise ParameterError("object_recovery: waypoints_world_m must be a list of [x, y, z]")
        if len(self.durations) != len(self.waypoints) or np.any(self.durations <= 0):
            raise ParameterError(
                "object_recovery: phase_durations_s needs one positive duration per waypoint "
                f"({len(self.waypoints)}), got {list(phase_durations_s)}"
            )
        self.starts = np.concatenate([[0.0], np.cumsum(self.durations)])
        self._starts = self.starts.tolist()  # bisect's: np.searchsorted's index, cheaper
        self.jaw = JawJoints.of(self.model, None, uvms.source)
        if self.jaw.count == 0:
            raise ParameterError(
                "object_recovery: the controller drives the jaw, and its model has none: "
                "set [gripper] by_controller = true"
            )
        schedule = JawSchedule(jaw_close_at_s, jaw_open_at_s)
        servo = JawServo.for_model(self.model, self.jaw, grip_N, schedule, period_s)
        self.servo = SlowJawServo(**vars(servo), speed=float(jaw_speed_rad_s))
        self.arm_v = self.jaw.arm_v_index[6:]  # the arm joints: neither vehicle nor jaw
        self.arm_q = self.jaw.arm_q_index[7:]
        # the same entries as slices when consecutive: a tick reads views, not copies
        self._arm_v, self._arm_q = map(slice_if_consecutive, (self.arm_v, self.arm_q))
        self._jaw_v, self._jaw_q = map(slice_if_consecutive, (self.jaw.v_index, self.jaw.q_index))
        self._jaw_units = [
            "m" if self.model.joints[j].shortname().startswith("JointModelP") else "rad"
            for j in self.jaw.joint_ids
        ]
        self.arm_target = np.asarray(arm_target_rad, dtype=float)
        self.kp = np.asarray(kp_Nm_rad, dtype=float)
        self.kd = np.asarray(kd_Nm_s_rad, dtype=float)
        self.kx, self.dx, self.ix = (float(g) for g in position_gains)
        self.integral_limit_N = float(integral_limit_N)
        self.ka, self.da = (float(g) for g in attitude_gains)
        self.nv = self.model.nv
        self.reset()

    def reset(self) -> None:
        self.start_world_m: np.ndarray | None = None
        self.integral_N = np.zeros(3)
        self.last_time_s: float | None = None
        self.jaw_q = np.zeros(self.jaw.count)
        self.jaw_tau = np.zeros(self.jaw.count)

    def target_world_m(self, time_s: float, start_world_m: np.ndarray) -> np.ndarray:
        """The jaw's target at ``time_s``: the current move's smooth interpolation, the
        first from ``start_world_m``."""
        k = bisect.bisect_right(self._starts, time_s) - 1
        if k >= len(self.durations):
            return self.waypoints[-1].copy()
        before = start_world_m if k == 0 else self.waypoints[k - 1]
        s = _smooth((time_s - self._starts[k]) / self.durations[k])
        return before + s * (self.waypoints[k] - before)

    def _vehicle_force_world(self, time_s: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """f_world: the PID on the jaw point (module docstring)."""
        pin.forwardKinematics(self.model, self.data, q, v)
        pin.updateFramePlacement(self.model, self.data, self.frame_id)
        jaw_world = self.data.oMf[self.frame_id].translation
        jaw_velocity_world = pin.getFrameVelocity(
            self.model, self.data, self.frame_id, pin.LOCAL_WORLD_ALIGNED
        ).linear
        if self.start_world_m is None:
            self.start_world_m = jaw_world.copy()
        error_m = self.target_world_m(time_s, self.start_world_m) - jaw_world
        step_s = 0.0 if self.last_time_s is None else time_s - self.last_time_s
        self.last_time_s = time_s
        limit = self.integral_limit_N
        if math.sqrt(error_m @ error_m) < INTEGRATE_WITHIN_M:  # no wind-up on the long moves
            # minimum(maximum()) is np.clip without its per-call dispatch cost (the same bits)
            integral = np.maximum(self.integral_N + self.ix * error_m * step_s, -limit)
            self.integral_N = np.minimum(integral, limit)
        return self.kx * error_m - self.dx * jaw_velocity_world + self.integral_N

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        rotation = pin.Quaternion(q[3:7]).matrix()
        tau = np.zeros(self.nv)
        tau[:3] = rotation.T @ self._vehicle_force_world(time_s, q, v)
        tau[3:6] = -self.ka * pin.log3(rotation) - self.da * v[3:6]
        tau[self._arm_v] = self.kp * (self.arm_target - q[self._arm_q]) - self.kd * v[self._arm_v]
        self.jaw_q = q[self._jaw_q]  # frozen (a view of the measurement's) or a copy
        self.jaw_tau = self.servo.torque(time_s, self.jaw_q, v[self._jaw_v])
        tau[self._jaw_v] = self.jaw_tau
        return tau

    def signals(self) -> dict[str, np.ndarray | Signal]:
        return {"jaw": self.servo.signal(self.jaw_q, self.jaw_tau, self._jaw_units)}
