"""The arm's joint limits solved implicitly (`uvms_pin.physics.constraints`): the shipped
BlueROV2 Heavy + Alpha 5 without its drives' armature (light links: the hard case), free and
driven by random joint torques, stays within its limits
(1e-6 rad) for 2,000 periods of 2 ms where the compliant stops at the same period diverge;
the impulses never add kinetic energy; the rows, their labels and the refusals."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import ALPHA5_URDF, without_drives

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.step import constrained_configuration, constrained_velocity
from uvms_pin.physics.joint_stops import JointStops

PERIOD_S = 2e-3
TORQUE_LIMIT_NM = np.array([9.0, 9.0, 9.0, 5.0])  # the Alpha 5's (scenario file)
START_RAD = [-0.2, 0.8, 2.2, 0.2]
DIVERGED = 1e4  # a velocity past this [rad/s, m/s] has diverged


@pytest.fixture(scope="module")
def alpha5(tmp_path_factory):
    """The BlueROV2 + Alpha 5 without its drives' armature: light arm links, stiff stops."""
    light = without_drives(ALPHA5_URDF, tmp_path_factory.mktemp("light_alpha5"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        return up.load_uvms(light)


def _start(uvms) -> tuple[np.ndarray, np.ndarray]:
    q = uvms.neutral_configuration()
    q[7:] = uvms.arm_joints.configuration(np.array(START_RAD))
    return q, np.zeros(uvms.nv)


def _torques(uvms, periods: int, hold: int = 50) -> np.ndarray:
    """Random joint torques within the Alpha 5's limits, each held ``hold`` periods."""
    rng = np.random.default_rng(2017)
    tau = np.zeros((periods, uvms.nv))
    for start in range(0, periods, hold):
        tau[start : start + hold, 6:] = rng.uniform(-1.0, 1.0, 4) * TORQUE_LIMIT_NM
    return tau


def _excursion_rad(uvms, q: np.ndarray) -> float:
    """How far the joints are past their limits at q [rad] (<= 0 inside)."""
    positions = uvms.arm_joints.positions(q)
    return float(
        np.max(np.maximum(positions - uvms.arm_joints.upper, uvms.arm_joints.lower - positions))
    )


def test_limits_hold_where_the_stops_diverge(alpha5):
    periods = 2000
    torques = _torques(alpha5, periods)
    limits = JointLimits.of_uvms(alpha5)
    q, v = _start(alpha5)
    worst_rad, pressed, iterations = -np.inf, 0, []
    for tau in torques:
        v_free = v + PERIOD_S * up.forward_dynamics(alpha5, q, v, tau)
        mass = up.mass_matrix(alpha5, q)
        step = constrained_velocity(alpha5.model, mass, v_free, q, [limits], PERIOD_S)
        assert step.converged
        v = step.velocity
        q = pin.integrate(alpha5.model, q, PERIOD_S * v)
        worst_rad = max(worst_rad, _excursion_rad(alpha5, q))
        pressed += bool(np.any(step.impulses["joint_limits"] > 1e-9))
        iterations.append(step.iterations)
    assert np.all(np.isfinite(q)) and np.abs(v).max() < DIVERGED
    assert worst_rad <= 1e-6
    assert pressed > 200  # the torques did drive the joints into their limits
    assert np.median(iterations) <= 20

    stops = JointStops.of_model(alpha5.model)
    q, v = _start(alpha5)
    for tau in torques:
        v = v + PERIOD_S * up.forward_dynamics(alpha5, q, v, tau + stops.torque(q, v))
        if not np.all(np.isfinite(v)) or np.abs(v).max() > DIVERGED:
            break
        q = pin.integrate(alpha5.model, q, PERIOD_S * v)
    assert not (np.all(np.isfinite(v)) and np.abs(v).max() < DIVERGED), "the stops did not diverge"


def test_impulses_never_add_kinetic_energy(alpha5):
    rng = np.random.default_rng(7)
    limits = JointLimits.of_uvms(alpha5)
    arm = alpha5.arm_joints
    active = 0
    for _ in range(200):
        positions = rng.uniform(arm.lower, arm.upper)
        at_limit = rng.random(4) < 0.3
        positions[at_limit] = np.where(rng.random(4) < 0.5, arm.lower, arm.upper)[at_limit]
        q = pin.integrate(alpha5.model, alpha5.neutral_configuration(), rng.normal(0, 0.3, 10))
        q[7:] = arm.configuration(positions)
        v_free = rng.normal(0.0, 1.0, alpha5.nv) * np.r_[[0.5] * 6, [20.0] * 4]
        mass = up.mass_matrix(alpha5, q)
        step = constrained_velocity(alpha5.model, mass, v_free, q, [limits], PERIOD_S)
        before, after = v_free @ mass @ v_free, step.velocity @ mass @ step.velocity
        assert after <= before + 1e-12
        active += bool(np.any(step.impulses["joint_limits"] > 0.0))
    assert active > 50


def test_the_step_is_the_impulse_through_the_mass(alpha5):
    limits = JointLimits.of_uvms(alpha5)
    q, _ = _start(alpha5)
    q[7:] = alpha5.arm_joints.configuration(np.array([3.0, 0.01, 3.45, 0.0]))
    v_free = np.r_[np.zeros(6), 50.0, -20.0, 30.0, -40.0]
    mass = up.mass_matrix(alpha5, q)
    step = constrained_velocity(alpha5.model, mass, v_free, q, [limits], PERIOD_S)
    (rows,) = step.rows
    impulse = step.impulses["joint_limits"]
    assert set(rows.labels) >= {"alpha_axis_d lower", "alpha_axis_e upper", "alpha_axis_c upper"}
    assert np.all(impulse >= 0.0) and impulse.max() > 0.1
    assert step.units["joint_limits"].startswith("N m s")
    np.testing.assert_allclose(step.generalized_impulse, rows.jacobian.T @ impulse, atol=1e-15)
    np.testing.assert_allclose(
        mass @ (step.velocity - v_free), step.generalized_impulse, rtol=1e-9, atol=1e-12
    )
    end_gap = rows.gap + PERIOD_S * rows.jacobian @ step.velocity
    assert end_gap.min() >= -1e-9  # each joint lands at its limit, not past it
    # the wrist, far from its limits and pushed by nothing, is still moved by the coupling
    assert step.velocity[9] != v_free[9]


def test_a_joint_past_its_limit_comes_back_by_the_correction(alpha5):
    limits = JointLimits.of_uvms(alpha5)
    q, v = _start(alpha5)
    q[7:] = alpha5.arm_joints.configuration(np.array([-0.2, -0.01, 2.2, 0.2]))  # 0.01 past
    mass = up.mass_matrix(alpha5, q)
    for beta in (0.2, 1.0):
        step = constrained_velocity(alpha5.model, mass, v, q, [limits], PERIOD_S, correction=beta)
        (rows,) = step.rows
        assert rows.labels == ("alpha_axis_d lower",) and rows.jacobian.shape == (1, alpha5.nv)
        assert step.velocity[7] * PERIOD_S == pytest.approx(beta * 0.01, rel=1e-5)


def test_refusals(alpha5):
    limits = JointLimits.of_uvms(alpha5)
    q, v = _start(alpha5)
    mass = up.mass_matrix(alpha5, q)
    model = alpha5.model
    with pytest.raises(ParameterError, match="v_free"):
        constrained_velocity(model, mass, v[:9], q, [limits], PERIOD_S)
    with pytest.raises(ParameterError, match="q must"):
        constrained_velocity(model, mass, v, q[:10], [limits], PERIOD_S)
    with pytest.raises(ParameterError, match="mass_matrix"):
        constrained_velocity(model, mass[:9], v, q, [limits], PERIOD_S)
    with pytest.raises(ParameterError, match="period_s"):
        constrained_velocity(model, mass, v, q, [limits], 0.0)
    for beta in (1.5, 0.0):  # beta in (0, 1]: 0 would never remove a penetration
        with pytest.raises(ParameterError, match="correction"):
            constrained_velocity(model, mass, v, q, [limits], PERIOD_S, correction=beta)
    with pytest.raises(ParameterError, match="own name"):
        constrained_velocity(model, mass, v, q, [limits, limits], PERIOD_S)
    with pytest.raises(ParameterError, match="one coordinate"):
        JointLimits((1,)).rows(model, model.createData(), q, np.abs(v), PERIOD_S)
    with pytest.raises(ParameterError, match="margin"):
        JointLimits((2,), margin=-1.0)
    # a joint whose one limit is Pinocchio's "none" (the largest double), or infinite
    for side, value in (("lower", -np.finfo(float).max), ("upper", np.inf), ("lower", -1e301)):
        open_ended = pin.Model(model)
        limits_of = getattr(open_ended, f"{side}PositionLimit").copy()
        limits_of[open_ended.joints[2].idx_q] = value
        setattr(open_ended, f"{side}PositionLimit", limits_of)
        name = open_ended.names[2]
        with pytest.raises(ParameterError, match=f"joint '{name}' has no finite position limits"):
            JointLimits((2,)).rows(open_ended, open_ended.createData(), q, np.abs(v), PERIOD_S)


@pytest.mark.parametrize("period_s", [2e-3, 5e-4])  # a period under 1 ms too
def test_without_rows_the_velocity_is_the_free_one(alpha5, period_s):
    """Nothing within reach: no solve, v+ = v_free, no impulse, nothing stalled."""
    q, _ = _start(alpha5)
    v_free = np.r_[np.zeros(6), 0.1, 0.1, 0.1, 0.1]
    mass = up.mass_matrix(alpha5, q)
    limits = JointLimits.of_uvms(alpha5)
    step = constrained_velocity(alpha5.model, mass, v_free, q, [limits], period_s)
    assert step.rows == () and step.iterations == 0
    assert (step.residual, step.converged, step.speed) == (0.0, True, 0.0)
    np.testing.assert_array_equal(step.velocity, v_free)
    np.testing.assert_array_equal(step.generalized_impulse, np.zeros(alpha5.nv))


def test_the_end_configuration_is_the_free_one_unless_rows_were_solved(alpha5):
    limits = JointLimits.of_uvms(alpha5)
    q, _ = _start(alpha5)
    q_free = q.copy()
    q_free[7:] += 1e-4  # what a higher-order step would reach, not q (+) h v_free
    mass = up.mass_matrix(alpha5, q)
    slow = np.r_[np.zeros(6), 0.1, 0.1, 0.1, 0.1]
    free_step = constrained_velocity(alpha5.model, mass, slow, q, [limits], PERIOD_S)
    end = constrained_configuration(alpha5.model, q, q_free, free_step, PERIOD_S)
    np.testing.assert_array_equal(end, q_free)
    hurled = np.r_[np.zeros(6), 0.0, -500.0, 0.0, 0.0]  # joint d, 0.8 rad from its limit
    stopped = constrained_velocity(alpha5.model, mass, hurled, q, [limits], PERIOD_S)
    end = constrained_configuration(alpha5.model, q, q_free, stopped, PERIOD_S)
    np.testing.assert_allclose(end, pin.integrate(alpha5.model, q, PERIOD_S * stopped.velocity))
    assert alpha5.arm_joints.positions(end)[1] == pytest.approx(0.0, abs=1e-9)


def test_a_limit_gets_a_row_within_its_reach_plus_the_1_mm_margin(alpha5):
    """A limit's row is solved when its gap is at most h |v| + margin, the margin 1 mm (1e-3
    rad) by default (docs/physics.md); a margin of 0 is allowed (the reach alone), a
    negative one refused."""
    model, data = alpha5.model, alpha5.model.createData()
    joint = 2 + int(np.flatnonzero(alpha5.arm_joints.limited)[0])
    at = model.joints[joint].idx_q
    speed = np.zeros(model.nv)
    speed[model.joints[joint].idx_v] = 0.5  # reaches h |v| = 1 mm in a period of 2 ms

    def rows(gap_rad: float, margin: float | None = None) -> int:
        q, _ = _start(alpha5)
        q[at] = model.upperPositionLimit[at] - gap_rad
        limits = JointLimits((joint,)) if margin is None else JointLimits((joint,), margin)
        return limits.rows(model, data, q, speed, PERIOD_S).size

    assert JointLimits((joint,)).margin == JointLimits.of_uvms(alpha5).margin == 1e-3
    assert rows(1.9e-3) == 1 and rows(2.1e-3) == 0  # h |v| + 1 mm
    assert rows(0.9e-3, margin=0.0) == 1 and rows(1.1e-3, margin=0.0) == 0
    with pytest.raises(ParameterError, match="margin"):
        JointLimits((joint,), margin=-1e-9)
