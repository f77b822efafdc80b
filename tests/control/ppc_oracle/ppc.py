"""The paper's model-free prescribed-performance force/orientation controller (Section 4).

Heshmati-alamdari, Nikou, Kyriakopoulos, Dimarogonas, "A Robust Force Control Approach for
Underwater Vehicle Manipulator Systems" (IFAC 2017). Two levels (docs/controller.md):

First level (task space, 6 components j = f_x, f_y, f_z, roll, pitch, yaw):

    e_x      = [f_meas - f_d(t) (3) N;  rpy_ee(q) - rpy_d(t) (3) rad]
    xi_x     = e_x / rho_x(t)                      (must stay in (-1, 1))
    eps_x    = ln((1 + xi_x) / (1 - xi_x))
    xdot_r   = -k_x eps_x                          ([m/s (3); rad/s Euler rates (3)])
    zeta_r   = J(q)^+ xdot_r  [+ (I - J^+ J) zeta_0]

with J = J'^-1 J^g the analytical Jacobian of the end-effector
(:func:`uvms_pin.physics.kinematics.analytical_jacobian`).

Second level (generalized velocity, n = nv components):

    e_zeta   = zeta_meas - zeta_r
    xi_zeta  = P_zeta(t)^-1 e_zeta,   P_zeta = diag(rho_zeta_j(t))
    tau      = -K_zeta P_zeta^-1 R(xi_zeta) eps_zeta,   R = diag(2 / (1 - xi_zeta_j^2))

The controller is model-free: it uses only frame placements and frame Jacobians of the
model (kinematics), never its inertias, gravity or hydrodynamics, nor the environment.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from ppc_oracle.kinematics import analytical_jacobian, end_effector_pose, frame_id_from_name
from ppc_oracle.performance import (
    PerformanceFunction,
    barrier_extended,
    check_funnel,
    normalized_error,
    transformation_gain,
    transformed_error,
    transformed_error_extended,
)
from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError

#: Names of the first-level (task-space) error components.
FIRST_LEVEL_NAMES: tuple[str, ...] = ("f_x", "f_y", "f_z", "roll", "pitch", "yaw")
#: Names of the vehicle's six generalized-velocity components (SNAME: surge, sway, heave,
#: roll rate, pitch rate, yaw rate), all in the vehicle body frame.
VEHICLE_VELOCITY_NAMES: tuple[str, ...] = ("u", "v", "w", "p", "q", "r")

_N_VEHICLE = 6
#: With the funnel extension on (continuous-time simulation), the barrier is continued
#: linearly beyond |xi| = this (where eps ~ 14.5, r ~ 1e6): it keeps growing outside.
_XI_CLAMP = 1.0 - 1e-6
#: Joint position limits at or beyond this magnitude are treated as absent (Pinocchio marks
#: "no limit" with +-max double).
_NO_LIMIT_THRESHOLD = 1e10


@dataclass(frozen=True, eq=False)
class PPCParams:
    """Gains and funnels of :class:`PrescribedPerformanceController`.

    Every array field accepts a scalar (broadcast to all components) or one value per
    component: 6 for the first level (``_x``: f_x, f_y, f_z [N]; roll, pitch, yaw [rad]),
    nv = 6 + n_joints for the second level (``_zeta``: u, v, w [m/s]; p, q, r [rad/s];
    joint rates [rad/s]). :meth:`for_uvms` returns fully sized arrays; :meth:`sized`
    validates and sizes any instance.

    Defaults are the paper's simulation values (Section 5) with the docs/controller.md
    errata fixed:

    - ``k_x = 0.2`` and ``k_zeta = 5``: the paper prints k_x = -0.2 and k_v = -5, but its
      law (eq. 13, 18) already carries the minus sign and requires k > 0; negative gains
      would push every error out of its funnel.
    - The paper's rho_v / rho_zeta and P(t) / P_zeta(t) are the same thing: here ``_zeta``.
    - ``l_x = 3`` for all six: the paper gives l_x only for j = 1..3 (forces); we use 3 for
      the orientation components too.
    - ``rho_inf_zeta``: 0.2 for the 6 vehicle components and 0.4 for the arm joints (the
      paper's second "j in {1..6}" line is the vehicle). ``None`` means this split.

    Attributes:
        k_x: first-level gains k_x [m/s or rad/s per unit of eps], > 0, (6,).
        k_zeta: diagonal of K_zeta [N, N m per unit of eps rho^-1], > 0, (nv,).
        rho0_x, rho_inf_x: first-level funnel bounds [N (3); rad (3)].
        l_x_per_s: first-level decay rates [1/s].
        rho0_zeta, rho_inf_zeta: second-level funnel bounds [m/s (3); rad/s (3 + n)].
        l_zeta_per_s: second-level decay rates [1/s].
        desired_rpy: constant desired end-effector Euler angles (roll, pitch, yaw) [rad],
            used when the controller is given no ``desired_rpy``.
        null_space_gain_per_s: gain k_0 >= 0 [rad/s] of the optional secondary task
            (joint-limit avoidance in the null space of J). 0 (default) = the paper's plain
            pseudo-inverse, eq. (9).
        pinv_relative_cutoff: singular values of J below this fraction of the largest are
            treated as zero in J^+ (numerical rank only, no damping).
        null_space_target: arm joint positions (n_joints,) [rad] the secondary task pulls
            toward (e.g. a pose with reach in the task direction); None = mid-range.
        velocity_weights: positive weights W (nv,) of the generalized pseudo-inverse of the
            paper's remark, J^# = W^-1 J^T (J W^-1 J^T)^+, which minimises zeta^T W zeta:
            a large weight keeps that DoF out of the task (e.g. an unactuated vehicle roll).
            1 (default) = the Moore-Penrose pseudo-inverse of eq. (9).
    """

    k_x: ArrayLike = 0.2
    k_zeta: ArrayLike = 5.0
    rho0_x: ArrayLike = (1.0, 1.0, 1.0, 0.9, 0.9, 0.9)
    rho_inf_x: ArrayLike = 0.2
    l_x_per_s: ArrayLike = 3.0
    rho0_zeta: ArrayLike = 1.0
    rho_inf_zeta: ArrayLike | None = None
    l_zeta_per_s: ArrayLike = 2.2
    desired_rpy: ArrayLike = (0.0, 0.0, 0.0)
    null_space_gain_per_s: float = 0.0
    pinv_relative_cutoff: float = 1e-12
    velocity_weights: ArrayLike = 1.0
    null_space_target: ArrayLike | None = None

    @classmethod
    def for_uvms(cls, n_joints: int, **overrides) -> PPCParams:
        """The paper's parameters sized for a vehicle with ``n_joints`` arm DoFs.

        ``overrides`` replace fields before sizing (e.g. ``k_zeta=2.0``).
        """
        if int(n_joints) != n_joints or n_joints < 0:
            raise ParameterError(f"n_joints must be a non-negative integer, got {n_joints}")
        return cls(**overrides).sized(_N_VEHICLE + int(n_joints))

    def sized(self, nv: int) -> PPCParams:
        """A copy whose array fields have 6 (first level) or ``nv`` (second level) entries.

        Raises:
            ParameterError: a field has the wrong size or a non-finite value, a gain is
                not > 0, or ``null_space_gain_per_s`` / ``pinv_relative_cutoff`` < 0.
        """
        nv = int(nv)
        if nv < _N_VEHICLE:
            raise ParameterError(f"nv = {nv}: a UVMS has at least the 6 vehicle velocities")
        rho_inf_zeta = self.rho_inf_zeta
        if rho_inf_zeta is None:
            rho_inf_zeta = np.r_[np.full(_N_VEHICLE, 0.2), np.full(nv - _N_VEHICLE, 0.4)]
        sized = {
            "k_x": _vector("k_x", self.k_x, 6),
            "rho0_x": _vector("rho0_x", self.rho0_x, 6),
            "rho_inf_x": _vector("rho_inf_x", self.rho_inf_x, 6),
            "l_x_per_s": _vector("l_x_per_s", self.l_x_per_s, 6),
            "desired_rpy": _vector("desired_rpy", self.desired_rpy, 3),
            "k_zeta": _vector("k_zeta", self.k_zeta, nv),
            "rho0_zeta": _vector("rho0_zeta", self.rho0_zeta, nv),
            "rho_inf_zeta": _vector("rho_inf_zeta", rho_inf_zeta, nv),
            "l_zeta_per_s": _vector("l_zeta_per_s", self.l_zeta_per_s, nv),
            "velocity_weights": _vector("velocity_weights", self.velocity_weights, nv),
        }
        if self.null_space_target is not None:
            sized["null_space_target"] = _vector(
                "null_space_target", self.null_space_target, nv - _N_VEHICLE
            )
        for name in ("k_x", "k_zeta", "velocity_weights"):
            bad = np.flatnonzero(~(sized[name] > 0.0))
            if bad.size:
                raise ParameterError(
                    f"{name} must be > 0 (the law already has the minus sign; the paper's "
                    f"printed negative gains are an erratum), got {sized[name][bad]} at "
                    f"indices {bad.tolist()}"
                )
        for name in ("null_space_gain_per_s", "pinv_relative_cutoff"):
            value = float(getattr(self, name))
            if not (np.isfinite(value) and value >= 0.0):
                raise ParameterError(f"{name} must be finite and >= 0, got {value}")
        return dataclasses.replace(self, **sized)


def _vector(name: str, value: ArrayLike, size: int) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        array = np.full(size, float(array))
    if array.shape != (size,):
        raise ParameterError(f"{name} must be a scalar or have {size} entries, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"{name} has non-finite entries: {array}")
    array = array.copy()
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class PPCSignals:
    """Internal signals of one :meth:`PrescribedPerformanceController.compute` call.

    First level (6,): ``e_x`` [N (3); rad (3)], ``rho_x`` (same units), ``xi_x``, ``eps_x``,
    ``xdot_r`` [m/s (3); rad/s (3)]. Second level (nv,): ``zeta_r`` and ``e_zeta``
    [m/s, rad/s], ``rho_zeta``, ``xi_zeta``, ``eps_zeta``, ``tau`` [N, N m].
    """

    time_s: float
    force_desired_world_N: np.ndarray
    rpy_desired: np.ndarray
    rpy_ee: np.ndarray
    e_x: np.ndarray
    rho_x: np.ndarray
    xi_x: np.ndarray
    eps_x: np.ndarray
    xdot_r: np.ndarray
    zeta_r: np.ndarray
    e_zeta: np.ndarray
    rho_zeta: np.ndarray
    xi_zeta: np.ndarray
    eps_zeta: np.ndarray
    tau: np.ndarray


def _as_function(value, name: str, size: int) -> Callable[[float], np.ndarray]:
    """Wrap a constant into a function of time; check a callable's output when called."""
    if callable(value):

        def evaluate(time_s: float) -> np.ndarray:
            out = np.asarray(value(time_s), dtype=float)
            if out.shape != (size,) or not np.all(np.isfinite(out)):
                raise ParameterError(
                    f"{name}({time_s}) must return {size} finite values, got {out!r}"
                )
            return out

        return evaluate
    constant = _vector(name, value, size)
    return lambda time_s: constant


def pseudo_inverse(
    matrix: np.ndarray, relative_cutoff: float, weights: np.ndarray | None = None
) -> np.ndarray:
    """Moore-Penrose pseudo-inverse through the SVD, or its weighted form.

    Singular values ``s_i <= relative_cutoff * s_max`` are treated as zero (numerical
    rank); the others are inverted exactly (no damping), as in the paper's eq. (9).
    With ``weights`` w (columns), J^# = W^-1/2 (J W^-1/2)^+, i.e. the minimum of
    x^T W x among the least-squares solutions of J x = b.
    """
    if weights is not None:
        scale = 1.0 / np.sqrt(weights)
        return scale[:, None] * pseudo_inverse(matrix * scale[None, :], relative_cutoff)
    u, s, vt = np.linalg.svd(matrix, full_matrices=False)
    if s.size == 0 or s[0] == 0.0:
        return np.zeros(matrix.shape[::-1])
    keep = s > relative_cutoff * s[0]
    s_inv = np.zeros_like(s)
    s_inv[keep] = 1.0 / s[keep]
    return (vt.T * s_inv) @ u.T


class PrescribedPerformanceController(Controller):
    """The paper's two-level prescribed-performance force/orientation controller.

    Args:
        model: the UVMS kinematic model: Pinocchio model whose joint 1 is the vehicle's
            free-flyer root; any number nv - 6 of arm DoFs. Only frame placements and
            Jacobians are used (a private copy is kept).
        ee_frame_name: name of the end-effector frame whose Euler angles are controlled.
        params: gains and funnels; scalars broadcast. Default: the paper's values.
        desired_force_world_N: f_d(t), the force [N] the end-effector should exert on the
            environment in world axes: a function of time [s] returning (3,), or a
            constant. Default zero.
        desired_rpy: desired end-effector Euler angles (roll, pitch, yaw) [rad], a
            function of time or a constant. Default ``params.desired_rpy``.

    The measured force is ``measurement.wrench_world[:3]`` (sensor noise included, the
    paper's f_e + Delta f_e).

    Attributes:
        performance_x: first-level funnels rho_x(t) (6 components).
        performance_zeta: second-level funnels rho_zeta(t) (nv components).
        first_level_names, second_level_names: component names used in errors and logs.
        last_signals: :class:`PPCSignals` of the last successful ``compute`` (None before).

    Raises:
        ParameterError: unknown frame (the message lists the frames), root joint not a
            free-flyer, or invalid parameters.
    """

    def __init__(
        self,
        model: pin.Model,
        ee_frame_name: str,
        params: PPCParams | None = None,
        desired_force_world_N: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0),
        desired_rpy: Callable[[float], ArrayLike] | ArrayLike | None = None,
    ):
        if model.njoints < 2 or model.joints[1].shortname() != "JointModelFreeFlyer":
            raise ParameterError(
                "the UVMS model must have a free-flyer root joint (joint 1); build it with "
                "pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())"
            )
        self.model = pin.Model(model)  # private copy: later edits of `model` do not leak in
        self.data = self.model.createData()
        self.ee_frame_name = ee_frame_name
        self.ee_frame_id = frame_id_from_name(self.model, ee_frame_name)
        self.params = (params if params is not None else PPCParams()).sized(self.model.nv)
        self._desired_force = _as_function(desired_force_world_N, "desired_force_world_N", 3)
        self._desired_rpy = _as_function(
            self.params.desired_rpy if desired_rpy is None else desired_rpy, "desired_rpy", 3
        )

        self.first_level_names = FIRST_LEVEL_NAMES
        self.second_level_names = VEHICLE_VELOCITY_NAMES + tuple(self._arm_velocity_names())
        self.performance_x = PerformanceFunction(
            self.params.rho0_x, self.params.rho_inf_x, self.params.l_x_per_s, self.first_level_names
        )
        self.performance_zeta = PerformanceFunction(
            self.params.rho0_zeta,
            self.params.rho_inf_zeta,
            self.params.l_zeta_per_s,
            self.second_level_names,
        )
        self._limited_q_index, self._limited_v_index, self._mid, self._half_range = (
            self._joint_limits()
        )
        self._target = self._mid
        if self.params.null_space_target is not None:
            self._target = self.params.null_space_target[self._limited_v_index - _N_VEHICLE]
        self.last_signals: PPCSignals | None = None
        self._extend_beyond_funnels = False
        self._margin = np.inf
        weighted = np.any(self.params.velocity_weights != 1.0)
        self._weights = self.params.velocity_weights if weighted else None

    # ------------------------------------------------------------------ model helpers
    def _arm_velocity_names(self) -> list[str]:
        names = []
        for joint_id in range(2, self.model.njoints):
            joint, name = self.model.joints[joint_id], self.model.names[joint_id]
            names += [name] if joint.nv == 1 else [f"{name}[{k}]" for k in range(joint.nv)]
        return names

    def _joint_limits(self):
        """Arm DoFs with one position coordinate per velocity and finite limits."""
        q_index, v_index, mid, half_range = [], [], [], []
        for joint_id in range(2, self.model.njoints):
            joint = self.model.joints[joint_id]
            if joint.nq != 1 or joint.nv != 1:
                continue  # e.g. continuous joints (cos, sin): no position limits
            lower = float(self.model.lowerPositionLimit[joint.idx_q])
            upper = float(self.model.upperPositionLimit[joint.idx_q])
            if max(abs(lower), abs(upper)) >= _NO_LIMIT_THRESHOLD or not upper > lower:
                continue
            q_index.append(joint.idx_q)
            v_index.append(joint.idx_v)
            mid.append(0.5 * (upper + lower))
            half_range.append(0.5 * (upper - lower))
        return (np.array(q_index, int), np.array(v_index, int), np.array(mid), np.array(half_range))

    def null_space_velocity(self, q: np.ndarray) -> np.ndarray:
        """Secondary-task velocity zeta_0 (nv,) for joint-limit avoidance.

        zeta_0 = -k_0 grad H(q) with H(q) = sum_j (q_j - q_0j)^2 / (2 h_j), h_j the
        half-range of arm joint j and q_0 the target (mid-range by default), so
        zeta_0_j = -k_0 (q_j - q_0j) / h_j [rad/s]: each limited arm joint is pushed toward
        its target. It is zero on the 6 vehicle DoFs and on joints without (finite)
        position limits. Projected on the null space of J it moves the vehicle and the arm
        together without moving the end-effector: the vehicle slowly takes over what the
        arm is holding.
        """
        zeta_0 = np.zeros(self.model.nv)
        gain = float(self.params.null_space_gain_per_s)
        if gain > 0.0 and self._limited_q_index.size:
            offset = np.asarray(q)[self._limited_q_index] - self._target
            zeta_0[self._limited_v_index] = -gain * offset / self._half_range
        return zeta_0

    # ------------------------------------------------------------------ the law
    def _check_measurement(self, measurement: Measurement) -> tuple[np.ndarray, ...]:
        q = np.asarray(measurement.q, dtype=float)
        v = np.asarray(measurement.v, dtype=float)
        wrench = np.asarray(measurement.wrench_world, dtype=float)
        for label, array, size in (
            ("q", q, self.model.nq),
            ("v", v, self.model.nv),
            ("wrench_world", wrench, 6),
        ):
            if array.shape != (size,):
                raise ParameterError(
                    f"measurement.{label} must have shape ({size},), got {array.shape}"
                )
            if not np.all(np.isfinite(array)):
                raise ParameterError(f"measurement.{label} has non-finite entries: {array}")
        return q, v, wrench

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        """tau (nv,) [N, N m]: body wrench on the vehicle, then arm joint torques.

        A pure function of ``(time_s, measurement)`` (``time_s`` is the funnels' time,
        t = 0 at the start of the run); only ``last_signals`` is updated.

        Raises:
            FunnelViolation: a first-level (``level="first"``) or second-level
                (``level="second"``) error reached its bound, |xi| >= 1.
            ParameterError: malformed measurement, or the end-effector at the Euler
                singularity (pitch = +-90 deg).
        """
        time_s = float(time_s)
        q, v, wrench_world = self._check_measurement(measurement)
        params = self.params

        # ---- first level: force and orientation errors, eq. (8)-(12)
        force_desired = self._desired_force(time_s)
        rpy_desired = self._desired_rpy(time_s)
        _, rpy_ee = end_effector_pose(self.model, self.data, q, self.ee_frame_id)
        e_force = wrench_world[:3] - force_desired  # e_f = f_e + Delta f_e - f_d
        # e_o = rpy - rpy_d as in the paper, wrapped to [-pi, pi) so that a roll or yaw
        # crossing +-pi (where matrixToRpy jumps by 2 pi) is not read as a huge error.
        e_orientation = np.mod(rpy_ee - rpy_desired + np.pi, 2.0 * np.pi) - np.pi
        e_x = np.r_[e_force, e_orientation]
        rho_x = self.performance_x.value(time_s)
        xi_x = self._normalize("first", self.first_level_names, time_s, e_x, rho_x)
        eps_x = (
            transformed_error_extended(xi_x, _XI_CLAMP)
            if self._extend_beyond_funnels
            else transformed_error(xi_x)
        )
        # eq. (13), erratum: k_x > 0 (the paper's simulation prints -0.2). The force rows
        # are end-effector linear velocities [m/s]: with f_e = K_f (p - p0), K_f > 0, a
        # force above the desired one (e_f > 0) asks the end-effector to back off.
        xdot_r = -params.k_x * eps_x

        # ---- task space -> generalized velocities, eq. (9) (+ the remark's null space)
        jacobian = analytical_jacobian(self.model, self.data, q, self.ee_frame_id)
        jacobian_pinv = pseudo_inverse(jacobian, params.pinv_relative_cutoff, self._weights)
        zeta_r = jacobian_pinv @ xdot_r
        if params.null_space_gain_per_s > 0.0:
            zeta_0 = self.null_space_velocity(q)
            zeta_r = zeta_r + zeta_0 - jacobian_pinv @ (jacobian @ zeta_0)

        # ---- second level, eq. (14)-(19); erratum: rho_v == rho_zeta, P == P_zeta
        e_zeta = v - zeta_r
        rho_zeta = self.performance_zeta.value(time_s)
        xi_zeta = self._normalize("second", self.second_level_names, time_s, e_zeta, rho_zeta)
        # eq. (19), erratum: K_zeta > 0 (the paper's simulation prints k_v = -5).
        if self._extend_beyond_funnels:
            eps_zeta = transformed_error_extended(xi_zeta, _XI_CLAMP)
            tau = -params.k_zeta * barrier_extended(xi_zeta, _XI_CLAMP) / rho_zeta
        else:
            eps_zeta = transformed_error(xi_zeta)
            tau = -params.k_zeta * transformation_gain(xi_zeta) * eps_zeta / rho_zeta
        self._margin = float(min(np.min(1.0 - np.abs(xi_x)), np.min(1.0 - np.abs(xi_zeta))))

        self.last_signals = PPCSignals(
            time_s=time_s,
            force_desired_world_N=force_desired,
            rpy_desired=rpy_desired,
            rpy_ee=rpy_ee,
            e_x=e_x,
            rho_x=rho_x,
            xi_x=xi_x,
            eps_x=eps_x,
            xdot_r=xdot_r,
            zeta_r=zeta_r,
            e_zeta=e_zeta,
            rho_zeta=rho_zeta,
            xi_zeta=xi_zeta,
            eps_zeta=eps_zeta,
            tau=tau.copy(),
        )
        return tau

    def _normalize(self, level, names, time_s, error, bound) -> np.ndarray:
        """xi = e / rho; raises FunnelViolation at |xi| >= 1 unless the extension is on."""
        if self._extend_beyond_funnels:
            xi = normalized_error(error, bound)
            if not np.all(np.isfinite(xi)):
                check_funnel(level=level, names=names, time_s=time_s, error=error, bound=bound)
            return xi
        return check_funnel(level=level, names=names, time_s=time_s, error=error, bound=bound)

    def funnel_margin(self) -> float:
        """min(1 - |xi|) over both levels at the last ``compute`` (> 0: inside)."""
        return self._margin

    def set_funnel_extension(self, enabled: bool) -> None:
        self._extend_beyond_funnels = bool(enabled)

    def reset(self) -> None:
        """Forget the logged signals (the law itself has no state)."""
        self.last_signals = None
        self._margin = np.inf

    def signals(self) -> dict[str, np.ndarray]:
        """The last call's internal signals as arrays, for logging (empty before a call)."""
        if self.last_signals is None:
            return {}
        return {
            f.name: np.atleast_1d(getattr(self.last_signals, f.name))
            for f in dataclasses.fields(self.last_signals)
            if f.name != "time_s"
        }
