"""Prescribed-arm dynamics: consistent with the full forward dynamics; settles where G is under B."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.apps.validation.identify import quasi_static_roll_pitch
from uvms_pin.apps.validation.pool import trial_uvms
from uvms_pin.apps.validation.prescribed import (
    JointTrajectory,
    low_pass,
    simulate_prescribed_arm,
    vehicle_acceleration,
)
from uvms_pin.apps.validation.trials import roll_pitch_rad
from uvms_pin.errors import ParameterError


@pytest.fixture(scope="module")
def uvms():
    return trial_uvms()


def test_vehicle_rows_match_forward_dynamics_with_the_imposing_torques(uvms):
    """tau_arm = (M [a_v; qdd] + h)_arm, then forward_dynamics(tau = [0; tau_arm]) = [a_v; qdd]."""
    rng = np.random.default_rng(12)
    q = pin.randomConfiguration(uvms.model, -np.ones(uvms.nq), np.ones(uvms.nq))
    q[7:] = np.clip(q[7:], uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:])
    v = rng.normal(scale=0.3, size=uvms.nv)
    qdd = rng.normal(size=uvms.n_arm_joints)
    a_v = vehicle_acceleration(uvms, q[:7], v[:6], (q[7:], v[6:], qdd))
    acc = np.concatenate([a_v, qdd])
    tau = up.mass_matrix(uvms, q) @ acc + up.bias_forces(uvms, q, v)
    np.testing.assert_allclose(tau[:6], 0.0, atol=1e-10)
    tau[:6] = 0.0
    np.testing.assert_allclose(up.forward_dynamics(uvms, q, v, tau), acc, rtol=1e-9, atol=1e-9)


def test_low_pass_keeps_slow_motion_and_removes_jitter():
    t = np.arange(0.0, 20.0, 1.0 / 54.0)  # the encoders' rate
    slow = np.sin(2 * np.pi * 0.1 * t)
    grid, filtered = low_pass(t, slow + 0.05 * np.sin(2 * np.pi * 12.0 * t), 2.0, 0.01)
    inner = (grid > 2.0) & (grid < 18.0)  # away from the ends' transients
    np.testing.assert_allclose(filtered[inner], np.sin(2 * np.pi * 0.1 * grid[inner]), atol=2e-3)


def test_arm_held_still_vehicle_settles_with_g_below_b(uvms):
    """From 8 deg of roll and pitch, the damped free vehicle comes to rest with the system's
    centre of gravity vertically under its centre of buoyancy (zero restoring moment)."""

    def damped(body):
        p = body.params
        if body.name != "base_link":
            return p
        return dataclasses.replace(p, linear_damping=p.linear_damping + np.diag([0, 0, 0, 2, 2, 2]))

    model = uvms.with_hydro(damped)
    q_arm = np.array([0.3, 1.2, 1.5, 0.0])
    times = np.linspace(0.0, 40.0, 9)
    arm = JointTrajectory.from_samples(times, np.tile(q_arm, (len(times), 1)))
    tilt = pin.Quaternion(pin.rpy.rpyToMatrix(0.14, 0.14, 0.0)).coeffs()
    q0 = np.concatenate([[0, 0, 0], tilt])
    q_vehicle, nu = simulate_prescribed_arm(model, arm, q0, np.zeros(6), times, step_s=0.05)
    assert np.max(np.abs(nu[-1][3:])) < 1e-4  # at rest
    q = np.concatenate([q_vehicle[-1], q_arm])
    data = model.model.createData()
    com = pin.centerOfMass(model.model, data, q)
    cob = (
        sum(
            model.volume_per_joint_m3[j] * data.oMi[j].act(model.center_of_buoyancy_per_joint_m[j])
            for j in model.joints_with_volume
        )
        / model.volume_m3
    )
    np.testing.assert_allclose(com[:2], cob[:2], atol=2e-5)
    assert cob[2] > com[2]  # stable: B above G
    # the quasi-static solver of the identification finds the same attitude
    settled = roll_pitch_rad(q_vehicle[-1:, 3:7])[0]
    found = quasi_static_roll_pitch(model, q_arm, np.zeros(2))
    np.testing.assert_allclose(found, settled, atol=2e-5)


def test_times_outside_the_trajectory_are_refused(uvms):
    times = np.linspace(0.0, 2.0, 5)
    arm = JointTrajectory.from_samples(times, np.zeros((5, 4)))
    q0 = np.r_[0, 0, 0, 0, 0, 0, 1.0]
    with pytest.raises(ParameterError, match="leave the arm trajectory's span"):
        simulate_prescribed_arm(uvms, arm, q0, np.zeros(6), np.array([0.0, 3.0]))
