"""The compiled task-priority law (src/uvms_core/law_task_priority.hpp on task_priority.hpp
and dynamic_level.hpp), built by uvms_pin/sim/compiled/laws.py, in the compiled sampled loop
against `TaskPriorityController` in the Python loop: the whole rollout to 1e-12 on both
shipped tracking models and both dynamic levels, with the joint-limit task's active set
changing, the damped inverse near a singularity, the manipulability task, and a funnel left
at the same tick; the prioritized recursion itself against the Python one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from conftest import ALPHA5_URDF, ROOT, without_drives
from test_compiled_laws import _both
from test_compiled_loop import _assert_same

from uvms_pin.apps.compare.runs import controller_scenarios
from uvms_pin.control.tracking.dynamic_level import InverseDynamicsLevel
from uvms_pin.control.tracking.task_priority import KinematicLevel, prioritized_velocity
from uvms_pin.errors import FunnelViolation, ParameterError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.sim.compiled.laws import law_to_core

LBV150 = ROOT / "scenarios" / "lbv150_ee_circle.toml"
BLUEROV = ROOT / "scenarios" / "bluerov_alpha5_ee_circle.toml"
#: the vehicle on the circle instead of the end effector (the arm held by the limit task alone)
VEHICLE_CIRCLE = {"task.target": "vehicle", "task.radius_m": 0.3}
#: the sensors exact: the logged state is the measured one
NO_NOISE = {f"sensors.{name}": 0.0 for name in (
    "position_noise_m", "orientation_noise_rad", "joint_noise_rad", "velocity_noise")}  # fmt: skip
#: the end effector in the vehicle's frame, its position alone (a 4-joint arm)
EE_IN_VEHICLE = {"task.frame": "vehicle", "task.track_orientation": False}


def _scenario(path, kind="task_priority", duration_s=3.0, **overrides):
    overrides = {"scenario.duration_s": duration_s, **overrides}
    return controller_scenarios(path, [kind], overrides)[kind]


def _compiled_as_python(scenario, rtol=1e-12):
    """The compiled rollout, after checking it ran compiled throughout and equals the Python
    loop's to ``rtol``."""
    (compiled, stop_c), (python, stop_p) = _both(scenario)
    assert stop_c is None and stop_p is None
    ticks = round(scenario.settings.duration_s / scenario.settings.control_period_s) + 1
    assert compiled.metadata["closed_loop"] == {
        "path": "compiled", "reason": None, "compiled_ticks": ticks, "python_ticks": 0}  # fmt: skip
    assert python.metadata["closed_loop"]["python_ticks"] == ticks
    _assert_same(compiled, python, rtol)
    assert compiled.metadata["signal_units"] == python.metadata["signal_units"]
    assert np.max(np.abs(compiled.signals["task_position_error"])) > 1e-4
    return compiled


@pytest.mark.parametrize(
    "path, kind, overrides",
    [
        (LBV150, "task_priority", {}),
        (LBV150, "task_priority", {"water.current_world_m_s": [0.1, 0.0, 0.0]}),
        (LBV150, "task_priority_ppc", {}),
        (LBV150, "task_priority", EE_IN_VEHICLE),
        (LBV150, "task_priority", VEHICLE_CIRCLE),
        (BLUEROV, "task_priority", {}),
        (BLUEROV, "task_priority", VEHICLE_CIRCLE),
    ],
    ids=[
        "lbv150",
        "lbv150-current",
        "lbv150-ppc",
        "lbv150-ee-in-vehicle",
        "lbv150-vehicle",
        "bluerov-alpha5",
        "bluerov-alpha5-vehicle",
    ],
)
def test_task_priority_runs_compiled_as_in_python(path, kind, overrides):
    compiled = _compiled_as_python(_scenario(path, kind, **overrides))
    assert np.max(np.abs(compiled.signals["zeta_r"])) > 1e-3  # the reference moved


def test_the_joint_limit_tasks_active_set_changes_as_in_python():
    # joint 2 starts just outside the band of its upper limit (2.0 - 0.1 rad), joint 3 inside
    # the band of its lower one (-1.5 + 0.1 rad): the limit task takes joint 2 when the
    # tracking task drives it into its band, holds joint 3 at first, and lets both go
    scenario = _scenario(LBV150, **{"initial.joint_positions_rad": [-0.2, 1.85, -1.45, 0.2]})
    compiled = _compiled_as_python(scenario)
    change = np.diff(compiled.signals["joint_limit_active"], axis=0)
    np.testing.assert_array_equal((change > 0).sum(axis=0), [0, 1, 0, 0])  # joint 2 taken
    np.testing.assert_array_equal((change < 0).sum(axis=0), [0, 1, 1, 0])  # both let go


@pytest.mark.parametrize(
    "joints",
    [[-0.018, 0.87, 0.698, -2.091], [0.846, 1.36, 0.211, 0.898]],
    ids=["s~lambda", "s<<lambda"],
)
def test_the_damped_inverse_near_a_singularity_runs_compiled_as_in_python(joints):
    # LBV150 arm poses where the tracking task's smallest singular value (in the metric W,
    # the roll and pitch rates passive) is 1.6e-3 and 7.6e-5: near lambda = 1e-3 and below
    # (singular values of J W^-1/2 up to ~3): the damped inverse's gain s / (s^2 + lambda^2)
    # peaks at 1 / (2 lambda) = 500 there, so the rounding by which LAPACK's SVD and Eigen's
    # Jacobi SVD differ grows by as much: the loops agree to 1e-11 of each signal's scale on
    # one machine, to 1.5e-11 on another (an AMD EPYC, whose BLAS kernels LAPACK's SVD
    # rounds differently; the commit before any change of the core measured the same there):
    # 5e-11 holds both, far below what a wrong law gives
    exact = {"initial.joint_positions_rad": joints, **NO_NOISE}
    scenario = _scenario(LBV150, duration_s=2.0, **exact)
    compiled = _compiled_as_python(scenario, rtol=5e-11)
    # the damping matters along the run: at its logged states (measured exactly), the
    # reference with lambda = 1e-3 is the logged one, the undamped one another
    level = scenario.controller_factory(scenario.uvms).kinematics
    undamped = KinematicLevel(level.model, level.task, replace(level.gains, damping=1e-9))
    worst = 0.0
    for k in range(1, len(compiled)):
        time_s, q, v = compiled.time_s[k], compiled.q[k], compiled.v[k]
        damped, _ = level.reference(time_s, q, v)
        np.testing.assert_allclose(damped, compiled.signals["zeta_r"][k], rtol=0, atol=1e-12)
        change = undamped.reference(time_s, q, v)[0] - damped
        worst = max(worst, np.max(np.abs(change)) / np.max(np.abs(damped)))
    assert worst > 1e-2


def test_the_manipulability_task_runs_compiled_as_in_python():
    # w_min = 10 above w(q) all along: the arm climbs grad w, by central differences (step
    # 1e-6) of sqrt(det(J_a^T J_a)). The difference divides w's rounding by 2e-6, and det's
    # rounding depends on the order of its sums (numpy's LAPACK LU and matmul, Eigen's): the
    # reference's own gradient moves by ~1e-8 relative when the Gram matrix is summed in
    # another order. So the loops agree to that rounding (5e-9 of each signal's scale
    # measured over 3 s), 1e-7 here, not 1e-12
    scenario = _scenario(LBV150, duration_s=1.0, **{"controller.manipulability_threshold": 10.0})
    compiled = _compiled_as_python(scenario, rtol=1e-7)
    plain = _compiled_as_python(_scenario(LBV150, duration_s=1.0))
    climbed = compiled.signals["zeta_r"][0] - plain.signals["zeta_r"][0]
    assert np.max(np.abs(climbed[6:])) > 1e-3  # the task is active from the start


def test_a_funnel_left_stops_both_loops_at_the_same_tick(tmp_path):
    # the PPC velocity level of a BlueROV2 + Alpha 5 without its drives' armature (light
    # links): joints 2 or 3 leave their funnels early (scenarios/bluerov_alpha5_ee_circle.toml)
    light = {"scenario.model": str(without_drives(ALPHA5_URDF, tmp_path))}
    (compiled, stop_c), (python, stop_p) = _both(_scenario(BLUEROV, "task_priority_ppc", **light))
    assert isinstance(stop_c, FunnelViolation) and isinstance(stop_p, FunnelViolation)
    assert (stop_c.level, stop_c.component, stop_c.time_s) == (
        stop_p.level, stop_p.component, stop_p.time_s)  # fmt: skip
    meta = compiled.metadata["closed_loop"]
    assert meta["compiled_ticks"] > 0 and meta["python_ticks"] == 1
    _assert_same(compiled, python)


def test_the_integral_is_handed_over_when_a_tick_runs_in_python():
    # the first chunk compiled, then the Python loop: the inverse-dynamics level's integral
    # and last call must be the law's (push, pull)
    scenario = _scenario(LBV150, duration_s=1.0)
    core = core_module()
    controller = scenario.controller_factory(scenario.uvms)
    built = law_to_core(controller, core)
    level = controller.dynamic
    level.integral, level.last_time_s = np.linspace(-0.1, 0.1, level.integral.size), 0.25
    built.push()
    state = built.law.state
    np.testing.assert_array_equal(state.integral, level.integral)
    assert state.started and state.last_time_s == 0.25
    level.reset()
    built.pull(0.25, np.zeros(9))
    np.testing.assert_array_equal(level.integral, np.linspace(-0.1, 0.1, level.integral.size))
    assert level.last_time_s == 0.25


def _singular_tasks(rng, n=10, smallest=1e-4):
    """A task of 6 rows with one singular value ``smallest`` (damped by lambda = 1e-3)
    above a task of 2 rows, and a third of 4 that conflicts with both."""
    u, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    v, _ = np.linalg.qr(rng.normal(size=(n, 6)))
    first = u @ np.diag([3.0, 2.0, 1.0, 0.5, 0.1, smallest]) @ v.T
    return [
        (rng.normal(size=(2, n)), rng.normal(size=2)),
        (first, rng.normal(size=6)),
        (rng.normal(size=(4, n)), rng.normal(size=4)),
    ]


@pytest.mark.parametrize("smallest", [0.1, 1e-3, 1e-4])
@pytest.mark.parametrize("seed", range(5))
def test_the_core_recursion_is_the_python_one(seed, smallest):
    rng = np.random.default_rng(seed)
    core = core_module()
    tasks = _singular_tasks(rng, smallest=smallest)
    weights = rng.uniform(0.5, 50.0, 10)
    secondary = rng.normal(size=10)
    # two SVDs (LAPACK's, Eigen's Jacobi) differ by rounding, which the recursion grows by
    # the condition s_max / s_min = 3 / smallest of the task with the small singular value:
    # measured up to ~15 eps that condition over 30 draws, allowed 3e-15 times it
    tolerance = 3e-15 * 3.0 / smallest
    for damping in (1e-3, 1e-9):
        for extra in (None, secondary):
            python = prioritized_velocity(tasks, weights, damping, extra)
            compiled = core.prioritized_velocity(tasks, weights, damping, extra)
            scale = np.abs(python).max()
            np.testing.assert_allclose(compiled, python, rtol=0, atol=tolerance * scale)
    if smallest < 1e-2:  # the damping matters there
        damped = core.prioritized_velocity(tasks, weights, 1e-3)
        exact = core.prioritized_velocity(tasks, weights, 1e-9)
        assert np.max(np.abs(damped - exact)) > 0.1 * np.max(np.abs(damped))
    # an empty task and an all-zero one are skipped; a task the one above took entirely away
    # (its singular values at rounding level) adds nothing
    held = tasks[1]
    again = [held, (np.zeros((0, 10)), np.zeros(0)), (np.zeros((3, 10)), np.ones(3)), held]
    python = prioritized_velocity(again, weights, 1e-3)
    np.testing.assert_allclose(
        core.prioritized_velocity(again, weights, 1e-3),
        python,
        rtol=0,
        atol=tolerance * np.abs(python).max(),
    )


def test_bad_input_raises_parameter_errors():
    core = core_module()
    ones = np.ones(10)
    with pytest.raises(ParameterError, match="must be m x 10"):
        core.prioritized_velocity([(np.ones((2, 9)), np.ones(2))], ones, 1e-3)
    with pytest.raises(ParameterError, match="secondary needs 10"):
        core.prioritized_velocity([(np.ones((2, 10)), np.ones(2))], ones, 1e-3, np.ones(3))
    with pytest.raises(ParameterError, match="positive"):
        core.prioritized_velocity([], -ones, 1e-3)
    scenario = _scenario(LBV150, duration_s=0.1)
    controller = scenario.controller_factory(scenario.uvms)
    built = law_to_core(controller, core)
    with pytest.raises(ParameterError, match="nv = 10"):
        state = built.law.state
        state.integral = np.zeros(3)
        built.law.state = state
    model_text = controller.kinematics.model.saveToString()

    def settings(**fields):
        s = core.TaskPrioritySettings()
        s.frame_id, s.velocity_weights = controller.task.frame_id(controller.kinematics.model), ones
        for name, value in fields.items():
            setattr(s, name, value)
        return s

    level = core.PpcVelocitySettings()
    level.gain, level.rho0, level.rho_inf, level.decay_rate_per_s = ones, 2 * ones, ones, ones
    core.TaskPriorityLaw(model_text, settings(), level)  # well formed
    for fields, match in [
        ({"velocity_weights": np.ones(7)}, "velocity_weights needs nv = 10"),
        ({"velocity_weights": -ones}, "velocity_weights must be positive"),
        ({"passive_velocities": [6]}, "passive_velocities must be in 0..5"),
        ({"frame_id": 10_000}, "frame_id 10000 is out of range"),
        ({"rows": 4}, "6 or 3 rows"),
    ]:
        with pytest.raises(ParameterError, match=match):
            core.TaskPriorityLaw(model_text, settings(**fields), level)
    level.rho_inf = np.ones(4)
    with pytest.raises(ParameterError, match="rho_inf_zeta needs nv = 10"):
        core.TaskPriorityLaw(model_text, settings(), level)
    ppc = law_to_core(_controller(LBV150, "task_priority_ppc"), core)
    with pytest.raises(ParameterError, match="not inverse dynamics"):
        ppc.law.state  # noqa: B018


def _controller(path, kind):
    scenario = _scenario(path, kind, duration_s=0.1)
    return scenario.controller_factory(scenario.uvms)


def test_a_dynamic_level_of_another_class_runs_in_python():
    controller = _controller(LBV150, "task_priority")

    class Mine(InverseDynamicsLevel):
        pass

    level = controller.dynamic
    controller.dynamic = Mine(level.uvms, level.k_v, level.k_i, level.limit)
    reason = law_to_core(controller, core_module())
    assert isinstance(reason, Fallback) and "dynamic level Mine is not compiled" in reason.reason
