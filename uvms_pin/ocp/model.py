"""The UVMS in water as a crocoddyl differential action model.

State x = (q, v) on the configuration manifold (`uvms_pin.ocp.state.UvmsState`: free-flyer
SE(3) x joints), control u = the actuators' inputs, tau = B_u u (B_u the identity: u is the
generalized force; or `uvms_pin.physics.discrete.input_matrix`: u = thrust forces [N] and
joint torques [N m]). The dynamics are uvms-pin's underwater forward dynamics; calcDiff gives
their analytical derivatives along the tangent,

    Fx = [da/dq, da/dv],     Fu = da/dtau B_u,

and the Gauss-Newton derivatives of the cost terms (`uvms_pin.ocp.costs`). With a
``contact`` (the end-effector on a compliant environment, `uvms_pin.physics.contact`), the
environment's push is in the dynamics, tau_ext(q, v) = -J^T lambda(p, p_dot), and in their
derivatives (`uvms_pin.physics.derivatives.task_contact`; da/dtau_ext = da/dtau = M^-1):

    Fx += M^-1 [d tau_ext/dq, d tau_ext/dv].

Bounds on u (thrust and effort limits) go to crocoddyl's box-constrained solvers through
``u_lb`` / ``u_ub``; with ``bounds_as_constraints`` they are also the node's inequality
constraints, lower <= g(x, u) = u <= upper (G_x = 0, G_u = I: a crocoddyl
ConstraintModelManager holding a ConstraintModelResidual of ResidualModelControl), what a
constrained solver (mim_solvers' CSQP) enforces.

An exception raised in calc or calcDiff (a user's cost term or flow) is held, the node's
cost set to `REJECTED_COST` and its other outputs to zero, and raised by
`uvms_pin.ocp.problems.solve` after the solver returns (`uvms_pin.ocp.held_errors`: it
cannot cross crocoddyl's C++ loop).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp.crocoddyl_module import crocoddyl_module
from uvms_pin.ocp.held_errors import HeldError
from uvms_pin.ocp.plans import WeightedTerms, check_terms, checked_bounds, checked_input_matrix
from uvms_pin.ocp.state import UvmsState
from uvms_pin.physics.derivatives.task_contact import (
    TaskContact,
    contact_derivatives,
    contact_wrench,
    supports_mask,
)
from uvms_pin.physics.dynamics import forward_dynamics, forward_dynamics_derivatives

crocoddyl = crocoddyl_module()

#: the cost of a node that raised: finite, so that no step through it is accepted and the
#: solver returns (a NaN is itself an exception in mim_solvers' CSQP, which aborts)
REJECTED_COST = 1e30


class UnderwaterActionModel(crocoddyl.DifferentialActionModelAbstract):
    """M(q) a + h(q, v) = B_u u, the water included, with a sum of cost terms.

    Args:
        uvms: the model. terms: the node's cost, (term, scale) pairs.
        input_matrix_: B_u (nv, nu); None: the identity (u = tau).
        flow, time_s: the water (a `uvms_pin.flow.FlowField`, None: still) and the time the
            flow is frozen at [s] (one model per node for a moving flow).
        u_bounds: (lower, upper) (nu,) each, or None for none.
        backend: "core" (compiled) or "python" (the reference).
        contact: the end-effector's environment (a `TaskContact`, its model placed before
            the first calc), or None; a term with ``needs_contact`` requires one.
        bounds_as_constraints: ``u_bounds`` also as the inequality constraints
            lower <= u <= upper (ng = nu; ignored without bounds).
    """

    def __init__(
        self,
        uvms: UVMS,
        terms: WeightedTerms,
        *,
        input_matrix_: np.ndarray | None = None,
        flow: FlowField | None = None,
        time_s: float = 0.0,
        u_bounds: tuple[np.ndarray, np.ndarray] | None = None,
        backend: str = "core",
        contact: TaskContact | None = None,
        bounds_as_constraints: bool = False,
    ):
        b_u = checked_input_matrix(uvms, input_matrix_)
        nr, nu = sum(term.nr for term, _ in terms), b_u.shape[1]
        check_terms(terms, nu, contact is not None)
        ng = nu if bounds_as_constraints and u_bounds is not None else 0
        state = UvmsState(uvms.model)
        crocoddyl.DifferentialActionModelAbstract.__init__(self, state, nu, nr, ng)
        self.uvms, self.terms, self.input_matrix = uvms, list(terms), b_u
        # scale_i W_i of every residual row, in the terms' order
        self._weights = np.concatenate([np.zeros(0), *(s * term.weights for term, s in terms)])
        self.water = {"flow": flow, "time_s": float(time_s), "backend": backend}
        self.contact = contact
        self.held = HeldError()  # what calc / calcDiff raised inside crocoddyl
        # where d J_k/dq_m can be non-zero (the contact's derivatives), once per model
        self._supports = None if contact is None else supports_mask(uvms.model)
        self.constraints = None
        if u_bounds is not None:
            lower, upper = checked_bounds(u_bounds, nu)
            self.u_lb, self.u_ub = lower, upper
        if ng:  # (the manager's own g_lb / g_ub read garbage in the crocoddyl 3.2.1 wheels)
            self.constraints = _input_constraints(state, lower, upper)
            self.g_lb, self.g_ub = lower, upper

    def _split(self, x: np.ndarray, u: np.ndarray | None):
        nq = self.uvms.nq
        u = np.zeros(self.nu) if u is None else np.asarray(u)
        return x[:nq], x[nq:], u

    def calc(self, data, x, u=None):
        try:
            self._calc(data, x, u)
        except Exception as exc:  # it cannot cross crocoddyl's C++ loop (held_errors)
            self.held.hold(exc, "calc")
            _zero(data, "xout", "g", "residual")
            data.cost = REJECTED_COST

    def calcDiff(self, data, x, u=None):
        try:
            self._calc_diff(data, x, u)
        except Exception as exc:
            self.held.hold(exc, "calcDiff")
            _zero(data, "Fx", "Fu", "Gx", "Gu", "Lx", "Lu", "Lxx", "Luu", "Lxu")

    def _calc(self, data, x, u):
        q, v, u = self._split(x, u)
        model, pdata = self.uvms.model, data.pinocchio
        if self.contact is None:
            pin.forwardKinematics(model, pdata, q, v)
            data.contact, tau_ext = None, None
        else:  # its kinematics at (q, v) are the costs' too
            data.contact = contact_wrench(self.contact, model, pdata, q, v)
            data.contact_x = x.copy()  # where data.contact is (calcDiff reuses it there)
            tau_ext = data.contact.tau_ext
        pin.updateFramePlacements(model, pdata)
        data.xout[:] = forward_dynamics(
            self.uvms, q, v, self.input_matrix @ u, tau_ext=tau_ext, **self.water
        )
        if self.constraints is not None:
            self.constraints.calc(data.constraints, x, u)
            data.g[:] = data.constraints.g
        data.residuals = [term.residual(model, pdata, x, u, data.contact) for term, _ in self.terms]
        data.residual = residual = np.concatenate([np.zeros(0), *data.residuals])
        data.cost = 0.5 * float(residual @ (self._weights * residual))

    def _calc_diff(self, data, x, u):
        q, v, u = self._split(x, u)
        model, pdata, nv = self.uvms.model, data.pinocchio, self.uvms.nv
        contact, tau_ext = None, None
        if self.contact is not None:
            # also the WORLD joint Jacobians in pdata, as computeJointJacobians leaves them;
            # the contact of the last calc reused when it was at this state (crocoddyl's
            # solvers calc before calcDiff at the same point)
            known = data.contact if np.array_equal(data.contact_x, x) else None
            state, contact = contact_derivatives(
                self.contact, model, pdata, q, v, self._supports, at_state=known
            )
            tau_ext = state.tau_ext
        else:
            pin.computeJointJacobians(model, pdata, q)
        da_dq, da_dv, da_dtau = forward_dynamics_derivatives(
            self.uvms, q, v, self.input_matrix @ u, tau_ext=tau_ext, **self.water
        )
        if contact is not None:
            da_dq += da_dtau @ contact.tau_dq
            da_dv += da_dtau @ contact.tau_dv
        data.Fx[:, :nv], data.Fx[:, nv:] = da_dq, da_dv
        data.Fu[:, :] = da_dtau @ self.input_matrix
        if self.constraints is not None:
            self.constraints.calcDiff(data.constraints, x, u)
            data.Gx[:, :], data.Gu[:, :] = data.constraints.Gx, data.constraints.Gu
        self._cost_derivatives(data, x, u, contact)

    def _cost_derivatives(self, data, x, u, contact) -> None:
        """Gauss-Newton: l_x = R_x^T W r, l_xx = R_x^T W R_x (likewise u, xu), summed (the
        joint Jacobians at q already in the node's Pinocchio data): the terms' rows stacked,
        R = [R_x R_u] (nr, nx + nu), so that the sums are two products."""
        model, pdata = self.uvms.model, data.pinocchio
        nx = 2 * model.nv
        stacked = np.empty((self.nr, nx + self.nu))
        row = 0
        for term, _ in self.terms:
            rx, ru = term.jacobians(model, pdata, x, u, contact)
            stacked[row : row + term.nr, :nx], stacked[row : row + term.nr, nx:] = rx, ru
            row += term.nr
        weighted = self._weights[:, None] * stacked
        gradient = weighted.T @ data.residual
        hessian = stacked.T @ weighted
        data.Lx[:], data.Lu[:] = gradient[:nx], gradient[nx:]
        data.Lxx[:, :], data.Luu[:, :] = hessian[:nx, :nx], hessian[nx:, nx:]
        data.Lxu[:, :] = hessian[:nx, nx:]

    def createData(self):
        return UnderwaterActionData(self)


def _zero(data, *names: str) -> None:
    """Zero ``data``'s arrays ``names`` (what a node that raised computed: finite, see
    `REJECTED_COST`)."""
    for name in names:
        getattr(data, name)[...] = 0.0


def _input_constraints(state, lower: np.ndarray, upper: np.ndarray):
    """lower <= u <= upper as a crocoddyl ConstraintModelManager (one residual constraint on
    the control)."""
    manager = crocoddyl.ConstraintModelManager(state, lower.size)
    residual = crocoddyl.ResidualModelControl(state, lower.size)
    bounds = crocoddyl.ConstraintModelResidual(state, residual, lower, upper)
    manager.addConstraint("input_bounds", bounds)
    return manager


class UnderwaterActionData(crocoddyl.DifferentialActionDataAbstract):
    """The model's buffers: crocoddyl's, a Pinocchio data, the last residuals and the
    constraints' data (None without constraints)."""

    def __init__(self, model: UnderwaterActionModel):
        crocoddyl.DifferentialActionDataAbstract.__init__(self, model)
        self.constraints = None
        if model.constraints is not None:
            self._collector = crocoddyl.DataCollectorAbstract()  # outlives the data using it
            self.constraints = model.constraints.createData(self._collector)
        self.pinocchio = model.uvms.model.createData()
        self.residuals: list[np.ndarray] = []
        self.residual = np.zeros(model.nr)  # the residuals stacked (the costs' order)
        self.contact = None  # the last calc's ContactWrench (None without a contact)
        self.contact_x = np.full(model.state.nx, np.nan)  # the state it was computed at
