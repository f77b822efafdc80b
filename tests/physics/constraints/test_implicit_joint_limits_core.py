"""The compiled joint limits (src/uvms_core/joint_limits.hpp) against the Python reference
(`uvms_pin.physics.constraints.step` with Pinocchio's ADMM): the same v+ on random states at
and near the limits, to the ADMM's tolerance (at 1e-12 the two agree to 1e-7 rad/s; at the
reference's default 1e-8 the wrist's small inertia turns the impulses' tolerance into up to
3e-5 rad/s), the exact solve's objective never above the ADMM's; the exact solve's own
optimality conditions (bounds, signs, complementarity) to rounding; the selection of rows (no
row: the free velocity, untouched); bad input refused."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.model.resources import shipped_path
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.joint_limits import joint_limits_to_core
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.step import constrained_velocity, default_settings

PERIOD_S = 2e-3
MODELS = ("models/uvms_bluerov2_alpha5.urdf", "models/uvms_lbv150.urdf")


def _load(path: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        return up.load_uvms(shipped_path(path))


@pytest.fixture(scope="module", params=MODELS)
def uvms(request):
    return _load(request.param)


def _states(uvms, count: int, seed: int):
    """Random (q, v_free): the arm within or at its limits (some a little past them), the
    velocities of a violent period."""
    rng = np.random.default_rng(seed)
    arm = uvms.arm_joints
    limited = arm.limited
    for _ in range(count):
        positions = rng.uniform(
            np.where(limited, arm.lower, -3.0), np.where(limited, arm.upper, 3.0)
        )
        at = limited & (rng.random(arm.count) < 0.4)
        side = np.where(rng.random(arm.count) < 0.5, arm.lower, arm.upper)
        positions[at] = side[at] + rng.normal(0.0, 2e-3, arm.count)[at]
        q = pin.integrate(uvms.model, uvms.neutral_configuration(), rng.normal(0, 0.3, uvms.nv))
        q[7:] = arm.configuration(positions)
        v_free = rng.normal(0.0, 1.0, uvms.nv) * np.r_[[0.5] * 6, [20.0] * (uvms.nv - 6)]
        yield q, v_free


def test_the_core_gives_the_reference_velocity(uvms):
    limits = JointLimits.of_uvms(uvms)
    core = joint_limits_to_core(limits, uvms.model, core_module())
    solved_rows, pressed, worst = 0, 0, 0.0
    tight = default_settings(tolerance=1e-12, max_iterations=20000)
    for q, v_free in _states(uvms, 150, seed=11):
        mass = up.mass_matrix(uvms, q)
        reference = constrained_velocity(
            uvms.model, mass, v_free, q, [limits], PERIOD_S, settings=tight
        )
        selected, velocity = core.constrain(mass, q, v_free, PERIOD_S)
        assert selected == bool(reference.rows)
        worst = max(worst, float(np.abs(velocity - reference.velocity).max()))
        # the exact optimum of 1/2 |v - v_free|_M^2 over the bounds: not above the ADMM's
        # (which may undercut it within its feasibility tolerance)
        cost = (velocity - v_free) @ mass @ (velocity - v_free)
        cost_reference = (reference.velocity - v_free) @ mass @ (reference.velocity - v_free)
        assert cost <= cost_reference * (1.0 + 1e-9) + 1e-15
        solved_rows += selected
        pressed += bool(np.any(reference.impulses["joint_limits"] > 1e-6))
    assert worst < 1e-7  # rad/s, m/s
    assert solved_rows > 50 and pressed > 30  # the states did touch the limits


def test_the_exact_solve_meets_its_optimality_conditions(uvms):
    limits = JointLimits.of_uvms(uvms)
    core = joint_limits_to_core(limits, uvms.model, core_module())
    model = uvms.model
    for q, v_free in _states(uvms, 100, seed=5):
        mass = up.mass_matrix(uvms, q)
        selected, velocity = core.constrain(mass, q, v_free, PERIOD_S)
        impulse = mass @ (velocity - v_free)  # J^T lambda, in the joints' coordinates
        coupled = np.zeros(uvms.nv, dtype=bool)
        for joint_id in limits.joint_ids:
            joint = model.joints[joint_id]
            iq, iv = joint.idx_q, joint.idx_v
            coupled[iv] = True
            lower_gap = q[iq] - model.lowerPositionLimit[iq]
            upper_gap = model.upperPositionLimit[iq] - q[iq]
            reach = PERIOD_S * max(abs(v_free[iv]), abs(velocity[iv])) + limits.margin
            low = lower_gap if lower_gap >= 0 else 0.2 * lower_gap
            high = upper_gap if upper_gap >= 0 else 0.2 * upper_gap
            scale = 1e-9 * (1.0 + abs(velocity[iv]))
            if lower_gap <= reach:
                assert velocity[iv] >= -low / PERIOD_S - scale
            if upper_gap <= reach:
                assert velocity[iv] <= high / PERIOD_S + scale
            # an impulse only pushes away from a limit the velocity sits on
            if impulse[iv] > 1e-9:
                assert abs(velocity[iv] + low / PERIOD_S) < scale
            elif impulse[iv] < -1e-9:
                assert abs(velocity[iv] - high / PERIOD_S) < scale
        np.testing.assert_allclose(impulse[~coupled], 0.0, atol=1e-9 * np.abs(mass).max())
        if selected:  # never adds kinetic energy (no penetration was drawn deep)
            assert velocity @ mass @ velocity <= v_free @ mass @ v_free * (1 + 1e-12) + 1e-12


def test_far_from_every_limit_nothing_is_solved():
    uvms = _load(MODELS[0])
    core = joint_limits_to_core(JointLimits.of_uvms(uvms), uvms.model, core_module())
    q = uvms.neutral_configuration()
    q[7:] = uvms.arm_joints.configuration(np.array([-0.2, 0.8, 2.2, 0.2]))
    v_free = np.r_[np.zeros(6), 0.1, -0.1, 0.1, -0.1]
    selected, velocity = core.constrain(up.mass_matrix(uvms, q), q, v_free, PERIOD_S)
    assert not selected
    assert np.array_equal(velocity, v_free)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda c: setattr(c, "margin", -1.0), "margin"),
        (lambda c: setattr(c, "correction", 0.0), "correction"),
        (lambda c: setattr(c, "upper_rad", c.lower_rad - 1.0), "lower < upper"),
        (lambda c: setattr(c, "v_index", [99] * len(c.v_index)), "outside the model"),
        (lambda c: setattr(c, "q_index", c.q_index[:1]), "one q index"),
    ],
)
def test_bad_limits_are_refused(change, message):
    uvms = _load(MODELS[0])
    core = joint_limits_to_core(JointLimits.of_uvms(uvms), uvms.model, core_module())
    change(core)
    q = uvms.neutral_configuration()
    with pytest.raises(ValueError, match=message):
        core.constrain(up.mass_matrix(uvms, q), q, np.zeros(uvms.nv), PERIOD_S)


def test_bad_arguments_are_refused():
    uvms = _load(MODELS[0])
    core = joint_limits_to_core(JointLimits.of_uvms(uvms), uvms.model, core_module())
    q = uvms.neutral_configuration()
    mass = up.mass_matrix(uvms, q)
    with pytest.raises(ValueError, match=r"v_free must have shape \(10,\)"):
        core.constrain(mass, q, np.zeros(3), PERIOD_S)
    with pytest.raises(ValueError, match="period"):
        core.constrain(mass, q, np.zeros(uvms.nv), 0.0)
    with pytest.raises(ValueError, match="non-finite"):
        core.constrain(mass, q, np.full(uvms.nv, np.nan), PERIOD_S)
