"""The native vector environments (uvms_pin.apps.gym.vector): N episodes in one call equal
N single environments seeded the same, across autoresets, for any number of threads."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import uvms_pin.apps.gym  # noqa: F401 - registers the environments
from uvms_pin.errors import ParameterError, StiffModeError

FORCE = "uvms_pin/ForceTracking-v0"
STATION = "uvms_pin/StationKeeping-v0"
# a few control periods per episode, so that a short run crosses autoresets
EPISODES = {
    FORCE: {"overrides": {"scenario.duration_s": 0.01}},
    STATION: {"overrides": {"scenario.duration_s": 0.05}},
}


def _vector(env_id: str, num_envs: int, num_threads: int = 1, **kw):
    return gym.make_vec(
        env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
        num_threads=num_threads, **{**EPISODES[env_id], **kw},
    )  # fmt: skip


def _actions(space, steps: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    # beyond the box too: the clipping is part of what is compared
    return rng.uniform(-1.2, 1.2, (steps, *space.shape))


def _singles(env_id: str, num_envs: int, seed: int, actions: np.ndarray, **kw):
    """N single environments stepped with NEXT_STEP autoreset by hand (Gymnasium's rule)."""
    envs = [gym.make(env_id, **{**EPISODES[env_id], **kw}) for _ in range(num_envs)]
    first = [env.reset(seed=seed + i)[0] for i, env in enumerate(envs)]
    done = [False] * num_envs
    out = {"obs": [np.array(first)], "reward": [], "terminated": [], "truncated": []}
    for step_actions in actions:
        row = {k: [] for k in ("obs", "reward", "terminated", "truncated")}
        for i, env in enumerate(envs):
            if done[i]:
                obs, _ = env.reset()
                reward, terminated, truncated = 0.0, False, False
            else:
                obs, reward, terminated, truncated, _ = env.step(step_actions[i])
            done[i] = terminated or truncated
            for key, value in zip(row, (obs, reward, terminated, truncated), strict=True):
                row[key].append(value)
        for key, values in row.items():
            out[key].append(np.array(values))
    return {key: np.array(values) for key, values in out.items()}


def _vector_run(envs, seed: int, actions: np.ndarray):
    first, _ = envs.reset(seed=seed)
    out = {"obs": [first], "reward": [], "terminated": [], "truncated": []}
    for step_actions in actions:
        obs, reward, terminated, truncated, _ = envs.step(step_actions)
        for key, value in zip(out, (obs, reward, terminated, truncated), strict=True):
            out[key].append(np.array(value))
    return {key: np.array(values) for key, values in out.items()}


def _assert_same(vector, single):
    for key in ("terminated", "truncated"):
        np.testing.assert_array_equal(vector[key], single[key], err_msg=key)
    np.testing.assert_allclose(vector["obs"], single["obs"], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(vector["reward"], single["reward"], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("env_id", [FORCE, STATION])
def test_the_vector_env_is_n_single_envs_across_autoresets(env_id):
    num_envs, steps = 3, 16
    envs = _vector(env_id, num_envs, num_threads=2)
    actions = _actions(envs.action_space, steps, seed=1)
    vector = _vector_run(envs, 40, actions)
    single = _singles(env_id, num_envs, 40, actions)
    # the run crossed autoresets (episodes of 5 steps), and the NEXT_STEP rows are resets
    assert single["truncated"].any()
    _assert_same(vector, single)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP


def test_funnel_terminations_and_their_autoreset():
    # f_d(0) = 0.4 N, f(0) = 0: outside a 0.1 N funnel at once, every episode ends at once
    kw = {"funnel": (0.1, 0.05, 1.0)}
    envs = _vector(FORCE, 2, **kw)
    actions = _actions(envs.action_space, 5, seed=2)
    vector, single = _vector_run(envs, 7, actions), _singles(FORCE, 2, 7, actions, **kw)
    np.testing.assert_array_equal(vector["terminated"][:, 0], [True, False] * 2 + [True])
    _assert_same(vector, single)


@pytest.mark.parametrize("env_id", [FORCE, STATION])
def test_any_number_of_threads_gives_the_same_numbers(env_id):
    actions = _actions(_vector(env_id, 5).action_space, 8, seed=3)
    runs = [_vector_run(_vector(env_id, 5, num_threads=t), 11, actions) for t in (1, 2, 3, 8)]
    for run in runs[1:]:
        for key in run:
            np.testing.assert_array_equal(run[key], runs[0][key], err_msg=key)


def test_seeding_is_deterministic_and_seeds_differ():
    actions = _actions(_vector(STATION, 2).action_space, 4, seed=4)
    a, b = (_vector_run(_vector(STATION, 2), 21, actions) for _ in range(2))
    np.testing.assert_array_equal(a["obs"], b["obs"])
    other = _vector_run(_vector(STATION, 2), 22, actions)
    assert not np.allclose(a["obs"][0], other["obs"][0])
    # the environments of a batch get different seeds: different first observations
    assert not np.allclose(a["obs"][0][0], a["obs"][0][1])
    envs = _vector(STATION, 2)
    _, infos = envs.reset(seed=[5, 9])
    np.testing.assert_array_equal(infos["seed"], [5, 9])
    unseeded = [envs.reset()[1]["seed"] for _ in range(2)]
    assert unseeded[0].tolist() != unseeded[1].tolist()


def test_same_step_autoreset_keeps_the_final_observation():
    next_step = _vector(STATION, 2)
    same_step = _vector(STATION, 2, autoreset_mode=AutoresetMode.SAME_STEP)
    assert same_step.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    actions = _actions(next_step.action_space, 6, seed=5)
    next_step.reset(seed=3)
    same_step.reset(seed=3)
    for k in range(5):  # episodes of 5 steps: the 5th ends them
        ended = next_step.step(actions[k])
        result = same_step.step(actions[k])
        np.testing.assert_array_equal(result[1], ended[1])
    assert ended[3].all() and result[3].all()
    infos = result[4]
    assert infos["_final_obs"].all()
    for i in range(2):
        np.testing.assert_array_equal(infos["final_obs"][i], ended[0][i])
    # NEXT_STEP returns the new episode's first observation one step later
    restarted = next_step.step(actions[5])
    np.testing.assert_array_equal(result[0], restarted[0])
    np.testing.assert_array_equal(restarted[1], [0.0, 0.0])


def test_divergence_ends_that_episode_only():
    # unlimited actuation with an absurd scale on one environment's command: it blows up
    envs = gym.make_vec(
        STATION, num_envs=2, vectorization_mode="vector_entry_point",
        scenario="passive_still_water", overrides={"control.period_s": 0.002},
        action_scale=np.full(10, 1e12),
    )  # fmt: skip
    observations, _ = envs.reset(seed=0)
    actions = np.zeros((2, 10))
    actions[0] = 1.0
    for _ in range(5):
        observations, reward, terminated, truncated, infos = envs.step(actions)
        if terminated[0]:
            break
    assert terminated[0] and not truncated[0] and infos["diverged"][0]
    assert reward[0] == -100.0
    assert not terminated[1] and not infos["diverged"][1]
    assert np.all(np.isfinite(observations))
    observations, reward, *_ = envs.step(actions)  # NEXT_STEP: a new episode
    assert reward[0] == 0.0 and np.all(np.isfinite(observations))


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"num_envs": 0}, "num_envs"),
        ({"num_envs": -2}, "num_envs"),
        ({"num_threads": 0}, "num_threads"),
        ({"num_threads": 1.5}, "num_threads"),
        ({"autoreset_mode": "sometimes"}, "autoreset_mode"),
        ({"render_mode": "rgb_array"}, "render"),
    ],
)
def test_bad_arguments_are_clear_errors(kw, match):
    kw = {"num_envs": 2, **kw}
    with pytest.raises(ParameterError, match=match):
        gym.make_vec(STATION, vectorization_mode="vector_entry_point", **kw)


def test_bad_steps_are_clear_errors():
    envs = _vector(STATION, 2)
    with pytest.raises(ParameterError, match="reset"):
        envs.step(np.zeros((2, 10)))
    envs.reset(seed=0)
    with pytest.raises(ParameterError, match="actions"):
        envs.step(np.zeros((3, 10)))
    with pytest.raises(ParameterError, match="actions"):
        envs.step(np.full((2, 10), np.nan))
    with pytest.raises(ParameterError, match="actions"):  # was numpy's ValueError
        envs.step([["a"] * 10] * 2)


def test_unsupported_plants_are_refused():
    with pytest.raises(ParameterError, match="flow"):
        gym.make_vec(
            FORCE, num_envs=2, vectorization_mode="vector_entry_point",
            scenario="sea_state_force_tracking",
        )  # fmt: skip


def test_a_stiff_mode_is_refused_before_the_batch_is_built():
    """The vector environment refuses what its single environment refuses at reset: the
    compliant stops of StationKeeping's light wrist are unstable at its RK4 step (named,
    with the largest stable step), so no batch is built and no episode diverges."""
    overrides = {"joints.stops": "compliant"}
    with pytest.raises(StiffModeError) as single:
        gym.make(STATION, overrides=overrides).reset(seed=0)
    with pytest.raises(StiffModeError) as vector:
        _vector(STATION, 2, overrides=overrides)
    assert str(vector.value) == str(single.value)
    assert "compliant stop of joint" in str(vector.value)
    assert "largest stable step" in str(vector.value)


def test_the_defaults_record_their_stiffest_mode():
    envs = _vector(STATION, 2)
    assert envs.unwrapped.stiff_modes["checked"] is True
    envs.close()


def test_with_a_servoed_jaw_the_vector_env_is_n_single_envs():
    # the model whose jaw's fingers move, its [gripper] servo driving them from each
    # environment's measured jaw at its own time (episodes of 5 steps, so across resets),
    # noisy joints so that the measurement differs from the state
    kw = {
        "scenario": "bluerov_alpha5_force_tracking",
        "model": "uvms_bluerov2_alpha5_jaws",
        "overrides": {
            "initial.joint_positions_rad": [-0.2, 0.8, 2.2, 0.2, 0.0, 0.0],
            "initial.velocity": [0.0] * 12,
            "sensors.joint_noise_rad": 0.001,
            "sensors.velocity_noise": 0.005,
            "scenario.duration_s": 0.01,
        },
    }
    num_envs, steps = 3, 16
    envs = _vector(FORCE, num_envs, num_threads=2, **kw)
    assert envs.single_action_space.shape == (10,)  # 12 but the two fingers
    actions = _actions(envs.action_space, steps, seed=2)
    vector = _vector_run(envs, 40, actions)
    single = _singles(FORCE, num_envs, 40, actions, **kw)
    assert single["truncated"].any()
    _assert_same(vector, single)
