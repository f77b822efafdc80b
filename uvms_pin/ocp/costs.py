"""The cost terms of an underwater OCP: weighted least squares of residuals of the state.

Each term is  l = (1/2) r^T W r  (W = diag(weights)) of a residual r(x, u) with its
Jacobians R_x (over the tangent dx = (dq, dv)) and R_u; the action model sums the terms and
their Gauss-Newton derivatives  l_x = R_x^T W r,  l_xx = R_x^T W R_x  (likewise u, xu).
Frame Jacobians are Pinocchio's LOCAL ones (`pin.getFrameJacobian`) at the node's state,
after `pin.computeJointJacobians` and `pin.updateFramePlacements` in the node's data.

    frame pose         r = log6(T_target^-1 T_f)         R_q = Jlog6 J_f          (6)
    frame rotation     r = log3(R_target^T R_f)          R_q = Jlog3 J_f^w        (3)
    frame position     r = p_f - p_target [m]            R_q = R_f J_f^v          (3)
    effort             r = u (thrust [N], torque [N m])  R_u = I                  (nu)
    state              r = (q (-) q_ref, v - v_ref)      R_q = dDifference, R_v = I
    contact force      r = f - f_d [N]                   R_x = [df/dq, df/dv]     (3)
    joint limits       r = q_j - clip(q_j, lo_j, hi_j)   R_q = 1 outside, else 0  (n)

The contact force f = lambda[:3] is the end-effector's push on its environment (world axes)
in a node whose dynamics hold a contact (`uvms_pin.ocp.model.UnderwaterActionModel` with
``contact``): the terms receive the node's `ContactWrench` (in ``residual``) and its
`ContactJacobians` (in ``jacobians``), `uvms_pin.physics.derivatives.task_contact`; None in a
node without a contact, where a term that needs one (``needs_contact``) is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.derivatives.task_contact import ContactJacobians, ContactWrench


def vehicle_frame_id(uvms: UVMS) -> int:
    """The Pinocchio frame of the vehicle's body (the first body frame on joint 1)."""
    for k, frame in enumerate(uvms.model.frames):
        if frame.parentJoint == 1 and frame.type == pin.FrameType.BODY:
            return k
    raise ParameterError(f"model '{uvms.model.name}' has no body frame on its vehicle joint")


class CostTerm:
    """(1/2) r^T W r of one residual; subclasses give r and its Jacobians. ``needs_contact``:
    the residual is of the contact (a node without one refuses the term)."""

    needs_contact = False

    def __init__(self, weights, size: int, name: str):
        weights = np.asarray(weights, dtype=float).reshape(-1)
        if (
            weights.shape != (size,)
            or np.any(~(weights >= 0.0))
            or not np.all(np.isfinite(weights))
        ):
            raise ParameterError(f"cost '{name}': {size} finite weights >= 0 needed, got {weights}")
        self.weights, self.nr, self.name = weights, size, name

    def residual(
        self,
        model: pin.Model,
        data: pin.Data,
        x: np.ndarray,
        u: np.ndarray,
        contact: ContactWrench | None = None,
    ) -> np.ndarray:
        """r (nr,) at (x, u); ``contact``: the node's contact at x (None: none)."""
        raise NotImplementedError

    def jacobians(
        self,
        model: pin.Model,
        data: pin.Data,
        x: np.ndarray,
        u: np.ndarray,
        contact: ContactJacobians | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(R_x (nr, 2 nv), R_u (nr, nu)); ``contact``: the node's contact derivatives."""
        raise NotImplementedError


@dataclass(frozen=True)
class _Frame:
    frame_id: int

    def jacobian(self, model: pin.Model, data: pin.Data) -> np.ndarray:
        return pin.getFrameJacobian(model, data, self.frame_id, pin.LOCAL)


def _state_jacobian(jq: np.ndarray, nv: int, nu: int) -> tuple[np.ndarray, np.ndarray]:
    rx = np.zeros((jq.shape[0], 2 * nv))
    rx[:, :nv] = jq
    return rx, np.zeros((jq.shape[0], nu))


class FramePose(CostTerm):
    """(1/2)||log6(T_target^-1 T_f)||^2_W: W over (position [m], rotation [rad])."""

    def __init__(self, frame_id: int, target: pin.SE3, weights):
        super().__init__(weights, 6, "frame pose")
        self.frame, self.target_inverse = _Frame(frame_id), target.inverse()

    def _error(self, data: pin.Data) -> pin.SE3:
        return self.target_inverse * data.oMf[self.frame.frame_id]

    def residual(self, model, data, x, u, contact=None):
        return pin.log6(self._error(data)).vector

    def jacobians(self, model, data, x, u, contact=None):
        jq = pin.Jlog6(self._error(data)) @ self.frame.jacobian(model, data)
        return _state_jacobian(jq, model.nv, len(u))


class FrameRotation(CostTerm):
    """(1/2)||log3(R_target^T R_f)||^2_W [rad], e.g. the vehicle's attitude."""

    def __init__(self, frame_id: int, rotation: np.ndarray, weights):
        super().__init__(weights, 3, "frame rotation")
        self.frame, self.target_transposed = _Frame(frame_id), np.asarray(rotation, float).T

    def _error(self, data: pin.Data) -> np.ndarray:
        return self.target_transposed @ data.oMf[self.frame.frame_id].rotation

    def residual(self, model, data, x, u, contact=None):
        return pin.log3(self._error(data))

    def jacobians(self, model, data, x, u, contact=None):
        jq = pin.Jlog3(self._error(data)) @ self.frame.jacobian(model, data)[3:]
        return _state_jacobian(jq, model.nv, len(u))


class FramePosition(CostTerm):
    """(1/2)||p_f - p_target||^2_W [m], world axes."""

    def __init__(self, frame_id: int, target_m: np.ndarray, weights):
        super().__init__(weights, 3, "frame position")
        self.frame, self.target_m = _Frame(frame_id), np.asarray(target_m, float)

    def residual(self, model, data, x, u, contact=None):
        return data.oMf[self.frame.frame_id].translation - self.target_m

    def jacobians(self, model, data, x, u, contact=None):
        rotation = data.oMf[self.frame.frame_id].rotation
        jq = rotation @ self.frame.jacobian(model, data)[:3]
        return _state_jacobian(jq, model.nv, len(u))


class Effort(CostTerm):
    """(1/2)||u||^2_W: thrust forces [N] and joint torques [N m] (or tau)."""

    def __init__(self, weights):
        weights = np.asarray(weights, float).reshape(-1)
        super().__init__(weights, weights.size, "effort")

    def residual(self, model, data, x, u, contact=None):
        return np.asarray(u, float).copy()

    def jacobians(self, model, data, x, u, contact=None):
        return np.zeros((self.nr, 2 * model.nv)), np.eye(self.nr)


class StateDeviation(CostTerm):
    """(1/2)||x (-) x_ref||^2_W over the tangent (2 nv): (q (-) q_ref, v - v_ref)."""

    def __init__(self, model: pin.Model, x_ref: np.ndarray, weights):
        super().__init__(weights, 2 * model.nv, "state")
        x_ref = np.asarray(x_ref, float)
        if x_ref.shape != (model.nq + model.nv,):
            raise ParameterError(f"cost 'state': x_ref needs nq + nv = {model.nq + model.nv}")
        self.q_ref, self.v_ref = x_ref[: model.nq], x_ref[model.nq :]

    def residual(self, model, data, x, u, contact=None):
        nq = model.nq
        return np.concatenate((pin.difference(model, self.q_ref, x[:nq]), x[nq:] - self.v_ref))

    def jacobians(self, model, data, x, u, contact=None):
        nv = model.nv
        rx = np.zeros((2 * nv, 2 * nv))
        rx[:nv, :nv] = pin.dDifference(model, self.q_ref, x[: model.nq], pin.ARG1)
        rx[nv:, nv:] = np.eye(nv)
        return rx, np.zeros((2 * nv, len(u)))


class ContactForce(CostTerm):
    """(1/2)||f - f_d||^2_W: the contact force f [N] the end-effector exerts on its environment
    (world axes) against the desired one; ``target_N`` (f_d) may be moved between solves (a
    receding horizon's time-varying desired force). R_x = [df/dq, df/dv], the contact's
    derivatives (`uvms_pin.physics.derivatives.task_contact`); the weights of the directions
    the environment cannot push along (e.g. a plane's tangent) can be 0."""

    needs_contact = True

    def __init__(self, target_N, weights):
        super().__init__(weights, 3, "contact force")
        self.target_N = finite_vector("contact force target_N", target_N, 3)

    def residual(self, model, data, x, u, contact=None):
        return contact.wrench_world[:3] - self.target_N

    def jacobians(self, model, data, x, u, contact=None):
        return np.hstack([contact.wrench_dq[:3], contact.wrench_dv[:3]]), np.zeros((3, len(u)))


class JointLimitMargin(CostTerm):
    """(1/2)||q_j - clip(q_j, lo_j + m, hi_j - m)||^2_W [rad]: zero inside the one-DoF arm
    joints' limits less a margin m, growing past it (a soft wall the plan keeps off the
    stops; the plant's limits are not in the dynamics)."""

    def __init__(self, model: pin.Model, margin_rad: float, weight: float):
        joints = [j for j in range(2, model.njoints) if model.nqs[j] == model.nvs[j] == 1]
        super().__init__(np.full(len(joints), weight), len(joints), "joint limits")
        if not (margin_rad >= 0.0 and np.isfinite(margin_rad)):
            raise ParameterError(f"joint limits: margin_rad must be >= 0, got {margin_rad}")
        self.q_index = _indices([model.idx_qs[j] for j in joints])
        self.v_index = np.array([model.idx_vs[j] for j in joints], dtype=int)
        self.lower = model.lowerPositionLimit[self.q_index] + margin_rad
        self.upper = model.upperPositionLimit[self.q_index] - margin_rad

    def residual(self, model, data, x, u, contact=None):
        q = x[self.q_index]
        # np.clip's own definition, without its dispatch (a third of this term's time)
        return q - np.minimum(np.maximum(q, self.lower), self.upper)

    def jacobians(self, model, data, x, u, contact=None):
        q = x[self.q_index]
        rx = np.zeros((self.nr, 2 * model.nv))
        outside = (q < self.lower) | (q > self.upper)
        rx[np.arange(self.nr), self.v_index] = outside
        return rx, np.zeros((self.nr, len(u)))


def _indices(indices: list[int]) -> slice | np.ndarray:
    """A slice for consecutive indices (a view, cheaper than fancy indexing), else an array."""
    if indices and indices == list(range(indices[0], indices[0] + len(indices))):
        return slice(indices[0], indices[0] + len(indices))
    return np.array(indices, dtype=int)


def end_effector_pose(uvms: UVMS, target: pin.SE3, weights) -> FramePose:
    return FramePose(uvms.require_ee_frame("an end-effector pose cost"), target, weights)


def vehicle_pose(uvms: UVMS, target: pin.SE3, weights) -> FramePose:
    return FramePose(vehicle_frame_id(uvms), target, weights)


def vehicle_attitude(uvms: UVMS, rotation: np.ndarray, weights) -> FrameRotation:
    return FrameRotation(vehicle_frame_id(uvms), rotation, weights)


def end_effector_attitude(uvms: UVMS, rotation: np.ndarray, weights) -> FrameRotation:
    return FrameRotation(uvms.require_ee_frame("an end-effector attitude cost"), rotation, weights)
