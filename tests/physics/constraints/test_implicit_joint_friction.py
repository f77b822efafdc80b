"""Joint Coulomb friction solved implicitly (`uvms_pin.physics.constraints.joint_friction`):
a hinge held by a torque below its friction stands exactly still, above it accelerates at
(tau - c) / I, coasting stops in I v0 / c without turning back; it never adds energy."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.step import constrained_velocity

COULOMB_NM, PERIOD_S = 2.0, 2e-3
STILL_RAD_S = 1e-7  # standing still, to the solver's tolerance (1e-8 relative)


@pytest.fixture(scope="module")
def hinge():
    """One revolute joint about the vertical (gravity has no torque on it), in air."""
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "hinge")
    inertia = pin.Inertia(2.0, np.array([0.3, 0.0, 0.0]), np.eye(3) * 0.01)
    model.appendBodyToJoint(joint, inertia, pin.SE3.Identity())
    return model


def _turn(model, tau_Nm: float, v0: float, periods: int) -> np.ndarray:
    """The hinge's velocity after each period [rad/s]."""
    friction = JointCoulombFriction((1,), np.array([COULOMB_NM]))
    data = model.createData()
    q, v, out = pin.neutral(model), np.array([v0]), []
    for _ in range(periods):
        v_free = v + PERIOD_S * pin.aba(model, data, q, v, np.array([tau_Nm]))
        mass = pin.crba(model, data, q)
        step = constrained_velocity(model, mass, v_free, q, [friction], PERIOD_S)
        assert step.converged
        assert step.velocity @ mass @ step.velocity <= v_free @ mass @ v_free + 1e-12
        assert abs(step.impulses["joint_friction"][0]) <= COULOMB_NM * PERIOD_S * (1 + 1e-9)
        v = step.velocity
        q = pin.integrate(model, q, PERIOD_S * v)
        out.append(v[0])
    return np.array(out)


def _inertia(model) -> float:
    return float(pin.crba(model, model.createData(), pin.neutral(model))[0, 0])


def test_below_the_friction_it_sticks(hinge):
    assert np.abs(_turn(hinge, 1.5, 0.0, 100)).max() < STILL_RAD_S


def test_above_the_friction_it_accelerates_by_the_difference(hinge):
    velocity = _turn(hinge, 3.0, 0.0, 100)
    expected = 100 * PERIOD_S * (3.0 - COULOMB_NM) / _inertia(hinge)
    assert velocity[-1] == pytest.approx(expected, rel=1e-6)


def test_coasting_it_stops_without_turning_back(hinge):
    v0 = 1.0
    velocity = _turn(hinge, 0.0, v0, 100)
    stop_s = _inertia(hinge) * v0 / COULOMB_NM  # 0.095 s
    stopped = np.flatnonzero(np.abs(velocity) < STILL_RAD_S)
    assert velocity.min() > -STILL_RAD_S
    assert np.all(np.abs(velocity[stopped[0] :]) < STILL_RAD_S)
    assert (stopped[0] + 1) * PERIOD_S == pytest.approx(stop_s, abs=PERIOD_S)


def test_refusals():
    with pytest.raises(ParameterError, match="one Coulomb friction per joint"):
        JointCoulombFriction((1, 2), np.array([1.0]))
    with pytest.raises(ParameterError, match=">= 0"):
        JointCoulombFriction((1,), np.array([-1.0]))
    with pytest.raises(ParameterError, match="increasing"):
        JointCoulombFriction((2, 1), np.array([1.0, 1.0]))
