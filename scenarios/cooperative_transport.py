"""The controller of scenarios/cooperative_transport.toml: one UVMS of a team carrying a
commonly grasped object without exchanging data, after the decentralized leader-follower
scheme of Heshmati-alamdari, Bechlioulis, Karras and Kyriakopoulos (arXiv 1905.04531). Each
robot runs its own instance; ``role`` says which: the leader knows the object's desired
path, a follower estimates it from its own force/torque measurement alone.

Translational law (world axes; the object's and the robots' attitudes are held, not
steered). The robot holds the object at its grasp point p (the jaw frame's origin moved by
``grasp_offset_in_jaw_m`` in the jaw frame; from the measured configuration by forward
kinematics), w_o = (0, 0, -W) is the object's net weight [N] (weight minus buoyancy,
known), K [N/m] and D [N s/m] the object's impedance, c_i the robot's load-sharing
coefficient (sum_i c_i = 1):

    leader:    F_l = -c_l w_o - c_l [K (p - y_d) + D (p_dot - y_d_dot)]
               y_d(t) = x_d(t) + (p(0) - x_d(0))      x_d: the object's desired path
    follower:  F_f = -c_f w_o - c_f K (p + (D/K) p_dot - z_hat)

F_i is the force robot i exerts on the object at p. If the follower's estimate z_hat equals
its virtual target z = y_f + (D/K) y_f_dot (its grasp point's desired place, led by its
desired velocity), F_f = (c_f / c_l) (F_l + c_l w_o) - c_f w_o: every robot pushes its share
of what the object needs, and no internal force squeezes the object between them.

The follower's estimate (the prescribed-performance estimation law). The object's dynamics,
M_o a_o = F_l + F_f + w_o, and the leader's law give what the leader pushes from the
follower's own measurement F_f (its force/torque sensor, ``[sensors] held_object_wrench``,
low-pass filtered with the time constant ``force_filter_s``: the fingers' contacts ring at
the integrator's rate):

    z_meas = p + (D/K) p_dot - (F_f + c_f w_o - M_o a_o) / (c_l K)     (= z exactly)

with the inertial term M_o a_o dropped (a slow transport: it enters z_meas as an error of
M_o |a_o| / (c_l K), which the funnel's final width must hold). Per axis j:

    e_j    = z_hat_j - z_meas_j                         the estimation error [m]
    rho(t) = (rho_0 - rho_inf) exp(-lambda t) + rho_inf  its prescribed bound [m]
    xi_j   = e_j / rho(t)
    z_hat_j' = -k_e rho(t) ln((1 + xi_j) / (1 - xi_j))   [m/s]

integrated at the control period from z_hat(0) = p(0) + (D/K) p_dot(0) (the follower
starts believing the object is where it should be). While |xi_j| < 1 the error stays inside
its funnel |e_j| < rho(t); the largest |xi_j| so far is logged (``estimate``), and a
|xi_j| >= 1 (a funnel left) is recorded, not raised: xi is then held at 0.999 for the law.

Each robot realizes its force through its own dynamics, model-based: its generalized force
is tau = h(q, v) + J_p^T F_i + [attitude PD on the vehicle] + [PD holding the arm's
posture], with h the robot's own bias forces (restoring, damping, Coriolis, from its model
and measured state; `uvms_pin.physics.dynamics.bias_forces`) and J_p the grasp point's
translational Jacobian (world axes). The robots' inertia is not compensated (slow motion).
The jaw is the scenario's ``[gripper]`` servo, closed from t = 0 on the object.

Logged (``estimate``): the follower's z_hat (3) and z_meas (3) [m], its rho [m] and its
largest |xi| so far per axis; the leader logs its target y_d (3) [m] in the first three
and zeros. ``force`` (both): the commanded F_i (3) [N] and the measured force on the held
object (3) [N].

A scenario's own controller (``type = "cooperative_transport:CooperativeTransport"``): it
needs its scenario's geometry (the grasp point in the jaw, the object's net weight, the
path), hence beside the scenario rather than among the project's registered controllers.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError
from uvms_pin.hydro.vector import cross3
from uvms_pin.physics.dynamics import bias_forces
from uvms_pin.results.signal import Signal

#: the largest |xi| the law uses once a funnel is left (its logarithm stays finite)
XI_HELD = 0.999
ROLES = ("leader", "follower")


def smooth_path(
    time_s: float, start_s: float, waypoints: np.ndarray, durations: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(x_d, x_d_dot) at ``time_s`` [m, m/s]: held at waypoints[0] until ``start_s``, then
    a smoothstep move s(u) = 3u^2 - 2u^3 from each waypoint to the next in its duration."""
    starts = start_s + np.concatenate([[0.0], np.cumsum(durations)])
    k = int(np.searchsorted(starts, time_s, side="right")) - 1
    if k < 0:
        return waypoints[0].copy(), np.zeros(3)
    if k >= len(durations):
        return waypoints[-1].copy(), np.zeros(3)
    u = (time_s - starts[k]) / durations[k]
    step = waypoints[k + 1] - waypoints[k]
    return (
        waypoints[k] + (3 * u**2 - 2 * u**3) * step,
        (6 * u - 6 * u**2) / durations[k] * step,
    )


def funnel_m(time_s: float, rho_0: float, rho_inf: float, rate: float) -> float:
    """rho(t) = (rho_0 - rho_inf) exp(-rate t) + rho_inf [m]."""
    return (rho_0 - rho_inf) * np.exp(-rate * time_s) + rho_inf


def estimate_rate_m_s(
    error_m: np.ndarray, rho_m: float, gain: float
) -> tuple[np.ndarray, np.ndarray]:
    """(z_hat' [m/s], xi): the prescribed-performance estimation law of the module
    docstring, xi held at +-0.999 once a funnel is left."""
    xi = error_m / rho_m
    held = np.clip(xi, -XI_HELD, XI_HELD)
    return -gain * rho_m * np.log((1.0 + held) / (1.0 - held)), xi


class CooperativeTransport(Controller):
    def __init__(
        self,
        uvms,
        role: str,
        load_share: float,
        object_net_weight_N: float,
        stiffness_N_m: float = 200.0,
        damping_N_s_m: float = 150.0,
        leader_load_share: float = 0.5,
        waypoints_world_m: list[list[float]] | None = None,
        phase_durations_s: list[float] | None = None,
        path_start_s: float = 2.0,
        funnel_start_m: float = 0.05,
        funnel_end_m: float = 0.01,
        funnel_rate_per_s: float = 0.5,
        estimate_gain_per_s: float = 30.0,
        force_filter_s: float = 0.1,
        period_s: float = 0.002,
        grasp_offset_in_jaw_m: list[float] = (0.0, 0.0, 0.071),
        attitude_gains: list[float] = (40.0, 20.0),
        kp_Nm_rad: list[float] = (10.0, 40.0, 30.0, 0.5),
        kd_Nm_s_rad: list[float] = (0.8, 1.5, 1.0, 0.02),
        jaw_frame: str = "alpha_jaw_base_link",
    ):
        finite_parameters("cooperative_transport", locals())  # inf or nan: refused now, by name
        if role not in ROLES:
            raise ParameterError(
                f"cooperative_transport: role must be one of {ROLES}, got {role!r}"
            )
        if not (0.0 < load_share <= 1.0 and 0.0 < leader_load_share <= 1.0):
            raise ParameterError("cooperative_transport: load shares must be in (0, 1]")
        self.uvms = uvms
        self.model = uvms.model
        self.data = self.model.createData()
        if not self.model.existFrame(jaw_frame):
            raise ParameterError(f"cooperative_transport: the model has no frame '{jaw_frame}'")
        self.frame_id = self.model.getFrameId(jaw_frame)
        self.role = role
        self.share = float(load_share)
        self.leader_share = float(leader_load_share)
        self.weight_world_N = np.array([0.0, 0.0, -float(object_net_weight_N)])
        self.k, self.d = float(stiffness_N_m), float(damping_N_s_m)
        if role == "leader":
            if waypoints_world_m is None or phase_durations_s is None:
                raise ParameterError(
                    "cooperative_transport: the leader needs waypoints_world_m and "
                    "phase_durations_s (the object's desired path)"
                )
            self.waypoints = np.asarray(waypoints_world_m, dtype=float)
            self.durations = np.asarray(phase_durations_s, dtype=float)
            if self.waypoints.ndim != 2 or self.waypoints.shape[1] != 3:
                raise ParameterError("cooperative_transport: waypoints_world_m: [[x, y, z], ...]")
            if len(self.durations) != len(self.waypoints) - 1 or np.any(self.durations <= 0):
                raise ParameterError(
                    "cooperative_transport: one positive phase duration per move "
                    f"({len(self.waypoints) - 1}), got {list(phase_durations_s)}"
                )
        self.path_start_s = float(path_start_s)
        self.funnel = (float(funnel_start_m), float(funnel_end_m), float(funnel_rate_per_s))
        if not 0.0 < self.funnel[1] <= self.funnel[0]:
            raise ParameterError("cooperative_transport: 0 < funnel_end_m <= funnel_start_m")
        self.gain = float(estimate_gain_per_s)
        self.filter_s = float(force_filter_s)
        self.period_s = float(period_s)
        self.offset = np.asarray(grasp_offset_in_jaw_m, dtype=float)
        self.ka, self.da = (float(g) for g in attitude_gains)
        self.kp = np.asarray(kp_Nm_rad, dtype=float)
        self.kd = np.asarray(kd_Nm_s_rad, dtype=float)
        self.nv = self.model.nv
        self.reset()

    def reset(self) -> None:
        self.start: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # p, R, arm
        self.z_hat = np.zeros(3)
        self.z_meas = np.zeros(3)
        self.rho_m = self.funnel[0]
        self.xi_max = np.zeros(3)
        self.force_N = np.zeros(3)
        self.measured_N = np.zeros(3)
        self.target = np.zeros(3)

    def grasp_point(
        self, q: np.ndarray, v: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(p [m], p_dot [m/s], J_p (3, nv)) of the grasp point, world axes."""
        model, data, frame = self.model, self.data, self.frame_id
        pin.computeJointJacobians(model, data, q)
        pin.forwardKinematics(model, data, q, v)
        placement = pin.updateFramePlacement(model, data, frame)
        arm = placement.rotation @ self.offset
        twist = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
        jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
        point_jacobian = jacobian[:3] - pin.skew(arm) @ jacobian[3:]
        return (
            placement.translation + arm,
            twist.linear + cross3(twist.angular, arm),  # np.cross costs ~10 us a call
            point_jacobian,
        )

    def _leader_force(self, time_s: float, p: np.ndarray, p_dot: np.ndarray) -> np.ndarray:
        x_d, x_d_dot = smooth_path(time_s, self.path_start_s, self.waypoints, self.durations)
        self.target = x_d + (self.start[0] - self.waypoints[0])
        impedance = self.k * (p - self.target) + self.d * (p_dot - x_d_dot)
        return -self.share * (self.weight_world_N + impedance)

    def _follower_force(self, time_s: float, p: np.ndarray, p_dot: np.ndarray, measured):
        lead = p + (self.d / self.k) * p_dot
        pushed = measured + self.share * self.weight_world_N
        self.z_meas = lead - pushed / (self.leader_share * self.k)
        if time_s == 0.0:
            self.z_hat = lead.copy()
        self.rho_m = funnel_m(time_s, *self.funnel)
        rate, xi = estimate_rate_m_s(self.z_hat - self.z_meas, self.rho_m, self.gain)
        self.xi_max = np.maximum(self.xi_max, np.abs(xi))
        force = -self.share * (self.weight_world_N + self.k * (lead - self.z_hat))
        self.z_hat = self.z_hat + self.period_s * rate  # held until the next tick
        return force

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        p, p_dot, jacobian = self.grasp_point(q, v)
        rotation = pin.Quaternion(q[3:7]).matrix()
        if self.start is None:
            self.start = (p.copy(), rotation.copy(), q[7:].copy())
        raw = np.asarray(measurement.force_world_N, dtype=float)
        blend = self.period_s / (self.filter_s + self.period_s)
        self.measured_N = (
            raw.copy() if time_s == 0.0 else self.measured_N + blend * (raw - self.measured_N)
        )
        if self.role == "leader":
            self.force_N = self._leader_force(time_s, p, p_dot)
        else:
            self.force_N = self._follower_force(time_s, p, p_dot, self.measured_N)
        tau = bias_forces(self.uvms, q, v) + jacobian.T @ self.force_N
        attitude = pin.log3(self.start[1].T @ rotation)
        tau[3:6] += -self.ka * attitude - self.da * v[3:6]
        tau[6:] += self.kp * (self.start[2] - q[7:]) - self.kd * v[6:]
        return tau

    def signals(self) -> dict[str, np.ndarray | Signal]:
        if self.role == "leader":
            estimate = np.concatenate([self.target, np.zeros(7)])
        else:
            estimate = np.concatenate([self.z_hat, self.z_meas, [self.rho_m], self.xi_max])
        axes = ("x", "y", "z")
        return {
            "estimate": Signal(
                estimate,
                [
                    *(f"z_hat_{a}" for a in axes),
                    *(f"z_meas_{a}" for a in axes),
                    "rho",
                    *(f"xi_max_{a}" for a in axes),
                ],
                ["m"] * 7 + ["1"] * 3,
            ),
            "force": Signal(
                np.concatenate([self.force_N, self.measured_N]),
                [*(f"commanded_{a}" for a in axes), *(f"measured_{a}" for a in axes)],
                ["N"] * 6,
            ),
        }
