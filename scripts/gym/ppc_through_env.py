"""A random policy, then the scenario's PPC driven through the Gymnasium API, compared with
``uvms-pin run`` (the same scenario and seed): the trajectories agree to rounding.

    python scripts/gym/ppc_through_env.py [--scenario realistic_force_tracking] [--duration 2]
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import uvms_pin.apps.gym  # noqa: F401 - registers the environments
from uvms_pin.apps.gym.env import scenario_path
from uvms_pin.apps.gym.policy import ControllerPolicy
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate


def random_episode(scenario: str, seed: int, steps: int) -> float:
    """Return of ``steps`` uniformly random actions (or fewer if the episode ends)."""
    env = gym.make("uvms_pin/ForceTracking-v0", scenario=scenario)
    env.action_space.seed(seed)
    env.reset(seed=seed)
    total = 0.0
    for _ in range(steps):
        _, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        total += reward
        if terminated or truncated:
            break
    env.close()
    return total


def ppc_through_env(
    scenario: str,
    duration_s: float,
    model: str | None = None,
    overrides: dict | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(q of the scenario's controller run through the environment, q of ``uvms-pin run``)
    at the log times; ``model`` and ``overrides`` as `gym.make` takes them."""
    overrides = {**(overrides or {}), "scenario.duration_s": duration_s}
    model_override = {} if model is None else {"scenario.model": model}
    reference = load_scenario(scenario_path(scenario), {**overrides, **model_override})
    expected = simulate(reference, progress=False)
    env = gym.make(
        "uvms_pin/ForceTracking-v0",
        scenario=scenario,
        model=model,
        overrides=overrides,
        clip_actions=False,
        initial_position_noise_m=0.0,
        initial_joint_noise_rad=0.0,
    ).unwrapped
    policy = ControllerPolicy(reference.controller_factory(reference.uvms), env)
    observation, info = env.reset(seed=reference.settings.seed)
    done = False
    while not done:
        observation, _, terminated, truncated, info = env.step(policy(observation, info))
        done = terminated or truncated
    rollout = env.episode_rollout()
    return rollout.q[:: reference.settings.ticks_per_log], expected.q


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="realistic_force_tracking")
    parser.add_argument("--duration", type=float, default=2.0, help="simulated seconds")
    parser.add_argument("--seed", type=int, default=0, help="random policy's seed")
    args = parser.parse_args()
    ret = random_episode(args.scenario, args.seed, 500)
    print(f"random policy, 500 steps at most: return {ret:.4g}")
    q_env, q_run = ppc_through_env(args.scenario, args.duration)
    gap = float(np.max(np.abs(q_env - q_run)))
    # the run takes the compiled loop, the environment Python's: sums in another order
    verdict = "below 1e-12: rounding only" if gap < 1e-12 else "above 1e-12: NOT rounding"
    print(
        f"PPC through the environment vs uvms-pin run, {len(q_run)} samples: "
        f"max |dq| = {gap:.3g} ({verdict})"
    )


if __name__ == "__main__":
    main()
