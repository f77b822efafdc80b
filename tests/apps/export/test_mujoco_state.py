"""State and generalized-force conventions between uvms-pin and MuJoCo."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.apps.export.mujoco_state import (
    base_rotation,
    q_from_qpos,
    qfrc_from_tau,
    qpos_from_q,
    qvel_from_v,
    v_from_qvel,
)


def _random_state(rng: np.random.Generator, n_arm: int = 3) -> tuple[np.ndarray, np.ndarray]:
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    q = pin.randomConfiguration(model, -np.ones(7), np.ones(7))
    return np.concatenate([q, rng.normal(size=n_arm)]), rng.normal(size=6 + n_arm)


def test_round_trips_are_exact():
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, v = _random_state(rng)
        qpos = qpos_from_q(q)
        assert qpos[3] == q[6] and np.array_equal(qpos[4:7], q[3:6])
        np.testing.assert_array_equal(q_from_qpos(qpos), q)
        np.testing.assert_allclose(v_from_qvel(qpos, qvel_from_v(q, v)), v, rtol=0, atol=1e-14)


def test_linear_velocity_is_rotated_to_the_world_frame():
    rng = np.random.default_rng(8)
    q, v = _random_state(rng)
    qvel = qvel_from_v(q, v)
    rotation = pin.XYZQUATToSE3(q[:7]).rotation
    np.testing.assert_allclose(qvel[:3], rotation @ v[:3], atol=1e-15)
    np.testing.assert_allclose(base_rotation(q), rotation, atol=1e-15)
    np.testing.assert_array_equal(qvel[3:], v[3:])


def test_generalized_forces_keep_the_power():
    rng = np.random.default_rng(9)
    for _ in range(5):
        q, v = _random_state(rng)
        tau = rng.normal(size=v.size)
        power_pin = tau @ v
        power_mujoco = qfrc_from_tau(q, tau) @ qvel_from_v(q, v)
        assert abs(power_pin - power_mujoco) < 1e-13 * max(1.0, abs(power_pin))
