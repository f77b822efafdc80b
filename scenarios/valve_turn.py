"""The controller of scenarios/valve_turn.toml: a timed sequence of phases that brings the
arm's end (the Alpha 5's fixed jaw: the model's ball of ``tip_radius_m`` at ``tip_frame``)
onto the end of a quarter-turn valve's paddle and sweeps it through 90 degrees about the
valve's axis, the arm held in a fixed posture (pointing down) and the vehicle's thrusters
giving the push.

The tip's target lives in the valve's plane, in polar coordinates about the valve's axis
(``axis_world_m``, the axis along world x): at the paddle's angle phi and a height h above
its pushed face,

    p(phi, h) = axis + r t(phi) + h n(phi),    t(phi) = (0, cos phi, -sin phi)   (paddle),
                                               n(phi) = (0, sin phi,  cos phi)   (its face)

with r = ``radius_m`` out from the axis (the lever) and x = ``axis_world_m[0]``: turning the
valve by +phi moves that end of the paddle down, then towards -y. The tip touches the
face at h = ``half_thickness_m`` + ``tip_radius_m``. The phases, each a smooth move of (phi, h) in
``phase_durations_s``:

    approach  from where the tip is at t = 0 to (0, ``approach_height_m``) (a move in the world)
    descend   to (0, contact - ``press_m``)                     the tip on the paddle's face
    sweep     to (``sweep_to_rad``, contact - ``press_m``)      phi past pi/2: into the stop
    hold      at the end                                         against the stop
    retreat   to (``sweep_to_rad``, ``approach_height_m``)      off the paddle

The law (the push in the sweep and the hold only):

    e            = p_target - p_tip
    f_push       = K_p e - K_d v_tip - push_N n(phi_target)     clipped to |f_push| <= max_push_N
    f_world      = f_push + f_trim
    tau_vehicle  = [R^T f_world; -k_a log(R) - d_a omega]        (level attitude)
    tau_arm      = K_p,arm (q_arm,target - q_arm) - K_d,arm qdot_arm

with p_tip the ``tip_frame`` origin from the measured configuration by forward kinematics and
f_trim an integral of K_i e, taken while the tip is within 2 cm of its target and not
pushing (the vehicle's trim), then frozen: the push on the paddle is at most ``max_push_N``.
The arm's posture puts the push along the arm and through the arm's joints' axes (a few
centimetres of lever), so that the arm holds it within its joints' torques while the vehicle
heaves and sways. The valve's place is known (not perceived).

A scenario's own controller (``type = "valve_turn:ValveTurn"``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError
from uvms_pin.results.signal import Signal

#: the position error below which the trim's integral acts [m]
INTEGRATE_WITHIN_M = 0.02
PHASES = ("approach", "descend", "sweep", "hold", "retreat")
PUSHING = ("sweep", "hold")


def _smooth(x: float) -> float:
    s = min(max(x, 0.0), 1.0)
    return 3 * s**2 - 2 * s**3


class ValveTurn(Controller):
    def __init__(
        self,
        uvms,
        axis_world_m: list[float],
        phase_durations_s: list[float],
        arm_target_rad: list[float],
        kp_Nm_rad: list[float],
        kd_Nm_s_rad: list[float],
        radius_m: float = 0.08,
        half_thickness_m: float = 0.02,
        tip_radius_m: float = 0.017,
        approach_height_m: float = 0.05,
        press_m: float = 0.005,
        sweep_to_rad: float = 1.65,
        push_N: float = 35.0,
        max_push_N: float = 60.0,
        position_gains: list[float] = (300.0, 150.0, 100.0),
        integral_limit_N: float = 20.0,
        attitude_gains: list[float] = (40.0, 20.0),
        tip_frame: str = "alpha_jaw_link",
    ):
        finite_parameters("valve_turn", locals())  # inf or nan: refused now, by name
        self.model = uvms.model
        self.data = self.model.createData()
        if not self.model.existFrame(tip_frame):
            raise ParameterError(f"valve_turn: the model has no frame '{tip_frame}'")
        self.frame_id = self.model.getFrameId(tip_frame)
        self.axis = np.asarray(axis_world_m, dtype=float)
        self.durations = np.asarray(phase_durations_s, dtype=float)
        if self.axis.shape != (3,):
            raise ParameterError("valve_turn: axis_world_m must be [x, y, z]")
        if len(self.durations) != len(PHASES) or np.any(self.durations <= 0):
            raise ParameterError(
                f"valve_turn: phase_durations_s needs one positive duration per phase {PHASES}, "
                f"got {list(phase_durations_s)}"
            )
        if max_push_N < 0 or push_N < 0:
            raise ParameterError("valve_turn: push_N and max_push_N must be >= 0")
        self.starts = np.concatenate([[0.0], np.cumsum(self.durations)])
        self.radius_m = float(radius_m)
        self.half_thickness_m = float(half_thickness_m)
        self.tip_radius_m = float(tip_radius_m)
        self.approach_height_m = float(approach_height_m)
        self.press_m = float(press_m)
        self.sweep_to_rad = float(sweep_to_rad)
        self.push_N = float(push_N)
        self.max_push_N = float(max_push_N)
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
        self.phase = 0
        self.push_world_N = np.zeros(3)

    def point_world_m(self, angle_rad: float, height_m: float) -> np.ndarray:
        """p(phi, h) of the module docstring [m]."""
        c, s = np.cos(angle_rad), np.sin(angle_rad)
        return self.axis + self.radius_m * np.array([0.0, c, -s]) + height_m * np.array([0, s, c])

    def _waypoints(self) -> list[tuple[float, float]]:
        """(phi, h) at the end of each phase."""
        pressed = self.half_thickness_m + self.tip_radius_m - self.press_m
        return [
            (0.0, self.approach_height_m),
            (0.0, pressed),
            (self.sweep_to_rad, pressed),
            (self.sweep_to_rad, pressed),
            (self.sweep_to_rad, self.approach_height_m),
        ]

    def target(self, time_s: float, start_world_m: np.ndarray) -> tuple[np.ndarray, float, int]:
        """The tip's target [m], its angle phi [rad] and the phase's index at ``time_s``."""
        k = min(int(np.searchsorted(self.starts, time_s, side="right")) - 1, len(PHASES) - 1)
        s = _smooth((time_s - self.starts[k]) / self.durations[k])
        waypoints = self._waypoints()
        if k == 0:
            end = self.point_world_m(*waypoints[0])
            return start_world_m + s * (end - start_world_m), 0.0, k
        (a0, h0), (a1, h1) = waypoints[k - 1], waypoints[k]
        angle = a0 + s * (a1 - a0)
        return self.point_world_m(angle, h0 + s * (h1 - h0)), angle, k

    def _vehicle_force_world(self, time_s: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """f_world: the clipped push and the trim (module docstring)."""
        pin.forwardKinematics(self.model, self.data, q, v)
        pin.updateFramePlacement(self.model, self.data, self.frame_id)
        tip_world = self.data.oMf[self.frame_id].translation
        tip_velocity_world = pin.getFrameVelocity(
            self.model, self.data, self.frame_id, pin.LOCAL_WORLD_ALIGNED
        ).linear
        if self.start_world_m is None:
            self.start_world_m = tip_world.copy()
        target, angle, self.phase = self.target(time_s, self.start_world_m)
        error_m = target - tip_world
        step_s = 0.0 if self.last_time_s is None else time_s - self.last_time_s
        self.last_time_s = time_s
        pushing = PHASES[self.phase] in PUSHING
        push = self.kx * error_m - self.dx * tip_velocity_world
        if pushing:
            push = push - self.push_N * np.array([0.0, np.sin(angle), np.cos(angle)])
        elif np.linalg.norm(error_m) < INTEGRATE_WITHIN_M:  # the trim, not the push
            limit = self.integral_limit_N
            self.integral_N = np.clip(self.integral_N + self.ix * error_m * step_s, -limit, limit)
        norm = np.linalg.norm(push)
        if norm > self.max_push_N:
            push = push * (self.max_push_N / norm)
        self.push_world_N = push
        return push + self.integral_N

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        rotation = pin.Quaternion(q[3:7]).matrix()
        tau = np.zeros(self.nv)
        tau[:3] = rotation.T @ self._vehicle_force_world(time_s, q, v)
        tau[3:6] = -self.ka * pin.log3(rotation) - self.da * v[3:6]
        tau[6:] = self.kp * (self.arm_target - q[7:]) - self.kd * v[6:]
        return tau

    def signals(self) -> dict[str, np.ndarray | Signal]:
        return {
            "valve_turn": Signal(
                np.array([float(self.phase), *self.push_world_N]),
                ["phase", "push_x", "push_y", "push_z"],
                ["", "N", "N", "N"],
            )
        }
