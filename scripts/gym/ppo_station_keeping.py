"""PPO (stable-baselines3) learning uvms_pin/StationKeeping-v0 on the native vector
environment, and its learning curve: mean reward per step of the finished episodes against
environment steps and wall time.

    pip install torch==2.13.0   # a CPU build of torch first (else pip may fetch a CUDA one)
    pip install -e '.[rl]'
    python scripts/gym/ppo_station_keeping.py --timesteps 300000 --num-envs 16 --threads 2 \\
        --out docs/ppo_station_keeping.png

The zero action (the thrusters idle: the current carries the vehicle off) and a random
policy are drawn for reference: what PPO must beat.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode

import uvms_pin.apps.gym  # noqa: F401 - registers the environments

ENV = "uvms_pin/StationKeeping-v0"


def make_vector(num_envs: int, threads: int, duration_s: float):
    return gym.make_vec(
        ENV, num_envs=num_envs, vectorization_mode="vector_entry_point", num_threads=threads,
        autoreset_mode=AutoresetMode.SAME_STEP, overrides={"scenario.duration_s": duration_s},
    )  # fmt: skip


def baseline(policy: str, num_envs: int, threads: int, duration_s: float, seed: int) -> float:
    """Mean reward per step over one episode of each environment: zero or random actions."""
    envs = make_vector(num_envs, threads, duration_s)
    envs.reset(seed=seed)
    rng = np.random.default_rng(seed)
    total, steps = np.zeros(num_envs), np.zeros(num_envs)
    alive = np.ones(num_envs, dtype=bool)
    while alive.any():
        shape = envs.action_space.shape
        actions = np.zeros(shape) if policy == "zero" else rng.uniform(-1.0, 1.0, shape)
        _, reward, terminated, truncated, _ = envs.step(actions)
        total += np.where(alive, reward, 0.0)
        steps += alive
        alive &= ~(terminated | truncated)
    return float(np.mean(total / steps))


def train(args) -> dict:
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from uvms_pin.apps.gym.sb3 import Sb3VecEnv

    torch.set_num_threads(args.torch_threads)  # the batch has its own threads
    venv = VecMonitor(Sb3VecEnv(make_vector(args.num_envs, args.threads, args.duration)))
    if args.normalize:
        # running mean/std of observations and returns (the monitor inside logs raw rewards):
        # the observation mixes metres, radians and newtons
        venv = VecNormalize(venv, gamma=0.99)
    venv.seed(args.seed)
    curve: list[dict] = []
    start = time.perf_counter()

    class Curve(BaseCallback):
        def _on_step(self) -> bool:
            return True

        def _on_rollout_end(self) -> None:
            episodes = list(self.model.ep_info_buffer)
            if episodes:
                per_step = [e["r"] / e["l"] for e in episodes]
                curve.append({
                    "env_steps": int(self.num_timesteps),
                    "wall_s": time.perf_counter() - start,
                    "reward_per_step": float(np.mean(per_step)),
                    "episode_length": float(np.mean([e["l"] for e in episodes])),
                })  # fmt: skip

    model = PPO(
        "MlpPolicy", venv, n_steps=args.n_steps, batch_size=256, seed=args.seed, verbose=0,
        device="cpu",
    )  # fmt: skip
    model.learn(total_timesteps=args.timesteps, callback=Curve())
    return {"curve": curve, "wall_s": time.perf_counter() - start}


def figure(result: dict, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curve = result["curve"]
    steps = [c["env_steps"] for c in curve]
    wall = [c["wall_s"] for c in curve]
    reward = [c["reward_per_step"] for c in curve]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, x, label in ((axes[0], steps, "environment steps"), (axes[1], wall, "wall time [s]")):
        ax.plot(x, reward, label="PPO (last 100 episodes)")
        ax.axhline(result["zero_action"], color="gray", ls="--", label="zero action")
        ax.axhline(result["random_action"], color="gray", ls=":", label="random actions")
        ax.set_xlabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("mean reward per step")
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle(result["title"], fontsize=9)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=300_000)
    parser.add_argument("--num-envs", type=int, default=16)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--torch-threads", type=int, default=1, help="torch's threads")
    parser.add_argument("--n-steps", type=int, default=256, help="PPO steps per env per update")
    parser.add_argument("--duration", type=float, default=4.0, help="episode length [s]")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--no-normalize", dest="normalize", action="store_false",
        help="feed raw observations and rewards (default: VecNormalize)",
    )  # fmt: skip
    parser.add_argument("--out", type=Path, default=Path("docs/ppo_station_keeping.png"))
    args = parser.parse_args()
    result = train(args)
    for policy in ("zero", "random"):
        result[f"{policy}_action"] = baseline(
            policy, args.num_envs, args.threads, args.duration, args.seed + 1
        )
    result["title"] = (
        f"PPO on {ENV} ({args.duration:g} s episodes), {args.num_envs} envs, "
        f"{args.threads} threads, seed {args.seed}: {args.timesteps} steps in "
        f"{result['wall_s']:.0f} s"
    )
    figure(result, args.out)
    args.out.with_suffix(".json").write_text(json.dumps(result, indent=1))
    last = result["curve"][-1] if result["curve"] else {}
    print(
        f"{result['title']}; last mean reward per step {last.get('reward_per_step', float('nan')):.3f} "
        f"(zero action {result['zero_action']:.3f}, random {result['random_action']:.3f}); "
        f"wrote {args.out}"
    )


if __name__ == "__main__":
    main()
