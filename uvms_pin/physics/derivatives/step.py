"""The derivatives of one control period of the plant: the discrete step a DDP-type solver
linearises, x+ = F(x, tau) with x = (q, v) and tau held over the period.

The period is taken in n equal substeps h of semi-implicit (symplectic) Euler, the plant's
`uvms_pin.sim.integrators.SemiImplicitEuler`:

    v+ = v + h a(t, q, v, tau),     q+ = q (+) h v+      ((+): pin.integrate)

Along the tangent (dq at q, dq+ at q+), with J0 = d(q (+) w)/dq and J1 = d(q (+) w)/dw at
w = h v+ (Pinocchio's dIntegrate, ARG0 and ARG1):

    dv+ = (h A_q) dq + (I + h A_v) dv + (h A_tau) dtau
    dq+ = J0 dq + h J1 dv+

and the period's Jacobians are the product of the substeps'. When the input is the
actuators' u (thrust forces and joint torques) rather than tau, tau = B_u u and
dx+/du = dx+/dtau B_u (`input_matrix`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster


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
        """d(q+, v+)/du (2 nv, m) for tau = B_u u (`input_matrix`)."""
        return self.dx_dtau @ input_matrix_


Derivative = Callable[[float, np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, ...]]
"""(t, q, v, tau) -> (a, da/dq, da/dv, da/dtau): the forward dynamics and their derivatives."""


def substeps(period_s: float, step_s: float) -> tuple[int, float]:
    """(n, h): the fewest equal substeps no longer than ``step_s`` covering the period."""
    if not (period_s > 0.0 and math.isfinite(period_s)):
        raise ParameterError(f"period_s must be positive and finite, got {period_s}")
    if not (step_s > 0.0 and math.isfinite(step_s)):
        raise ParameterError(f"step_s must be positive and finite, got {step_s}")
    n = max(1, math.ceil(period_s / step_s - 1e-9))
    return n, period_s / n


def step_derivatives_of(
    model: pin.Model,
    derivative: Derivative,
    time_s: float,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    period_s: float,
    step_s: float,
) -> StepDerivatives:
    """The `StepDerivatives` of the period [time_s, time_s + period_s] for the dynamics
    ``derivative`` (see the module docstring)."""
    n, h = substeps(period_s, step_s)
    nv = model.nv
    identity = np.eye(nv)
    state = np.eye(2 * nv)  # d(q_k, v_k)/d(q_0, v_0)
    forced = np.zeros((2 * nv, nv))  # d(q_k, v_k)/dtau
    for k in range(n):
        a, a_q, a_v, a_tau = derivative(time_s + k * h, q, v, tau)
        v_next = v + h * a
        w = h * v_next
        j0 = pin.dIntegrate(model, q, w, pin.ARG0)
        j1 = pin.dIntegrate(model, q, w, pin.ARG1)
        # the substep's own Jacobian on (dq, dv, dtau)
        dv_next = np.hstack([h * a_q, identity + h * a_v, h * a_tau])
        dq_next = np.hstack([j0, np.zeros((nv, nv)), np.zeros((nv, nv))]) + h * j1 @ dv_next
        local = np.vstack([dq_next, dv_next])
        state, forced = local[:, : 2 * nv] @ state, local[:, : 2 * nv] @ forced + local[:, 2 * nv :]
        q, v = pin.integrate(model, q, w), v_next
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
