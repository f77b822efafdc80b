"""The UVMS in water as a crocoddyl differential action model.

State x = (q, v) on the configuration manifold (`uvms_pin.ocp.state.UvmsState`: free-flyer
SE(3) x joints), control u = the actuators' inputs, tau = B_u u (B_u the identity: u is the
generalized force; or `uvms_pin.physics.discrete.input_matrix`: u = thrust forces [N] and
joint torques [N m]). The dynamics are uvms-pin's underwater forward dynamics; calcDiff gives
their analytical derivatives along the tangent,

    Fx = [da/dq, da/dv],     Fu = da/dtau B_u,

and the Gauss-Newton derivatives of the cost terms (`uvms_pin.ocp.costs`). Bounds on u
(thrust and effort limits) go to crocoddyl's box-constrained solvers through ``u_lb`` /
``u_ub``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp.costs import CostTerm
from uvms_pin.ocp.crocoddyl_module import crocoddyl_module
from uvms_pin.ocp.state import UvmsState
from uvms_pin.physics.dynamics import forward_dynamics, forward_dynamics_derivatives

crocoddyl = crocoddyl_module()

WeightedTerms = Sequence[tuple[CostTerm, float]]
"""The cost of a node: (term, scale) pairs, l = sum_i scale_i (1/2) r_i^T W_i r_i."""


class UnderwaterActionModel(crocoddyl.DifferentialActionModelAbstract):
    """M(q) a + h(q, v) = B_u u, the water included, with a sum of cost terms.

    Args:
        uvms: the model. terms: the node's cost, (term, scale) pairs.
        input_matrix_: B_u (nv, nu); None: the identity (u = tau).
        flow, time_s: the water (a `uvms_pin.flow.FlowField`, None: still) and the time the
            flow is frozen at [s] (one model per node for a moving flow).
        u_bounds: (lower, upper) (nu,) each, or None for none.
        backend: "core" (compiled) or "python" (the reference).
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
    ):
        b_u = np.eye(uvms.nv) if input_matrix_ is None else np.asarray(input_matrix_, float)
        if b_u.ndim != 2 or b_u.shape[0] != uvms.nv:
            raise ParameterError(f"input_matrix_ must be (nv={uvms.nv}, nu), got {b_u.shape}")
        nr = sum(term.nr for term, _ in terms)
        crocoddyl.DifferentialActionModelAbstract.__init__(
            self, UvmsState(uvms.model), b_u.shape[1], nr
        )
        self.uvms, self.terms, self.input_matrix = uvms, list(terms), b_u
        self.water = {"flow": flow, "time_s": float(time_s), "backend": backend}
        if u_bounds is not None:
            lower, upper = (np.asarray(b, float).reshape(-1) for b in u_bounds)
            if lower.shape != (self.nu,) or upper.shape != (self.nu,) or np.any(lower > upper):
                raise ParameterError(f"u_bounds: two (nu={self.nu},) arrays, lower <= upper")
            self.u_lb, self.u_ub = lower, upper

    def _split(self, x: np.ndarray, u: np.ndarray | None):
        nq = self.uvms.nq
        u = np.zeros(self.nu) if u is None else np.asarray(u)
        return x[:nq], x[nq:], u

    def calc(self, data, x, u=None):
        q, v, u = self._split(x, u)
        data.xout[:] = forward_dynamics(self.uvms, q, v, self.input_matrix @ u, **self.water)
        model, pdata = self.uvms.model, data.pinocchio
        pin.forwardKinematics(model, pdata, q, v)
        pin.updateFramePlacements(model, pdata)
        data.residuals = [term.residual(model, pdata, x, u) for term, _ in self.terms]
        data.cost = sum(
            0.5 * scale * float(r @ (term.weights * r))
            for (term, scale), r in zip(self.terms, data.residuals, strict=True)
        )

    def calcDiff(self, data, x, u=None):
        q, v, u = self._split(x, u)
        nv = self.uvms.nv
        da_dq, da_dv, da_dtau = forward_dynamics_derivatives(
            self.uvms, q, v, self.input_matrix @ u, **self.water
        )
        data.Fx[:, :nv], data.Fx[:, nv:] = da_dq, da_dv
        data.Fu[:, :] = da_dtau @ self.input_matrix
        self._cost_derivatives(data, x, u)

    def _cost_derivatives(self, data, x, u) -> None:
        """Gauss-Newton: l_x = R_x^T W r, l_xx = R_x^T W R_x (likewise u, xu), summed."""
        model, pdata = self.uvms.model, data.pinocchio
        pin.computeJointJacobians(model, pdata, x[: model.nq])
        nx, nu = 2 * model.nv, self.nu
        lx, lu = np.zeros(nx), np.zeros(nu)
        lxx, luu, lxu = np.zeros((nx, nx)), np.zeros((nu, nu)), np.zeros((nx, nu))
        for (term, scale), r in zip(self.terms, data.residuals, strict=True):
            rx, ru = term.jacobians(model, pdata, x, u)
            w = scale * term.weights
            lx += rx.T @ (w * r)
            lu += ru.T @ (w * r)
            lxx += rx.T @ (w[:, None] * rx)
            luu += ru.T @ (w[:, None] * ru)
            lxu += rx.T @ (w[:, None] * ru)
        data.Lx[:], data.Lu[:] = lx, lu
        data.Lxx[:, :], data.Luu[:, :], data.Lxu[:, :] = lxx, luu, lxu

    def createData(self):
        return UnderwaterActionData(self)


class UnderwaterActionData(crocoddyl.DifferentialActionDataAbstract):
    """The model's buffers: crocoddyl's, a Pinocchio data and the last residuals."""

    def __init__(self, model: UnderwaterActionModel):
        crocoddyl.DifferentialActionDataAbstract.__init__(self, model)
        self.pinocchio = model.uvms.model.createData()
        self.residuals: list[np.ndarray] = []
