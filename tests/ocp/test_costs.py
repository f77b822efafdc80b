"""The OCP's cost terms one by one (`uvms_pin.ocp.costs`): each residual's Jacobian R_x
against central differences of the residual along the tangent, anisotropic weights in the
action model's gradient, the joint-limit margin's wall where its definition puts it, and bad
weights refused.

(The action model's own NumDiff test, tests/ocp/test_ocp.py, compares only the gradient
l_x = R_x^T W r; for a rotation residual with the same weight on every axis
Jlog3^T log3 = log3, so a Jacobian without Jlog3 gives the same gradient there: these tests
check R_x itself.)
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, random_state

from uvms_pin.errors import ParameterError

pytest.importorskip("crocoddyl")

from uvms_pin.ocp import costs
from uvms_pin.ocp.model import UnderwaterActionModel


def _at(uvms, q, v):
    """A Pinocchio data at (q, v) as a node leaves it for its costs."""
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q, v)
    pin.computeJointJacobians(uvms.model, data, q)
    pin.updateFramePlacements(uvms.model, data)
    return data


def _terms(uvms, rng):
    """One of each state term, targets well away from the state (large residuals: a
    missing log Jacobian shows)."""
    target = pin.SE3(pin.exp3(np.array([0.9, -0.7, 1.1])), np.array([0.5, 0.1, -2.5]))
    x_ref = np.r_[uvms.neutral_configuration(), rng.normal(size=uvms.nv)]
    rotation = pin.exp3(np.array([-0.8, 1.0, 0.6]))
    return [
        costs.end_effector_pose(uvms, target, np.ones(6)),
        costs.vehicle_pose(uvms, target, np.ones(6)),
        costs.vehicle_attitude(uvms, rotation, np.ones(3)),
        costs.end_effector_attitude(uvms, rotation, np.ones(3)),
        costs.FramePosition(uvms.ee_frame_id, [0.3, 0.0, -3.0], np.ones(3)),
        costs.StateDeviation(uvms.model, x_ref, np.ones(2 * uvms.nv)),
    ]


def test_residual_jacobians_match_central_differences(reference_uvms):
    """R_x of the pose, attitude, position and state terms against 4-point central
    differences of r along the tangent (q (+) dq, v + dv)."""
    uvms, rng = reference_uvms, np.random.default_rng(11)
    model, nq, nv = reference_uvms.model, reference_uvms.nq, reference_uvms.nv
    u = np.zeros(nv)
    for _ in range(2):
        q, v, _ = random_state(uvms, rng)
        x = np.r_[q, v]

        def plus(x0, dx):
            return np.r_[pin.integrate(model, x0[:nq], dx[:nv]), x0[nq:] + dx[nv:]]

        for term in _terms(uvms, rng):

            def residual(xx, term=term):
                return term.residual(model, _at(uvms, xx[:nq], xx[nq:]), xx, u)

            rx, ru = term.jacobians(model, _at(uvms, q, v), x, u)
            expected = central_difference(residual, x, 2 * nv, 1e-5, plus=plus)
            error = np.abs(rx - expected).max() / max(1.0, np.abs(expected).max())
            assert error < 1e-7, f"{term.name}: {error}"
            assert np.all(ru == 0.0)


def test_joint_limit_margin_walls_are_inside_the_limits(reference_uvms):
    """The margin's wall is m inside each limit (every one-DoF arm joint counted): zero
    residual inside [lo + m, hi - m], q - (hi - m) past the upper wall, q - (lo + m) past
    the lower one, and R_q 1 on the joint's velocity column exactly there."""
    model, margin = reference_uvms.model, 0.1
    term = costs.JointLimitMargin(model, margin, 1.0)
    arm = [j for j in range(2, model.njoints) if model.nvs[j] == 1]
    assert term.nr == len(arm) > 0
    lower = np.array([model.lowerPositionLimit[model.idx_qs[j]] for j in arm])
    upper = np.array([model.upperPositionLimit[model.idx_qs[j]] for j in arm])
    q = reference_uvms.neutral_configuration()
    index = [model.idx_qs[j] for j in arm]
    depth = 0.5 * margin
    q[index[0]] = upper[0] - depth  # inside the limit, past the wall
    q[index[-1]] = lower[-1] + depth
    x = np.r_[q, np.zeros(model.nv)]
    r = term.residual(model, None, x, np.zeros(model.nv))
    expected = np.zeros(term.nr)
    expected[0], expected[-1] = margin - depth, -(margin - depth)
    np.testing.assert_allclose(r, expected, rtol=0, atol=1e-12)
    rx, _ = term.jacobians(model, None, x, np.zeros(model.nv))
    assert rx[0, model.idx_vs[arm[0]]] == 1.0 and rx[-1, model.idx_vs[arm[-1]]] == 1.0
    assert np.count_nonzero(rx) == 2


@pytest.mark.parametrize("weights", [[1.0, -1.0, 1.0], [1.0, np.nan, 1.0], [1.0, np.inf, 1.0]])
def test_negative_or_non_finite_weights_are_refused(weights):
    with pytest.raises(ParameterError, match="weights >= 0"):
        costs.FramePosition(0, np.zeros(3), weights)


class _Coupled(costs.CostTerm):
    """r = A dx + B u (a user's term of both the state and the input): R_x = A, R_u = B."""

    def __init__(self, nv, nu, rng):
        super().__init__(rng.uniform(0.5, 2.0, size=4), 4, "coupled")
        self.a, self.b = rng.normal(size=(4, 2 * nv)), rng.normal(size=(4, nu))

    def residual(self, model, data, x, u, contact=None):
        return self.a[:, model.nv :] @ x[model.nq :] + self.b @ u

    def jacobians(self, model, data, x, u, contact=None):
        rx = self.a.copy()
        rx[:, : model.nv] = 0.0
        return rx, self.b


def test_the_gauss_newton_blocks_of_a_term_of_state_and_input(reference_uvms):
    """l_xx, l_uu, l_xu of the action model are R^T (s W) R of the stacked terms, the cross
    block l_xu included (zero for every shipped term; not for a user's term coupling x and u)."""
    uvms, rng = reference_uvms, np.random.default_rng(12)
    nv = uvms.nv
    coupled = _Coupled(nv, nv, rng)
    model = UnderwaterActionModel(uvms, [(coupled, 0.7), (costs.Effort(np.ones(nv)), 1e-2)])
    data = model.createData()
    q, v, _ = random_state(uvms, rng)
    x, u = np.r_[q, v], rng.normal(size=nv)
    model.calc(data, x, u)
    model.calcDiff(data, x, u)
    rx, ru = coupled.jacobians(uvms.model, None, x, u)
    w = 0.7 * coupled.weights[:, None]
    np.testing.assert_allclose(data.Lxu, rx.T @ (w * ru), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(data.Lxx, rx.T @ (w * rx), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(data.Luu, ru.T @ (w * ru) + 1e-2 * np.eye(nv), rtol=1e-12)
    assert np.abs(data.Lxu).max() > 0.1


def test_each_residual_is_its_value_less_its_target_with_jacobians_of_its_size(reference_uvms):
    """r = 0 where the state meets the term's target (the frames' poses, attitude and
    position where they are, the state itself, the contact force f = f_d), and r = value -
    target: a target moved by d moves r by -d. R_x is (nr, 2 nv) and R_u (nr, nu) for
    every term, the contact force's and the joint-limit margin's included (the action
    model stacks them)."""
    from uvms_pin.physics.derivatives.task_contact import ContactJacobians, ContactWrench

    uvms, rng = reference_uvms, np.random.default_rng(13)
    model, nv = uvms.model, uvms.nv
    q, v, _ = random_state(uvms, rng)
    x, u, data = np.r_[q, v], np.zeros(nv), _at(uvms, q, v)
    ee, vehicle = uvms.ee_frame_id, costs.vehicle_frame_id(uvms)
    force = np.array([3.0, -1.0, 12.0])
    contact = ContactWrench(np.r_[force, 0.2, -0.1, 0.3], np.zeros(nv), np.zeros((6, nv)),
                            np.zeros(3), np.zeros(3))  # fmt: skip
    shift = np.array([0.2, -0.3, 0.5])
    at_target = [
        costs.FramePose(ee, data.oMf[ee], np.ones(6)),
        costs.FramePose(vehicle, data.oMf[vehicle], np.ones(6)),
        costs.FrameRotation(ee, data.oMf[ee].rotation, np.ones(3)),
        costs.FramePosition(ee, data.oMf[ee].translation, np.ones(3)),
        costs.StateDeviation(model, x, np.ones(2 * nv)),
        costs.ContactForce(force, np.ones(3)),
    ]
    for term in at_target:
        r = term.residual(model, data, x, u, contact)
        np.testing.assert_allclose(r, np.zeros(term.nr), atol=1e-12, err_msg=term.name)
    moved = costs.FramePosition(ee, data.oMf[ee].translation + shift, np.ones(3))
    np.testing.assert_allclose(moved.residual(model, data, x, u), -shift, atol=1e-12)
    pushed = costs.ContactForce(force + shift, np.ones(3))
    np.testing.assert_allclose(pushed.residual(model, data, x, u, contact), -shift, atol=1e-12)
    derivatives = ContactJacobians(rng.normal(size=(6, nv)), rng.normal(size=(6, nv)),
                                   np.zeros((nv, nv)), np.zeros((nv, nv)))  # fmt: skip
    terms = [*at_target, costs.Effort(np.ones(nv)), costs.JointLimitMargin(model, 0.1, 1.0)]
    for term in terms:
        rx, ru = term.jacobians(model, data, x, u, derivatives)
        assert rx.shape == (term.nr, 2 * nv) and ru.shape == (term.nr, nv), term.name
