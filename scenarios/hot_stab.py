"""The controller of scenarios/hot_stab.toml: a small state machine that carries a stab held
in the jaw to a receptacle's mouth, aligns the stab's axis with the bore and pushes it in to
full depth, the arm held in a posture and the vehicle's thrusters giving the push.

The stab is held across the jaw (its axis along the jaw base frame's -x, ``jaw_frame``, its
centre ``grasp_in_jaw_m`` out from the jaw's base); its tip, ``stab_length_m`` / 2 ahead of
the centre, is the point the controller steers:

    p_tip = p_jaw + R_jaw (grasp_in_jaw_m + (-L/2, 0, 0)),   a_stab = R_jaw (-1, 0, 0)

from the measured configuration by forward kinematics. The bore is known (not perceived):
its mouth ``mouth_world_m`` and its axis ``axis_world`` (unit, into the bore); ``aim_error_m``
is added to the mouth where the controller aims (a stand-in for a perception error: the
receptacle's chamfer has to take it). The phases, each a smooth move of the tip's target in
``phase_durations_s``:

    approach  from where the tip is at t = 0 to ``standoff_m`` before the (aimed) mouth
    align     held there while the arm's wrist pitch turns a_stab onto the bore's axis
    insert    along the axis to ``depth_m`` + ``overtravel_m`` past the mouth
    hold      there, pressing the stab's tip on the bore's bottom

Alignment: the arm's target posture is ``arm_target_rad`` with its pitch joint
(``pitch_joint``, an index into the arm's joints) moved by the angle between a_stab and the
bore's axis in the vertical plane, found once from the model at a level vehicle (Newton on
the arm's forward kinematics); the align phase ramps the posture to it.

The law:

    e            = p_target - p_tip
    f_servo      = K_p e - K_d v_tip                                (world)
    f_push       = clip(a . (f_servo + f_trim), -max_push_N, max_push_N)
    f_world      = f_push a + (I - a a^T)(lateral_gain f_servo + f_trim)   (insert, hold)
                   f_servo + f_trim                                         (otherwise)
    tau_vehicle  = [R^T f_world; -k_a log(R) - d_a omega]          (level attitude)
    tau_arm      = K_p,arm (q_arm,target - q_arm) - K_d,arm qdot_arm

with f_trim an integral of K_i e taken while the tip is within 2 cm of its target before
the insertion and then frozen (the vehicle's trim): the push along the bore is at most
``max_push_N`` (the push budget), and the lateral servo ``lateral_gain`` times the
approach's (the trim kept whole), so that the chamfer, not the thrusters, centres the stab. The jaw is the scenario's
``[gripper]`` servo (this controller is built on the model with the jaw locked).

A scenario's own controller (``type = "hot_stab:HotStab"``).
"""

from __future__ import annotations

import bisect
import math

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError
from uvms_pin.results.signal import Signal

#: the position error below which the trim's integral acts [m]
INTEGRATE_WITHIN_M = 0.02
PHASES = ("approach", "align", "insert", "hold")
PUSHING = ("insert", "hold")


def _smooth(x: float) -> float:
    s = min(max(x, 0.0), 1.0)
    return 3 * s**2 - 2 * s**3


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of two 3-vectors, numpy's formula (np.cross's bits) without its per-call
    axis handling (some 40 us a tick)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


class HotStab(Controller):
    def __init__(
        self,
        uvms,
        mouth_world_m: list[float],
        phase_durations_s: list[float],
        arm_target_rad: list[float],
        kp_Nm_rad: list[float],
        kd_Nm_s_rad: list[float],
        axis_world: list[float] = (1.0, 0.0, 0.0),
        grasp_in_jaw_m: list[float] = (0.0, 0.0, 0.07),
        stab_length_m: float = 0.38,
        depth_m: float = 0.15,
        standoff_m: float = 0.05,
        overtravel_m: float = 0.01,
        aim_error_m: list[float] = (0.0, 0.0, 0.0),
        max_push_N: float = 20.0,
        lateral_gain: float = 0.3,
        pitch_joint: int = 2,
        position_gains: list[float] = (300.0, 150.0, 100.0),
        integral_limit_N: float = 20.0,
        attitude_gains: list[float] = (40.0, 20.0),
        jaw_frame: str = "alpha_jaw_base_link",
    ):
        finite_parameters("hot_stab", locals())  # inf or nan: refused now, by name
        self.model = uvms.model
        self.data = self.model.createData()
        if not self.model.existFrame(jaw_frame):
            raise ParameterError(f"hot_stab: the model has no frame '{jaw_frame}'")
        self.frame_id = self.model.getFrameId(jaw_frame)
        self.durations = np.asarray(phase_durations_s, dtype=float)
        if len(self.durations) != len(PHASES) or np.any(self.durations <= 0):
            raise ParameterError(
                f"hot_stab: phase_durations_s needs one positive duration per phase {PHASES}, "
                f"got {list(phase_durations_s)}"
            )
        if max_push_N <= 0:
            raise ParameterError(f"hot_stab: max_push_N must be > 0, got {max_push_N}")
        self.starts = np.concatenate([[0.0], np.cumsum(self.durations)])
        self._starts = self.starts.tolist()  # bisect's: np.searchsorted's index, cheaper
        axis = np.asarray(axis_world, dtype=float)
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or not np.linalg.norm(axis) > 0:
            raise ParameterError(
                f"hot_stab: axis_world must be a direction [x, y, z] (finite, not zero), got "
                f"{axis_world!r}"
            )
        self.axis = axis / np.linalg.norm(axis)
        aimed = np.asarray(mouth_world_m, dtype=float) + np.asarray(aim_error_m, dtype=float)
        self.standoff_world_m = aimed - standoff_m * self.axis
        self.inserted_world_m = aimed + (depth_m + overtravel_m) * self.axis
        self.tip_in_jaw_m = np.asarray(grasp_in_jaw_m, dtype=float) - [stab_length_m / 2, 0, 0]
        self.max_push_N = float(max_push_N)
        self.lateral_gain = float(lateral_gain)
        nv_arm = self.model.nv - 6
        self.arm_target = np.asarray(arm_target_rad, dtype=float)
        if len(self.arm_target) != nv_arm or not 0 <= pitch_joint < nv_arm:
            raise ParameterError(
                f"hot_stab: arm_target_rad needs {nv_arm} angles and pitch_joint an index "
                f"below {nv_arm}"
            )
        self.aligned_arm = self.arm_target.copy()
        self.aligned_arm[pitch_joint] += self._pitch_correction_rad(pitch_joint)
        self.kp = np.asarray(kp_Nm_rad, dtype=float)
        self.kd = np.asarray(kd_Nm_s_rad, dtype=float)
        self.kx, self.dx, self.ix = (float(g) for g in position_gains)
        self.integral_limit_N = float(integral_limit_N)
        self.ka, self.da = (float(g) for g in attitude_gains)
        self.reset()

    def _stab_axis(self, q: np.ndarray) -> np.ndarray:
        pin.framesForwardKinematics(self.model, self.data, q)
        return -self.data.oMf[self.frame_id].rotation[:, 0]

    def _pitch_correction_rad(self, joint: int) -> float:
        """The change of the arm's ``joint`` that puts a_stab on the bore's axis in the
        vertical plane, the vehicle level (Newton, a numerical derivative)."""
        q = pin.neutral(self.model)
        q[7:] = self.arm_target

        def pitch_error(delta: float) -> float:
            q_try = q.copy()
            q_try[7 + joint] += delta
            a = self._stab_axis(q_try)
            return float(np.arcsin(np.clip(a[2], -1, 1)) - np.arcsin(self.axis[2]))

        delta = 0.0
        for _ in range(8):
            error = pitch_error(delta)
            slope = (pitch_error(delta + 1e-6) - error) / 1e-6
            if abs(slope) < 1e-9:
                raise ParameterError("hot_stab: pitch_joint does not pitch the stab")
            delta -= error / slope
        return delta

    def reset(self) -> None:
        self.start_world_m: np.ndarray | None = None
        self.trim_N = np.zeros(3)
        self.last_time_s: float | None = None
        self.phase = 0
        self.tip_world_m = np.zeros(3)
        self.push_N = 0.0

    def _phase(self, time_s: float) -> tuple[int, float]:
        k = bisect.bisect_right(self._starts, time_s) - 1
        k = min(max(k, 0), len(PHASES) - 1)
        return k, _smooth((time_s - self._starts[k]) / self.durations[k])

    def target_world_m(self, time_s: float, start_world_m: np.ndarray) -> np.ndarray:
        """The tip's target at ``time_s`` (the module docstring's phases)."""
        return self._target_in_phase(*self._phase(time_s), start_world_m)

    def _target_in_phase(self, k: int, s: float, start_world_m: np.ndarray) -> np.ndarray:
        """The tip's target ``s`` (0 -> 1) through phase ``k``."""
        if PHASES[k] == "approach":
            return start_world_m + s * (self.standoff_world_m - start_world_m)
        if PHASES[k] == "align":
            return self.standoff_world_m.copy()
        if PHASES[k] == "insert":
            return self.standoff_world_m + s * (self.inserted_world_m - self.standoff_world_m)
        return self.inserted_world_m.copy()

    def arm_target_now(self, time_s: float) -> np.ndarray:
        return self._arm_target_in_phase(*self._phase(time_s))

    def _arm_target_in_phase(self, k: int, s: float) -> np.ndarray:
        if PHASES[k] == "approach":
            return self.arm_target
        if PHASES[k] == "align":
            return self.arm_target + s * (self.aligned_arm - self.arm_target)
        return self.aligned_arm

    def _vehicle_force_world(
        self, time_s: float, phase: tuple[int, float], q: np.ndarray, v: np.ndarray
    ) -> np.ndarray:
        """f_world (module docstring) in ``phase`` (`_phase` at ``time_s``)."""
        pin.forwardKinematics(self.model, self.data, q, v)
        jaw = pin.updateFramePlacement(self.model, self.data, self.frame_id)  # oMf[frame_id]
        velocity = pin.getFrameVelocity(
            self.model, self.data, self.frame_id, pin.LOCAL_WORLD_ALIGNED
        )
        lever_world = jaw.rotation @ self.tip_in_jaw_m
        self.tip_world_m = jaw.translation + lever_world
        tip_velocity = velocity.linear + _cross(velocity.angular, lever_world)
        if self.start_world_m is None:
            self.start_world_m = self.tip_world_m.copy()
        error_m = self._target_in_phase(*phase, self.start_world_m) - self.tip_world_m
        step_s = 0.0 if self.last_time_s is None else time_s - self.last_time_s
        self.last_time_s = time_s
        self.phase = phase[0]
        pushing = PHASES[self.phase] in PUSHING
        if not pushing and math.sqrt(error_m @ error_m) < INTEGRATE_WITHIN_M:
            limit = self.integral_limit_N
            # minimum(maximum()) is np.clip without its per-call dispatch cost (the same bits)
            trim = np.maximum(self.trim_N + self.ix * error_m * step_s, -limit)
            self.trim_N = np.minimum(trim, limit)
        servo = self.kx * error_m - self.dx * tip_velocity
        if not pushing:
            self.push_N = 0.0
            return servo + self.trim_N
        force = servo + self.trim_N
        # a float's min(max()): np.clip's value without its dispatch (a tenth of the time)
        self.push_N = min(max(float(self.axis @ force), -self.max_push_N), self.max_push_N)
        lateral = servo - (self.axis @ servo) * self.axis
        trim = self.trim_N - (self.axis @ self.trim_N) * self.axis
        return self.push_N * self.axis + self.lateral_gain * lateral + trim

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        phase = self._phase(time_s)  # once a tick: the tip's and the arm's targets
        rotation = pin.Quaternion(q[3:7]).matrix()
        tau = np.zeros(self.model.nv)
        tau[:3] = rotation.T @ self._vehicle_force_world(time_s, phase, q, v)
        tau[3:6] = -self.ka * pin.log3(rotation) - self.da * v[3:6]
        tau[6:] = self.kp * (self._arm_target_in_phase(*phase) - q[7:]) - self.kd * v[6:]
        return tau

    def signals(self) -> dict[str, np.ndarray | Signal]:
        return {
            "hot_stab": Signal(
                np.array([float(self.phase), self.push_N, *self.tip_world_m]),
                ["phase", "push", "tip_x", "tip_y", "tip_z"],
                ["", "N", "m", "m", "m"],
            )
        }
