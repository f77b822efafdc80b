"""uvms_pin.apps.gym: the Gymnasium API contract, seeding, the PPC through the environment."""

from __future__ import annotations

import importlib.util
import re

import gymnasium as gym
import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT
from gymnasium.utils.env_checker import check_env

import uvms_pin.apps.gym  # noqa: F401 - registers the environments
from uvms_pin.errors import ParameterError, ScenarioError

FORCE = "uvms_pin/ForceTracking-v0"
STATION = "uvms_pin/StationKeeping-v0"
SHORT = {"scenario.duration_s": 0.1}


def _make(env_id: str, **kw):
    kw.setdefault("overrides", SHORT)
    return gym.make(env_id, **kw)


def _rollout(env, seed: int, steps: int) -> tuple[np.ndarray, list[float]]:
    observation, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    observations, rewards = [observation], []
    for _ in range(steps):
        observation, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        observations.append(observation)
        rewards.append(reward)
        if terminated or truncated:
            break
    return np.array(observations), rewards


@pytest.mark.parametrize("env_id", [FORCE, STATION])
def test_check_env_passes(env_id):
    env = _make(env_id, render_mode="rgb_array")
    check_env(env.unwrapped)  # raises on any violation of the API contract


@pytest.mark.parametrize("env_id", [FORCE, STATION])
def test_seeded_resets_are_reproducible(env_id):
    first = _rollout(_make(env_id), seed=5, steps=20)
    second = _rollout(_make(env_id), seed=5, steps=20)
    np.testing.assert_array_equal(first[0], second[0])
    assert first[1] == second[1]
    other = _rollout(_make(env_id), seed=6, steps=20)
    # another seed: another initial perturbation and other sensor noise
    assert not np.allclose(first[0][0], other[0][0])


def test_unseeded_resets_follow_the_last_seed():
    def seeds(env):
        env.reset(seed=9)
        return [env.reset()[1]["seed"] for _ in range(3)]

    a, b = seeds(_make(FORCE)), seeds(_make(FORCE))
    assert a == b
    assert len(set(a)) == 3


def test_observation_layout_is_the_measurement():
    env = _make(FORCE, initial_position_noise_m=0.0, initial_joint_noise_rad=0.0).unwrapped
    observation, _ = env.reset(seed=env.scenario.settings.seed)
    layout = env.observation_layout
    q0 = env.scenario.q0
    # the realistic scenario measures the state exactly, the wrench with +-0.02 N noise
    np.testing.assert_allclose(
        observation[layout["q"]],
        q0 / np.r_[1, 1, 1, [np.linalg.norm(q0[3:7])] * 4, np.ones(q0.size - 7)],
    )
    np.testing.assert_array_equal(observation[layout["v"]], env.scenario.v0)
    assert np.all(np.abs(observation[layout["wrench"]][:3]) <= 0.02)  # anchored: f(0) = 0
    # f_d(0) = 0.4 N on x (the scenario's [controller.desired_force])
    np.testing.assert_allclose(observation[layout["goal"]], [0.4, 0.0, 0.0], atol=1e-12)


def _ppc_script():
    spec = importlib.util.spec_from_file_location(
        "ppc_through_env", ROOT / "scripts" / "gym" / "ppc_through_env.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ppc_through_the_environment_is_uvms_pin_run():
    q_env, q_run = _ppc_script().ppc_through_env("realistic_force_tracking", 0.3)
    assert q_env.shape == q_run.shape == (31, q_run.shape[1])
    assert np.max(np.abs(q_run[-1] - q_run[0])) > 1e-3  # the run moves
    np.testing.assert_allclose(q_env, q_run, rtol=0, atol=1e-9)


def test_funnel_ends_the_episode():
    # f(0) = 0, f_d(0) = 0.4 N: outside a 0.1 N funnel at once
    env = _make(FORCE, funnel=(0.1, 0.05, 1.0))
    env.reset(seed=0)
    _, _, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
    assert terminated and not truncated
    assert info["force_error_N"] > 0.1


def test_time_limit_truncates():
    env = _make(STATION, overrides={"scenario.duration_s": 0.05})
    env.reset(seed=0)
    flags = [env.step(np.zeros(env.action_space.shape))[2:4] for _ in range(5)]
    assert flags == [(False, False)] * 4 + [(False, True)]


def test_station_keeping_reward_is_the_pose_error():
    """The errors are those of the true state reached (the episode's rollout, not the
    measurement) to the goal pose (the scenario's initial pose, in the observation), and
    the reward is -(|p - p_d| / 0.1 m)^2 - (angle / 0.1 rad)^2 (no effort at zero action)."""
    env = _make(STATION).unwrapped
    observation, _ = env.reset(seed=2)
    goal = observation[env.observation_layout["goal"]]
    np.testing.assert_array_equal(goal, env.scenario.q0[:7])
    for _ in range(3):
        _, reward, _, _, info = env.step(np.zeros(env.action_space.shape))
    q = env.episode_rollout().q[-1]
    position_error = np.linalg.norm(q[:3] - goal[:3])
    rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
    goal_rotation = pin.Quaternion(goal[3:7]).toRotationMatrix()
    angle_error = np.linalg.norm(pin.log3(goal_rotation.T @ rotation))
    assert info["position_error_m"] == pytest.approx(position_error, rel=1e-12)
    assert info["angle_error_rad"] == pytest.approx(angle_error, rel=1e-9, abs=1e-12)
    expected = -((position_error / 0.1) ** 2) - (angle_error / 0.1) ** 2
    assert reward == pytest.approx(expected, rel=1e-12)
    # the reset moved the vehicle up to 0.1 m per axis from the goal; 3 steps barely move it
    assert 0.0 < position_error <= np.sqrt(3) * 0.1


def test_vector_envs():
    sync = gym.make_vec(FORCE, num_envs=2, vectorization_mode="sync", overrides=SHORT)
    observations, _ = sync.reset(seed=[3, 4])
    single, _ = _make(FORCE).reset(seed=4)
    np.testing.assert_array_equal(observations[1], single)
    actions = np.zeros((2, sync.single_action_space.shape[0]))
    observations, rewards, *_ = sync.step(actions)
    assert observations.shape == (2, *sync.single_observation_space.shape)
    assert np.all(np.isfinite(rewards))
    sync.close()


def test_async_vector_env():
    envs = gym.make_vec(FORCE, num_envs=2, vectorization_mode="async", overrides=SHORT)
    try:
        observations, _ = envs.reset(seed=[3, 4])
        single, _ = _make(FORCE).reset(seed=3)
        np.testing.assert_array_equal(observations[0], single)
        envs.step(np.zeros((2, envs.single_action_space.shape[0])))
    finally:
        envs.close()


def test_render_and_replay_export(tmp_path):
    env = _make(FORCE, render_mode="rgb_array").unwrapped
    env.reset(seed=0)
    first = env.render()
    for _ in range(10):
        env.step(np.ones(env.action_space.shape))
    assert first.dtype == np.uint8 and first.shape == (360, 480, 3)
    assert np.any(env.render() != first)  # the image follows the state
    rollout = env.episode_rollout()
    assert len(rollout) == 11
    np.testing.assert_allclose(np.diff(rollout.time_s), 0.002, rtol=1e-9)
    from uvms_pin.apps.viz.replay import write_replay
    from uvms_pin.results.rollout import Rollout

    loaded = Rollout.load(rollout.save(tmp_path / "episode"))
    np.testing.assert_array_equal(loaded.q, rollout.q)
    page = write_replay(loaded, tmp_path / "replay.html")
    assert page.stat().st_size > 1000


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"scenario": "no_such_scenario"}, "no such file nor shipped scenario"),
        ({"scenario": "paper_force_tracking"}, "control.period_s"),
        (
            {"scenario": "passive_still_water", "overrides": {"control.period_s": 0.002}},
            "action_scale",
        ),
        ({"render_mode": "ansi"}, "render_mode"),
        ({"action_scale": [1.0, 2.0]}, "action_scale must be 10"),
        ({"funnel": "tight"}, "funnel must be"),
        ({"desired_force_N": [1.0, 2.0]}, "desired_force_N"),
        ({"initial_position_noise_m": -1.0}, "initial_position_noise_m"),
        ({"effort_weight": "high"}, "effort_weight must be a finite number"),
        ({"overrides": [("control.period_s", 0.01)]}, "overrides must be a mapping"),
    ],
)
def test_bad_options_are_clear_errors(kw, match):
    with pytest.raises(ParameterError, match=match):
        gym.make(FORCE, **kw)


def test_the_continuous_control_advice_works_as_given():
    """The refusal of a continuous-control scenario names a control period and, for one
    without actuation limits, action_scale: doing exactly that gives a working env."""
    with pytest.raises(ParameterError) as refused:
        gym.make(FORCE, scenario="paper_force_tracking")
    message = str(refused.value)
    period = re.search(r'overrides=\{"control\.period_s": ([0-9.e-]+)\}', message)
    assert period and "action_scale=<10 numbers" in message, message
    env = gym.make(
        FORCE,
        scenario="paper_force_tracking",
        overrides={"control.period_s": float(period.group(1))},
        action_scale=np.full(10, 5.0),
    )
    env.reset(seed=0)
    _, _, terminated, truncated, info = env.step(np.zeros(10))
    assert not (terminated or truncated) and info["time_s"] == pytest.approx(0.005)
    with pytest.raises(ParameterError) as refused:
        gym.make(FORCE, scenario="paper_force_tracking", action_scale=np.full(10, 5.0))
    assert "action_scale" not in str(refused.value)  # given already: not asked again


def test_force_tracking_needs_a_contact_environment():
    with pytest.raises(ParameterError, match="contact"):
        gym.make(FORCE, scenario="gym_station_keeping")


def test_bad_actions_are_clear_errors():
    env = _make(FORCE).unwrapped
    with pytest.raises(ParameterError, match="reset"):
        env.step(np.zeros(10))
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="10 finite numbers"):
        env.step(np.zeros(3))
    with pytest.raises(ParameterError, match="10 finite numbers"):
        env.step(np.full(10, np.nan))
    for given in ("0.5", ["a"] * 10, [[0.0], [0.0, 1.0]]):  # was numpy's ValueError
        with pytest.raises(ParameterError, match="10 finite numbers"):
            env.step(given)


def test_sea_state_is_drawn_from_the_episode_seed():
    env = _make(FORCE, scenario="sea_state_force_tracking").unwrapped
    point = np.array([[0.0, 0.0, -2.0]])

    def flow_at_seed(seed: int) -> np.ndarray:
        env.reset(seed=seed)
        assert env.scenario.raw["scenario"]["seed"] == seed
        return env.scenario.plant.flow.velocity(1.0, point)

    first, other, again = flow_at_seed(1), flow_at_seed(2), flow_at_seed(1)
    assert not np.allclose(first, other)  # another seed: another sea
    np.testing.assert_array_equal(first, again)


def test_divergence_ends_the_episode_cleanly():
    # unlimited actuation with an absurd scale: the vehicle blows up within a step or two
    env = gym.make(
        STATION,
        scenario="passive_still_water",
        overrides={"control.period_s": 0.002},
        action_scale=np.full(10, 1e12),
    ).unwrapped
    observation, _ = env.reset(seed=0)
    for _ in range(5):
        observation, reward, terminated, truncated, info = env.step(np.ones(10))
        if terminated:
            break
    assert terminated and not truncated
    assert "diverged" in info["error"]
    assert reward == -100.0
    assert np.all(np.isfinite(observation))
    with pytest.raises(ParameterError, match="reset"):
        env.step(np.ones(10))
    rollout = env.episode_rollout()  # the states reached before the failure, all finite
    assert np.all(np.isfinite(rollout.q)) and np.all(np.diff(rollout.time_s) > 0)


def test_any_scenario_or_model():
    bluerov = _make(FORCE, scenario="bluerov_alpha5_force_tracking").unwrapped
    uvms = bluerov.scenario.uvms
    assert bluerov.observation_space.shape == (uvms.nq + uvms.nv + 6 + 3,)
    assert bluerov.action_space.shape == (uvms.nv,)
    urdf = ROOT / "models" / "uvms_lbv150.urdf"
    lbv = _make(FORCE, model=str(urdf)).unwrapped
    assert lbv.scenario.uvms.source == str(urdf.resolve()) or lbv.scenario.uvms.source == str(urdf)
    assert lbv.observation_space.shape == (30,)


def test_a_model_the_scenarios_joints_do_not_fit_says_how_to_make_them_fit():
    """The shipped station-keeping scenario's arm start is the LBV150 arm's; the Alpha 5
    refuses it (a limit), naming the key and the override that fixes it, which then works."""
    with pytest.raises(ScenarioError, match=r"alpha_axis_c.*overrides=\{'initial\.joint_"):
        _make(STATION, model="uvms_bluerov2_alpha5")
    env = _make(STATION, model="uvms_bluerov2_alpha5",
                overrides={"initial.joint_positions_rad": [-0.2, 0.8, 2.2, 0.2]})  # fmt: skip
    assert env.action_space.shape == (10,)


POSE = "uvms_pin/PoseTracking-v0"


def test_pose_tracking_env_api_and_goal():
    env = _make(POSE, render_mode="rgb_array")
    check_env(env.unwrapped)
    env = env.unwrapped
    observation, _ = env.reset(seed=1)
    goal = observation[env.observation_layout["goal"]]
    p0, v0, _ = env.scenario.task.path.at(0.0)
    np.testing.assert_allclose(goal[:3], p0)
    np.testing.assert_allclose(goal[3:6], v0)
    rotation = pin.Quaternion(goal[6:10]).toRotationMatrix()  # xyzw
    np.testing.assert_allclose(rotation, env.scenario.task.rotation_reference, atol=1e-12)


def test_the_task_priority_controller_tracks_through_the_pose_env():
    """The scenario's controller as a policy: the rewards are its true pose errors, small."""
    from uvms_pin.apps.gym.policy import ControllerPolicy

    env = gym.make(POSE, overrides={"scenario.duration_s": 3.0}, clip_actions=False).unwrapped
    controller = env.scenario.controller_factory(env.scenario.uvms)
    policy = ControllerPolicy(controller, env)
    observation, info = env.reset(seed=3)
    info = {**info, "time_s": 0.0}
    errors = []
    while True:
        observation, reward, terminated, truncated, info = env.step(policy(observation, info))
        errors.append(info["position_error_m"])
        expected = -((info["position_error_m"] / 0.1) ** 2) - (info["angle_error_rad"] / 0.1) ** 2
        assert reward <= expected + 1e-12  # the effort term only lowers it
        if terminated or truncated:
            break
    assert truncated and not terminated and len(errors) == 300
    # the reset moved the vehicle by up to 1 cm per axis; the controller takes it back
    assert max(errors[-50:]) < 0.01
    with pytest.raises(ParameterError, match="PoseTracking needs a \\[task\\]"):
        gym.make(POSE, scenario="gym_station_keeping")


def test_an_observation_never_aliases_the_plant_state():
    """A policy that writes into its observation (or into the episode's rollout) changes
    nothing in the environment: the next observations are those of an untouched run."""

    def run(meddle: bool) -> np.ndarray:
        env = _make(FORCE).unwrapped
        observation, _ = env.reset(seed=5)
        seen = [observation.copy()]
        for _ in range(5):
            if meddle:
                assert not np.shares_memory(observation, env._loop.q)
                observation[:] = 99.0  # it is the policy's own array
                rollout = env.episode_rollout()
                rollout.q[:] = 99.0
                rollout.v[:] = 99.0
            observation, *_ = env.step(np.zeros(env.action_space.shape))
            seen.append(observation.copy())
        return np.array(seen)

    np.testing.assert_array_equal(run(meddle=True), run(meddle=False))


def test_continuous_arm_joints(tmp_path):
    """A model whose arm joints are continuous: q holds (cos, sin) of each (nq = 15 for
    nv = 10); the initial joint perturbation turns each joint by an angle, staying on the
    circle."""
    from conftest import continuous_joint_urdf

    urdf = continuous_joint_urdf(tmp_path)
    env = _make(FORCE, model=str(urdf), initial_joint_noise_rad=0.3).unwrapped
    assert env.observation_space.shape == (15 + 10 + 6 + 3,)
    observation, _ = env.reset(seed=3)
    q = observation[env.observation_layout["q"]]
    cos, sin = q[7::2], q[8::2]
    np.testing.assert_allclose(np.hypot(cos, sin), 1.0, rtol=0, atol=1e-14)
    turned = np.arctan2(sin, cos) - env.scenario.uvms.arm_joints.positions(env.scenario.q0)
    assert np.all(np.abs(turned) <= 0.3) and np.any(np.abs(turned) > 0.01)
    observation, *_ = env.step(np.zeros(10))
    assert np.all(np.isfinite(observation))


def test_the_render_draws_the_vehicle_at_its_size_and_attitude():
    """Its hull box (the first box collision of the root link), turned with the vehicle; not a
    0.1 m square for every vehicle."""
    import pinocchio as pin

    from uvms_pin.apps.gym.render import _outline_xz, vehicle_box

    env = _make(FORCE, scenario="bluerov_alpha5_force_tracking").unwrapped
    centre, size = vehicle_box(env.scenario.uvms)
    np.testing.assert_allclose(size, [0.457, 0.575, 0.254])  # the BlueROV2 Heavy's hull
    pitch = 0.3
    data = env.scenario.uvms.model.createData()
    q = env.scenario.q0.copy()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.0, pitch, 0.0)).coeffs()
    pin.forwardKinematics(env.scenario.uvms.model, data, q)
    outline = _outline_xz(data, (centre, size))
    width = np.ptp(outline[:, 0])
    assert width == pytest.approx(size[0] * np.cos(pitch) + size[2] * np.sin(pitch))
    lbv = _make(FORCE).unwrapped
    np.testing.assert_allclose(vehicle_box(lbv.scenario.uvms)[1], [0.53, 0.245, 0.254])


# the BlueROV2 + Alpha 5 force task on the model whose jaw's two fingers move: its [gripper]
# servo (closed from the start, by default) drives them
JAW_MODEL = {
    "scenario": "bluerov_alpha5_force_tracking",
    "model": "uvms_bluerov2_alpha5_jaws",
}
JAW_OVERRIDES = {
    "initial.joint_positions_rad": [-0.2, 0.8, 2.2, 0.2, 0.0, 0.0],
    "initial.velocity": [0.0] * 12,
}


def test_the_scenarios_controller_beside_its_jaw_servo_through_the_environment_is_uvms_pin_run():
    # the scenario's controller (the PPC beside the servo) as the policy: it gives the
    # vehicle's and arm's entries, the environment's own servo the jaw's
    q_env, q_run = _ppc_script().ppc_through_env(
        JAW_MODEL["scenario"], 0.3, JAW_MODEL["model"], JAW_OVERRIDES
    )
    assert q_env.shape == q_run.shape == (31, 13)
    assert np.max(np.abs(q_run[-1] - q_run[0])) > 1e-3  # the run moves
    np.testing.assert_allclose(q_env, q_run, rtol=0, atol=1e-9)
    env = gym.make(FORCE, **JAW_MODEL, overrides={**JAW_OVERRIDES, **SHORT}).unwrapped
    jaw = env.jaw_servo.jaw
    assert env.action_space.shape == (env.scenario.uvms.nv - jaw.count,)
    np.testing.assert_array_equal(env.action_index, jaw.arm_v_index)


def test_random_actions_leave_a_servoed_jaw_to_its_servo_on_the_measured_jaw():
    # noisy joints: the servo must read the measurement, as beside a controller
    noise = {"sensors.joint_noise_rad": 0.001, "sensors.velocity_noise": 0.005}
    env = gym.make(STATION, **JAW_MODEL, overrides={**JAW_OVERRIDES, **SHORT, **noise})
    env = env.unwrapped
    servo, layout = env.jaw_servo, env.observation_layout
    jaw = servo.jaw
    env.action_space.seed(5)
    observation, info = env.reset(seed=5)
    expected = []
    for _ in range(40):
        q, v = observation[layout["q"]], observation[layout["v"]]
        expected.append(servo.torque(info["time_s"], q[jaw.q_index], v[jaw.v_index]))
        observation, _, terminated, truncated, info = env.step(env.action_space.sample())
        assert not (terminated or truncated)
    tau = env.episode_rollout().signals["tau_commanded"][:40]
    np.testing.assert_array_equal(tau[:, jaw.v_index], expected)
    assert np.abs(np.array(expected)).max() > 0.0  # the servo acted
    # the fingers stay within their velocity limit (10 rad/s): a random torque of their
    # 10 N m effort limit on a 4e-5 kg m^2 finger turned it at over 100 rad/s in one step
    assert np.abs(env.episode_rollout().v[:, jaw.v_index]).max() < 10.0
