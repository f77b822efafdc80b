"""The end-effector contact's generalized force and its derivatives against central finite
differences (the 4-point rule, relative 1e-6), for the contact models the scenarios use."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference

from uvms_pin.errors import ParameterError
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring
from uvms_pin.physics.derivatives.task_contact import (
    TaskContact,
    contact_derivatives,
    contact_wrench,
    projection_dq,
    supports_mask,
)

REL = 1e-6


def _state(uvms, rng):
    q = uvms.neutral_configuration()
    q[:3] = [0.1, -0.2, -2.0]
    q[3:7] = pin.Quaternion(pin.exp3(rng.normal(scale=0.3, size=3))).coeffs()
    q[7:] = np.array([-0.2, 1.0, -0.8, 0.2]) + rng.uniform(-0.3, 0.3, size=uvms.nv - 6)
    return q, rng.normal(scale=0.3, size=uvms.nv)


def _tip(uvms, q):
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q)
    return data.oMf[uvms.ee_frame_id].translation.copy()


def _contacts(tip):
    """The scenarios' models, placed so that the tip is inside them (in contact)."""
    normal = np.array([-1.0, 0.3, 0.2])
    normal /= np.linalg.norm(normal)
    return {
        "spring": LinearSpring(np.array([2.0, 3.0, 5.0]), tip - [0.2, -0.1, 0.05]),
        "plane (spring)": CompliantPlane(normal, 400.0, 0.0, tip + 0.05 * normal),
        "plane (spring-damper)": CompliantPlane(normal, 400.0, 10.0, tip + 0.05 * normal),
    }


def _relative_error(actual, expected):
    return np.abs(actual - expected).max() / np.abs(expected).max()


@pytest.mark.parametrize("kind", ["spring", "plane (spring)", "plane (spring-damper)"])
def test_contact_derivatives_match_central_differences(reference_uvms, kind):
    """d lambda/dq, d lambda/dv, d tau_ext/dq (the projection J^T moving with q included),
    d tau_ext/dv at random states in contact, against central differences along the
    tangent (q (+) dq with pin.integrate)."""
    uvms = reference_uvms
    model, data = uvms.model, uvms.model.createData()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, v = _state(uvms, rng)
        contact = TaskContact(uvms.ee_frame_id, _contacts(_tip(uvms, q))[kind])
        state, jac = contact_derivatives(contact, model, data, q, v)
        assert np.linalg.norm(state.wrench_world[:3]) > 0.1  # in contact, pushing

        def at(q_, v_, contact=contact):
            out = contact_wrench(contact, model, model.createData(), q_, v_)
            return np.r_[out.wrench_world, out.tau_ext]

        def plus(q_, dq):
            return pin.integrate(model, q_, dq)

        by_q = central_difference(lambda q_, v=v: at(q_, v), q, uvms.nv, 1e-5, plus)
        by_v = central_difference(lambda v_, q=q: at(q, v_), v, uvms.nv, 1e-5)
        assert _relative_error(jac.wrench_dq, by_q[:6]) < REL
        assert _relative_error(jac.tau_dq, by_q[6:]) < REL
        if kind == "plane (spring-damper)":
            assert _relative_error(jac.wrench_dv, by_v[:6]) < REL
            assert _relative_error(jac.tau_dv, by_v[6:]) < REL
        else:  # no damping: the force does not depend on v
            for block in (jac.wrench_dv, jac.tau_dv, by_v):
                np.testing.assert_array_equal(block, 0.0)


def test_the_projection_term_alone_with_a_moment(reference_uvms):
    """d(J_W^T F)/dq for a fixed world wrench with force AND moment (the part the contact
    models exercise only with a zero moment), against central differences."""
    uvms = reference_uvms
    model, data = uvms.model, uvms.model.createData()
    rng = np.random.default_rng(4)
    q, _ = _state(uvms, rng)
    wrench = rng.normal(size=6)
    fid = uvms.ee_frame_id

    def projected(q_):
        jac = pin.computeFrameJacobian(model, model.createData(), q_, fid, pin.WORLD)
        return jac.T @ wrench

    pin.computeJointJacobians(model, data, q)
    jac_world = pin.getFrameJacobian(model, data, fid, pin.WORLD)
    got = projection_dq(jac_world, wrench, supports_mask(model))
    expected = central_difference(
        projected, q, uvms.nv, 1e-5, lambda q_, d: pin.integrate(model, q_, d)
    )
    assert _relative_error(got, expected) < REL


def test_a_plane_left_behind_gives_no_force_and_no_derivative(reference_uvms):
    uvms = reference_uvms
    q, v = _state(uvms, np.random.default_rng(5))
    tip = _tip(uvms, q)
    plane = CompliantPlane(
        np.array([-1.0, 0.0, 0.0]), 400.0, 30.0, tip + np.array([0.05, 0.0, 0.0])
    )
    state, jac = contact_derivatives(
        TaskContact(uvms.ee_frame_id, plane), uvms.model, uvms.model.createData(), q, v
    )
    np.testing.assert_array_equal(state.wrench_world, 0.0)
    for block in (jac.wrench_dq, jac.wrench_dv, jac.tau_dq, jac.tau_dv):
        np.testing.assert_array_equal(block, 0.0)


def test_a_contact_model_without_derivatives_is_refused(reference_uvms):
    class Magnet(ContactModel):
        def wrench_on_environment_world(self, position_world_m, velocity_world_m_s):
            return np.zeros(6)

    with pytest.raises(ParameterError, match="Magnet"):
        TaskContact(reference_uvms.ee_frame_id, Magnet())
