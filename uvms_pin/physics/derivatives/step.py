"""The derivatives of one control period of the plant: the discrete step a DDP-type solver
linearises, x+ = F(x, tau) with x = (q, v) and tau held over the period.

The period is taken in n equal substeps h of one of the plant's fixed-step integrators
(`uvms_pin.sim.integrators`), and its Jacobians are the product of the substeps'. Along the
tangent (dq at q, dq+ at q+), with J0(q, w) = d(q (+) w)/dq and J1(q, w) = d(q (+) w)/dw
(Pinocchio's dIntegrate, ARG0 and ARG1) and A_q, A_v, A_tau the forward dynamics' Jacobians:

Semi-implicit (symplectic) Euler, `SemiImplicitEuler`:

    v+ = v + h a(t, q, v, tau),     q+ = q (+) h v+      ((+): pin.integrate)
    dv+ = (h A_q) dq + (I + h A_v) dv + (h A_tau) dtau
    dq+ = J0 dq + h J1 dv+                               (J0, J1 at (q, h v+))

Classical RK4 in the local chart at q0 (Runge-Kutta-Munthe-Kaas, `RK4`): stages i = 1..4
with c = (0, 1/2, 1/2, 1), b = (1, 2, 2, 1)/6, delta_1 = 0, v_1 = v0,

    q_i = q0 (+) delta_i,   a_i = a(t + c_i h, q_i, v_i, tau),   d_i = Jint(delta_i)^-1 v_i
    delta_(i+1) = c_(i+1) h d_i,   v_(i+1) = v0 + c_(i+1) h a_i
    q+ = q0 (+) h sum b_i d_i,     v+ = v0 + h sum b_i a_i

(Jint(delta) = J1(q0, delta), independent of q0 for the joints handled: `chart`). Each
stage's differential, in (dq0, dv0, dtau):

    dq_i = J0(q0, delta_i) dq0 + J1(q0, delta_i) d delta_i      (the tangent at q_i)
    da_i = A_q,i dq_i + A_v,i dv_i + A_tau,i dtau                (A_q,i along q_i's tangent)
    dd_i = Jint(delta_i)^-1 dv_i + G(delta_i, v_i) d delta_i

with G(delta, w) = d/d delta [Jint(delta)^-1 w], the derivative of the inverse right
Jacobian of exp (SO(3), SE(3): `chart`, in closed form), and at the end

    dq+ = J0(q0, delta) dq0 + J1(q0, delta) h sum b_i dd_i,   dv+ = dv0 + h sum b_i da_i.

Every factor is exact (no finite difference inside). When the input is the actuators' u
(thrust forces and joint torques) rather than tau, tau = B_u u and dx+/du = dx+/dtau B_u
(`input_matrix`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster
from uvms_pin.physics.derivatives.chart import ChartBlocks


@dataclass(frozen=True)
class StepDerivatives:
    """One period's end state and Jacobians (tangent coordinates, x = (q, v)).

    Attributes:
        q, v: the state at the period's end.
        dx_dx: d(q+, v+)/d(q, v) (2 nv, 2 nv): rows [dq+; dv+], columns [dq, dv].
        dx_dtau: d(q+, v+)/dtau (2 nv, nv), tau the generalized force held over the period.
    """

    q: np.ndarray
    v: np.ndarray
    dx_dx: np.ndarray
    dx_dtau: np.ndarray

    def dx_du(self, input_matrix_: np.ndarray) -> np.ndarray:
        """d(q+, v+)/du (2 nv, m) for tau = B_u u (`input_matrix`: nv rows, finite);
        ParameterError for another shape or a non-finite entry."""
        b_u = np.asarray(input_matrix_, dtype=float)
        nv = self.dx_dtau.shape[1]
        if b_u.ndim != 2 or b_u.shape[0] != nv:
            raise ParameterError(f"the input matrix B_u must have shape ({nv}, m), got {b_u.shape}")
        if not np.all(np.isfinite(b_u)):
            raise ParameterError("the input matrix B_u contains a non-finite value")
        return self.dx_dtau @ b_u


class FixedStepIntegrator(Protocol):
    """A plant's fixed-step integrator (`uvms_pin.sim.integrators.FixedStep`): its method's
    name ("rk4", "semi_implicit_euler") and its substep [s]."""

    core_method: str
    step_s: float


Derivative = Callable[[float, np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, ...]]
"""(t, q, v, tau) -> (a, da/dq, da/dv, da/dtau): the forward dynamics and their derivatives."""


#: the most substeps one interval is split into (src/uvms_core/integrators.hpp's
#: kMaxSubsteps): beyond, the core's count is no int (it took one step of the whole
#: interval), and the call a hang
MAX_SUBSTEPS = 10_000_000


def split_interval(interval_s: float, step_s: float) -> tuple[int, float]:
    """(n, h): the fewest equal substeps no longer than ``step_s`` [s] over ``interval_s``
    [s], one at least, as the core splits it (1e-9 of a step's slack against rounding);
    ParameterError for more than `MAX_SUBSTEPS`. Unchecked numbers: the callers' own."""
    count = interval_s / step_s - 1e-9
    if not count <= MAX_SUBSTEPS:
        raise ParameterError(
            f"{interval_s:g} s in steps of {step_s:g} s is {count:.3g} substeps, more than "
            f"{MAX_SUBSTEPS:.0e} in one call: shorten the interval or lengthen the step"
        )
    n = max(1, math.ceil(count))
    return n, interval_s / n


def substeps(period_s: float, step_s: float) -> tuple[int, float]:
    """(n, h): the fewest equal substeps no longer than ``step_s`` covering the period."""
    for name, value in (("period_s", period_s), ("step_s", step_s)):
        if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
            raise ParameterError(f"{name} must be a number [s], got {value!r}")
    if not (period_s > 0.0 and math.isfinite(period_s)):
        raise ParameterError(f"period_s must be positive and finite, got {period_s}")
    if not (step_s > 0.0 and math.isfinite(step_s)):
        raise ParameterError(f"step_s must be positive and finite, got {step_s}")
    return split_interval(period_s, step_s)


def euler_substep(
    model: pin.Model,
    derivative: Derivative,
    t: float,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    h: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q+, v+, d(q+, v+)/d(q, v, tau) (2 nv, 3 nv)) of one semi-implicit Euler substep h
    [s] from (q, v) at t (the module docstring)."""
    nv = model.nv
    a, a_q, a_v, a_tau = derivative(t, q, v, tau)
    v_next = v + h * a
    w = h * v_next
    j0 = pin.dIntegrate(model, q, w, pin.ARG0)
    j1 = pin.dIntegrate(model, q, w, pin.ARG1)
    dv_next = np.hstack([h * a_q, np.eye(nv) + h * a_v, h * a_tau])
    dq_next = np.hstack([j0, np.zeros((nv, nv)), np.zeros((nv, nv))]) + h * j1 @ dv_next
    return pin.integrate(model, q, w), v_next, np.vstack([dq_next, dv_next])


#: the integrators differentiated (their names in `uvms_pin.sim.integrators`' core_method)
METHODS = ("semi_implicit_euler", "rk4")

#: the classical Runge-Kutta tableau: stage times c_i, stage rows a_(i+1, i) = c_(i+1), weights
_RK4_TIMES = (0.0, 0.5, 0.5, 1.0)
_RK4_WEIGHTS = (1.0 / 6.0, 2.0 / 6.0, 2.0 / 6.0, 1.0 / 6.0)


def rk4_substep(
    model: pin.Model,
    derivative: Derivative,
    t: float,
    q0: np.ndarray,
    v0: np.ndarray,
    tau: np.ndarray,
    h: float,
    chart: ChartBlocks,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q+, v+, d(q+, v+)/d(q0, v0, tau) (2 nv, 3 nv)) of one RK4 substep h [s] in the
    chart at q0 (`uvms_pin.sim.integrators.RK4`, the module docstring)."""
    nv = model.nv
    zero, identity = np.zeros((nv, nv)), np.eye(nv)
    e_q = np.hstack([identity, zero, zero])  # d q0 / d(q0, v0, tau) along the tangent
    e_v = np.hstack([zero, identity, zero])
    e_tau = np.hstack([zero, zero, identity])
    delta, d_delta = np.zeros(nv), np.zeros((nv, 3 * nv))  # stage 1: delta_1 = 0
    v, d_v = v0, e_v
    rate_sum, d_rate_sum = np.zeros(nv), np.zeros((nv, 3 * nv))
    accel_sum, d_accel_sum = np.zeros(nv), np.zeros((nv, 3 * nv))
    for i, (c_i, b_i) in enumerate(zip(_RK4_TIMES, _RK4_WEIGHTS, strict=True)):
        q = pin.integrate(model, q0, delta)
        j0 = pin.dIntegrate(model, q0, delta, pin.ARG0)
        j1 = pin.dIntegrate(model, q0, delta, pin.ARG1)
        inverse, rate_slope = chart.rate(delta, v)
        rate = inverse @ v  # d_i = Jint(delta_i)^-1 v_i
        d_rate = inverse @ d_v + rate_slope @ d_delta
        a, a_q, a_v, a_tau = derivative(t + c_i * h, q, v, tau)
        # dq_i along the tangent at q_i, carried back to q0's: J0 dq0 + J1 d delta_i
        d_accel = a_q @ (j0 @ e_q + j1 @ d_delta) + a_v @ d_v + a_tau @ e_tau
        rate_sum, d_rate_sum = rate_sum + b_i * rate, d_rate_sum + b_i * d_rate
        accel_sum, d_accel_sum = accel_sum + b_i * a, d_accel_sum + b_i * d_accel
        if i + 1 < len(_RK4_TIMES):  # the next stage: delta = c h d_i, v = v0 + c h a_i
            c_next = _RK4_TIMES[i + 1]
            delta, d_delta = c_next * h * rate, c_next * h * d_rate
            v, d_v = v0 + c_next * h * a, e_v + c_next * h * d_accel
    delta, d_delta = h * rate_sum, h * d_rate_sum
    j0 = pin.dIntegrate(model, q0, delta, pin.ARG0)
    j1 = pin.dIntegrate(model, q0, delta, pin.ARG1)
    local = np.vstack([j0 @ e_q + j1 @ d_delta, e_v + h * d_accel_sum])
    return pin.integrate(model, q0, delta), v0 + h * accel_sum, local


def step_derivatives_of(
    model: pin.Model,
    derivative: Derivative,
    time_s: float,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    period_s: float,
    step_s: float,
    method: str = "semi_implicit_euler",
) -> StepDerivatives:
    """The `StepDerivatives` of the period [time_s, time_s + period_s] for the dynamics
    ``derivative``, in substeps of ``method`` ("semi_implicit_euler" or "rk4", the module
    docstring): the product of the substeps' Jacobians."""
    n, h = substeps(period_s, step_s)
    nv = model.nv
    if method == "rk4":
        chart = ChartBlocks.of(model)

        def substep(t, q, v):
            return rk4_substep(model, derivative, t, q, v, tau, h, chart)
    elif method == "semi_implicit_euler":

        def substep(t, q, v):
            return euler_substep(model, derivative, t, q, v, tau, h)
    else:
        raise ParameterError(f"method must be one of {METHODS}, got '{method}'")
    state = np.eye(2 * nv)  # d(q_k, v_k)/d(q_0, v_0)
    forced = np.zeros((2 * nv, nv))  # d(q_k, v_k)/dtau
    for k in range(n):
        q, v, local = substep(time_s + k * h, q, v)
        state, forced = local[:, : 2 * nv] @ state, local[:, : 2 * nv] @ forced + local[:, 2 * nv :]
    return StepDerivatives(q=q, v=v, dx_dx=state, dx_dtau=forced)


def input_matrix(thrusters: tuple[Thruster, ...] | list[Thruster], nv: int) -> np.ndarray:
    """B_u (nv, m + nv - 6): tau = B_u u for u = (thrust forces f (m,) [N], joint torques
    (nv - 6,) [N m]), tau[:6] = B f the vehicle's body wrench (B the allocation matrix of
    the thrusters' wrench columns), tau[6:] the joint torques. The inverse of the plant's
    allocation (`uvms_pin.sim.actuation`) when no thruster saturates."""
    if not thrusters:
        raise ParameterError("input_matrix needs at least one thruster")
    if nv < 6:
        raise ParameterError(f"input_matrix needs a free-floating vehicle (nv >= 6), got nv={nv}")
    m = len(thrusters)
    out = np.zeros((nv, m + nv - 6))
    out[:6, :m] = np.column_stack([t.wrench_column for t in thrusters])
    out[6:, m:] = np.eye(nv - 6)
    return out
