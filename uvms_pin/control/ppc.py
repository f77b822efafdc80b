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

How ``compute`` is evaluated (it runs once per control tick, or once per integrator stage,
so it avoids per-call overhead; the results agree with the direct evaluation of the
equations above to ~1e-13, see tests/control/test_ppc_oracle.py):

- one Pinocchio pass gives the end-effector rotation and its LOCAL_WORLD_ALIGNED Jacobian
  J^lwa; the analytical Jacobian is J = diag(I, E^-1) J^lwa with E the Euler-rate matrix
  in world axes, and since J has full row rank, J^# xdot = (J^lwa)^# [xdot_p; E xdot_o]:
  E is applied in closed form and never inverted;
- J^# is applied by a Cholesky solve of the 6 x 6 J W^-1 J^T with one refinement step
  (:class:`~uvms_pin.control.pseudo_inverse.MinimumNormSolver`); when its certified
  condition bound is too large, the exact SVD route of the definition is used instead;
- both funnels are evaluated in one vector, and a funnel check is one max |xi| < 1; the
  detailed checks (which component, which exception) only run when that fails;
- scalar ``math`` on the 3- and 6-element quantities; ``last_signals`` is assembled only
  when read.

With ``backend="core"`` (the default) the same steps run compiled in one call
(``src/uvms_core/ppc.hpp``, the names there are the ones here): f_d(t) and rpy_d(t) are
still evaluated in Python (user code), and every call the kernel does not return as ok (a
funnel left or the extension's clamp passed, the solver declining, the Euler singularity, a
malformed or non-finite input) is evaluated by the Python code below, so the exceptions and
the SVD and extension routes are this module's own.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.performance import (
    PerformanceFunction,
    barrier_extended,
    check_funnel,
    max_abs,
    normalized_error,
    transformed_error,
    transformed_error_extended,
)
from uvms_pin.control.ppc_kernel import PpcKernel
from uvms_pin.control.ppc_params import PPCParams
from uvms_pin.control.pseudo_inverse import pseudo_inverse
from uvms_pin.control.task_space import (
    ForceOrientationTask,
    check_measurement,
    first_level_error,
)
from uvms_pin.physics.compiled.backend import Fallback, backend_named
from uvms_pin.physics.kinematics import (
    check_euler_singularity,
    frame_rotation_and_jacobian,
)
from uvms_pin.results.components import FIRST_LEVEL_NAMES, VEHICLE_VELOCITY_NAMES

__all__ = [
    "FIRST_LEVEL_NAMES",
    "VEHICLE_VELOCITY_NAMES",
    "PPCParams",
    "PPCSignals",
    "PrescribedPerformanceController",
    "pseudo_inverse",
]

#: With the funnel extension on (continuous-time simulation), the barrier is continued
#: linearly beyond |xi| = this (where eps ~ 14.5, r ~ 1e6): it keeps growing outside.
_XI_CLAMP = 1.0 - 1e-6


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
        backend: ``"core"`` (default): the compiled law (``src/uvms_core/ppc.hpp``) with
            this Python code as its fallback on every call it declines; ``"python"``: this
            code only, the reference. Both give the same tau to ~1e-13 and raise the same
            errors (tests/control/test_ppc_core.py).

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
        *,
        backend: str = "core",
    ):
        self.backend = backend_named(backend).name
        task = ForceOrientationTask(
            model, ee_frame_name, params or PPCParams(), desired_force_world_N, desired_rpy
        )
        self.task = task
        self.model, self.data, self.ee_frame_id = task.model, task.data, task.ee_frame_id
        self.ee_frame_name = ee_frame_name
        self.params = task.params
        self._desired_force, self._desired_rpy = task.desired_force, task.desired_rpy
        self._pull, self._reference = task.pull, task.reference
        self.first_level_names = FIRST_LEVEL_NAMES
        self.second_level_names = task.velocity_names
        self.performance_x = PerformanceFunction(
            self.params.rho0_x, self.params.rho_inf_x, self.params.l_x_per_s, self.first_level_names
        )
        self.performance_zeta = PerformanceFunction(
            self.params.rho0_zeta,
            self.params.rho_inf_zeta,
            self.params.l_zeta_per_s,
            self.second_level_names,
        )
        self._extend_beyond_funnels = False
        self._margin = np.inf

        # ---- constants of the fast evaluation (see the module docstring)
        # both levels' funnels in one vector: rho = [rho_x (6); rho_zeta (nv)]
        self._performance_both = PerformanceFunction(
            np.r_[self.performance_x.rho0, self.performance_zeta.rho0],
            np.r_[self.performance_x.rho_inf, self.performance_zeta.rho_inf],
            np.r_[self.performance_x.decay_rate_per_s, self.performance_zeta.decay_rate_per_s],
            self.first_level_names + self.second_level_names,
        )
        # -k_x eps = (-2 k_x) artanh(xi) and -k r eps / rho = (-4 k) artanh(xi) / ((1 - xi^2) rho)
        self._neg_two_k_x = (-2.0 * self.params.k_x).tolist()
        self._neg_four_k_zeta = -4.0 * self.params.k_zeta
        self._nq, self._nv = self.model.nq, self.model.nv
        # the last successful call's raw signals, and the PPCSignals built from them on demand
        # (_last is None when they are the compiled kernel's, see _core_last)
        self._last: tuple | None = None
        self._last_signals: PPCSignals | None = None
        self._core_last: tuple | None = None
        self._kernel = self._build_kernel()

    def _build_kernel(self) -> PpcKernel | None:
        """The compiled law with this controller's constants (None with the Python backend)."""
        kernel = PpcKernel.build(backend_named(self.backend), self.model, self.kernel_settings())
        return None if isinstance(kernel, Fallback) else kernel

    @property
    def kernel(self) -> PpcKernel | None:
        """The compiled law of this controller (None with the Python backend)."""
        return self._kernel

    def kernel_settings(self) -> dict[str, object]:
        """The compiled law's settings (the fields of the core's PpcSettings, by name)."""
        params, zeta, pull = self.params, self.performance_zeta, self._pull
        return {
            "ee_frame_id": self.ee_frame_id,
            "k_x": params.k_x,
            "rho0_x": params.rho0_x,
            "rho_inf_x": params.rho_inf_x,
            "l_x_per_s": params.l_x_per_s,
            "k_zeta": params.k_zeta,
            "rho0_zeta": zeta.rho0,
            "rho_inf_zeta": zeta.rho_inf,
            "l_zeta_per_s": zeta.decay_rate_per_s,
            "velocity_weights": params.velocity_weights,
            "null_space_gain_per_s": float(params.null_space_gain_per_s),
            "limited_q_index": pull.limited_q_index.tolist(),
            "limited_v_index": pull.limited_v_index.tolist(),
            "null_space_target": np.asarray(pull.target, dtype=float),
            "half_range": pull.half_range,
            "max_condition_bound": self._reference.solver.max_condition_bound,
            "xi_clamp": _XI_CLAMP,
        }

    _KERNEL_ATTRIBUTES = ("_kernel",)

    def __getstate__(self) -> dict:
        """For copy and pickle: the compiled kernel is rebuilt, the last signals kept."""
        self.last_signals  # noqa: B018 - builds the PPCSignals (from the kernel's buffers)
        state = {k: v for k, v in self.__dict__.items() if k not in self._KERNEL_ATTRIBUTES}
        state["_margin"] = self.funnel_margin()
        state["_core_last"] = None
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._kernel = self._build_kernel()

    def null_space_velocity(self, q: np.ndarray) -> np.ndarray:
        """The secondary task's velocity zeta_0 (nv,) at q (`JointLimitPull`)."""
        return self._pull.velocity(q)

    # ------------------------------------------------------------------ the law
    def _check_measurement(self, measurement: Measurement) -> tuple[np.ndarray, ...]:
        return check_measurement(measurement, self._nq, self._nv)

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        """tau (nv,) [N, N m]: body wrench on the vehicle, then arm joint torques.

        A pure function of ``(time_s, measurement)`` (``time_s`` is the funnels' time,
        t = 0 at the start of the run); only ``last_signals`` is updated.

        With ``backend="core"`` the compiled kernel evaluates the law; every call it does not
        return as ok (a funnel left, the solver declining, the Euler singularity, a malformed
        or non-finite input) is evaluated by the Python reference below, which raises, or
        takes the SVD route or the funnel extension, exactly as with ``backend="python"``.

        Raises:
            FunnelViolation: a first-level (``level="first"``) or second-level
                (``level="second"``) error reached its bound, |xi| >= 1.
            ParameterError: malformed measurement, or the end-effector at the Euler
                singularity (pitch = +-90 deg).
        """
        kernel = self._kernel
        time_s = float(time_s)
        if kernel is None:
            return self._compute_reference(time_s, measurement)
        try:
            force_desired = self._desired_force(time_s)
            rpy_desired = self._desired_rpy(time_s)
        except Exception:
            self._check_measurement(measurement)  # the reference checks the measurement first
            raise
        extended = self._extend_beyond_funnels
        # any status but ok (0), bad input included: the reference evaluates, raises or says why
        status = kernel.compute(
            time_s,
            measurement.q,
            measurement.v,
            measurement.wrench_world,
            force_desired,
            rpy_desired,
            extended,
        )
        if status:
            return self._compute_reference(time_s, measurement, force_desired, rpy_desired)
        self._core_last = (time_s, force_desired, rpy_desired, extended)
        self._last = None
        self._last_signals = None
        self._margin = None
        return kernel.tau.copy()

    def _compute_reference(
        self,
        time_s: float,
        measurement: Measurement,
        force_desired: np.ndarray | None = None,
        rpy_desired: np.ndarray | None = None,
    ) -> np.ndarray:
        """The Python evaluation of :meth:`compute` (``backend="python"``, and the calls the
        compiled kernel declines); f_d(t) and rpy_d(t) are evaluated here unless given."""
        q, v, wrench_world = self._check_measurement(measurement)
        extended = self._extend_beyond_funnels

        # ---- first level: force and orientation errors, eq. (8)-(12)
        if force_desired is None:
            force_desired = self._desired_force(time_s)
            rpy_desired = self._desired_rpy(time_s)
        rotation, jacobian_lwa = frame_rotation_and_jacobian(
            self.model, self.data, q, self.ee_frame_id
        )
        rpy_ee = pin.rpy.matrixToRpy(rotation)
        e_x = first_level_error(wrench_world, force_desired, rpy_ee, rpy_desired)
        rho = self._performance_both.value(time_s)
        rho_x, rho_zeta = rho[:6], rho[6:]
        # eq. (13), erratum: k_x > 0 (the paper's simulation prints -0.2). The force rows
        # are end-effector linear velocities [m/s]: with f_e = K_f (p - p0), K_f > 0, a
        # force above the desired one (e_f > 0) asks the end-effector to back off.
        # Six components: Python floats (-k_x eps = -2 k_x artanh(xi)).
        xi_x = [e / r for e, r in zip(e_x, rho_x.tolist(), strict=True)]
        max_xi_x = max_abs(xi_x)
        if max_xi_x < (_XI_CLAMP if extended else 1.0):
            xdot_r = [k * math.atanh(x) for k, x in zip(self._neg_two_k_x, xi_x, strict=True)]
        else:  # outside (raises), or beyond the clamp of the funnel extension
            e_x = np.array(e_x)
            xi_x = self._normalize("first", self.first_level_names, time_s, e_x, rho_x)
            xdot_r = (-self.params.k_x * transformed_error_extended(xi_x, _XI_CLAMP)).tolist()
        check_euler_singularity(self.model, self.ee_frame_id, rpy_ee)

        # ---- task space -> generalized velocities, eq. (9) (+ the remark's null space)
        zeta_r = self._reference_velocity(q, rpy_ee, jacobian_lwa, xdot_r)

        # ---- second level, eq. (14)-(19); erratum: rho_v == rho_zeta, P == P_zeta
        e_zeta = v - zeta_r
        xi_zeta = e_zeta / rho_zeta
        max_xi_zeta = max_abs(xi_zeta)
        # eq. (19), erratum: K_zeta > 0 (the paper's simulation prints k_v = -5).
        if max_xi_zeta < (_XI_CLAMP if extended else 1.0):
            # -K_zeta P^-1 r(xi) eps(xi) with r eps = 4 artanh(xi) / (1 - xi^2), and
            # (1 - xi^2) rho = rho - xi e
            tau = self._neg_four_k_zeta * np.arctanh(xi_zeta) / (rho_zeta - xi_zeta * e_zeta)
        else:
            xi_zeta = self._normalize("second", self.second_level_names, time_s, e_zeta, rho_zeta)
            tau = -self.params.k_zeta * barrier_extended(xi_zeta, _XI_CLAMP) / rho_zeta
        # min(1 - |xi|) = 1 - max |xi| exactly (1 - x rounds monotonically)
        self._margin = 1.0 - max(max_xi_x, max_xi_zeta)
        self._last = (
            time_s,
            force_desired,
            rpy_desired,
            rpy_ee,
            e_x,
            rho_x,
            xi_x,
            xdot_r,
            zeta_r,
            e_zeta,
            rho_zeta,
            xi_zeta,
            tau.copy(),
            extended,
        )
        self._core_last = None
        self._last_signals = None
        return tau

    def _reference_velocity(
        self, q: np.ndarray, rpy_ee: np.ndarray, jacobian_lwa: np.ndarray, xdot_r: list[float]
    ) -> np.ndarray:
        """zeta_r = J^# xdot_r + (I - J^# J) zeta_0 (nv,) [m/s, rad/s] (`ReferenceVelocity`)."""
        return self._reference(q, rpy_ee, jacobian_lwa, xdot_r)

    def _normalize(self, level, names, time_s, error, bound) -> np.ndarray:
        """xi = e / rho; raises FunnelViolation at |xi| >= 1 unless the extension is on."""
        if self._extend_beyond_funnels:
            xi = normalized_error(error, bound)
            if not np.all(np.isfinite(xi)):
                check_funnel(level=level, names=names, time_s=time_s, error=error, bound=bound)
            return xi
        return check_funnel(level=level, names=names, time_s=time_s, error=error, bound=bound)

    @property
    def last_signals(self) -> PPCSignals | None:
        """:class:`PPCSignals` of the last successful ``compute`` (None before one)."""
        if self._last_signals is not None:
            return self._last_signals
        if self._core_last is not None:  # copies: the kernel's buffer is rewritten
            time_s, force_desired, rpy_desired, extended = self._core_last
            (rpy_ee, e_x, rho_x, xi_x, xdot_r, zeta_r, e_zeta, rho_zeta, xi_zeta,
             tau) = self._kernel.copies()  # fmt: skip
        elif self._last is not None:
            (time_s, force_desired, rpy_desired, rpy_ee, e_x, rho_x, xi_x, xdot_r, zeta_r,
             e_zeta, rho_zeta, xi_zeta, tau, extended) = self._last  # fmt: skip
        else:
            return None
        transform = (
            (lambda xi: transformed_error_extended(xi, _XI_CLAMP))
            if extended
            else transformed_error
        )
        self._last_signals = PPCSignals(
            time_s=time_s,
            force_desired_world_N=force_desired,
            rpy_desired=rpy_desired,
            rpy_ee=rpy_ee,
            e_x=np.array(e_x),
            rho_x=rho_x,
            xi_x=np.array(xi_x),
            eps_x=transform(np.array(xi_x)),
            xdot_r=np.array(xdot_r),
            zeta_r=zeta_r,
            e_zeta=e_zeta,
            rho_zeta=rho_zeta,
            xi_zeta=xi_zeta,
            eps_zeta=transform(xi_zeta),
            tau=tau,
        )
        return self._last_signals

    def adopt_kernel_call(
        self, time_s: float, force_desired: np.ndarray, rpy_desired: np.ndarray
    ) -> None:
        """The compiled kernel's last call (at ``time_s``, with these f_d and rpy_d) was made
        for this controller by the compiled closed loop (`uvms_pin.sim.compiled_loop`): its
        signals and margin are this controller's last, as after an ok `compute`."""
        self._core_last = (float(time_s), force_desired, rpy_desired, False)
        self._last = None
        self._last_signals = None
        self._margin = None

    def desired_force_world_N(self, time_s: float) -> np.ndarray:
        """f_d(t) (3,) [N], world axes: the force this controller tracks."""
        return np.asarray(self._desired_force(time_s), dtype=float)

    def funnel_margin(self) -> float:
        """min(1 - |xi|) over both levels at the last ``compute`` (> 0: inside)."""
        margin = self._margin
        return self._kernel.margin if margin is None else margin

    def set_funnel_extension(self, enabled: bool) -> None:
        self._extend_beyond_funnels = bool(enabled)

    def reset(self) -> None:
        """Forget the logged signals (the law itself has no state)."""
        self._last = None
        self._core_last = None
        self._last_signals = None
        self._margin = np.inf

    def signals(self) -> dict[str, np.ndarray]:
        """The last call's internal signals as arrays, for logging (empty before a call)."""
        signals = self.last_signals
        if signals is None:
            return {}
        return {
            f.name: np.atleast_1d(getattr(signals, f.name))
            for f in dataclasses.fields(signals)
            if f.name != "time_s"
        }
