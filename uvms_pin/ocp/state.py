"""The state manifold of a UVMS for crocoddyl: x = (q, v), tangent dx = (dq, dv), 2 nv.

x (+) dx = (q (+) dq, v + dv) and x1 (-) x0 = (q1 (-) q0, v1 - v0) by Pinocchio's
integrate / difference (a continuous joint's angle by atan2: `UvmsState.diff`), with their
exact Jacobians (dIntegrate, dDifference) and the parallel
transport crocoddyl's solvers use.

Why not crocoddyl's own `StateMultibody`: the crocoddyl 3.2.1 wheels on PyPI are built
against a libpinocchio whose Model / Data layout differs from pin 4.1's (same unversioned
shared library name): `StateMultibody(model).diff` and the multibody residuals return NaN or
garbage beside pin 4.1 (tests/ocp/test_ocp.py checks this state against Pinocchio instead).
Everything uvms_pin.ocp gives crocoddyl is therefore on its abstract interfaces, computed
with the Python Pinocchio this package uses.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.ocp.crocoddyl_module import crocoddyl_module

crocoddyl = crocoddyl_module()


class UvmsState(crocoddyl.StateAbstract):
    """The state manifold of ``model`` (a Pinocchio model, e.g. ``uvms.model``); ``seed``:
    of `rand` (crocoddyl's interface), a state about the neutral one."""

    def __init__(self, model: pin.Model, seed: int = 0):
        crocoddyl.StateAbstract.__init__(self, model.nq + model.nv, 2 * model.nv)
        self.model = model
        self._rng = np.random.default_rng(seed)
        # [[J_q, 0], [0, +-I]]: the blocks of every Jacobian, the velocity part set once
        nv = model.nv
        self._plus, self._minus = np.zeros((2 * nv, 2 * nv)), np.zeros((2 * nv, 2 * nv))
        self._plus[nv:, nv:], self._minus[nv:, nv:] = np.eye(nv), -np.eye(nv)
        # continuous joints (q = cos, sin; one velocity): their q and v indices
        circles = [j for j in range(1, model.njoints) if (model.nqs[j], model.nvs[j]) == (2, 1)]
        self._circle_q = np.array([model.idx_qs[j] for j in circles], dtype=int)
        self._circle_v = np.array([model.idx_vs[j] for j in circles], dtype=int)

    def _split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return x[: self.model.nq], x[self.model.nq :]

    def zero(self) -> np.ndarray:
        return np.r_[pin.neutral(self.model), np.zeros(self.model.nv)]

    def rand(self) -> np.ndarray:
        tangent = self._rng.uniform(-1.0, 1.0, size=self.model.nv)
        q = pin.integrate(self.model, pin.neutral(self.model), tangent)
        return np.r_[q, self._rng.normal(size=self.model.nv)]

    def diff(self, x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
        model = self.model
        nq = model.nq
        dq = pin.difference(model, x0[:nq], x1[:nq])
        if self._circle_v.size:
            dq[self._circle_v] = self._circle_angles(x0, x1)
        return np.concatenate((dq, x1[nq:] - x0[nq:]))

    def _circle_angles(self, x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
        """The continuous joints' angles from x0 to x1 [rad], atan2(c0 s1 - s0 c1,
        c0 c1 + s0 s1): exact down to the rounding of cos and sin, where Pinocchio 4.1's
        difference returns 0 for about 1 % of steps below 1e-8 rad (its SO(2) log rounds a
        trace just above 2 to the identity) and crocoddyl's NumDiff steps by ~1.5e-8."""
        c0, s0 = x0[self._circle_q], x0[self._circle_q + 1]
        c1, s1 = x1[self._circle_q], x1[self._circle_q + 1]
        return np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)

    def integrate(self, x: np.ndarray, dx: np.ndarray) -> np.ndarray:
        model = self.model
        nq, nv = model.nq, model.nv
        return np.concatenate((pin.integrate(model, x[:nq], dx[:nv]), x[nq:] + dx[nv:]))

    def _block(self, jq: np.ndarray, sign: float = 1.0) -> np.ndarray:
        out = (self._plus if sign > 0.0 else self._minus).copy()
        out[: self.model.nv, : self.model.nv] = jq
        return out

    def Jdiff(self, x0, x1, firstsecond=crocoddyl.Jcomponent.both):
        if firstsecond == crocoddyl.Jcomponent.both:
            return [
                self.Jdiff(x0, x1, crocoddyl.Jcomponent.first),
                self.Jdiff(x0, x1, crocoddyl.Jcomponent.second),
            ]
        q0, q1 = self._split(x0)[0], self._split(x1)[0]
        if firstsecond == crocoddyl.Jcomponent.first:
            return self._block(pin.dDifference(self.model, q0, q1, pin.ARG0), -1.0)
        return self._block(pin.dDifference(self.model, q0, q1, pin.ARG1))

    def Jintegrate(self, x, dx, firstsecond=crocoddyl.Jcomponent.both):
        if firstsecond == crocoddyl.Jcomponent.both:
            return [
                self.Jintegrate(x, dx, crocoddyl.Jcomponent.first),
                self.Jintegrate(x, dx, crocoddyl.Jcomponent.second),
            ]
        q, nv = self._split(x)[0], self.model.nv
        arg = pin.ARG0 if firstsecond == crocoddyl.Jcomponent.first else pin.ARG1
        return self._block(pin.dIntegrate(self.model, q, dx[:nv], arg))

    def JintegrateTransport(self, x, dx, Jin, firstsecond):
        q, nv = self._split(x)[0], self.model.nv
        arg = pin.ARG0 if firstsecond == crocoddyl.Jcomponent.first else pin.ARG1
        out = np.array(Jin, dtype=float)
        out[:nv] = pin.dIntegrateTransport(self.model, q, dx[:nv], out[:nv], arg)
        return out
