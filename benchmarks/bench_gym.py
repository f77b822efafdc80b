"""Environment steps per second of the uvms-pin Gymnasium environments, as ratios to one
``pin.aba`` call.

    .venv/bin/python benchmarks/bench_gym.py [--steps N] [--repeat N] [--json FILE]

For each environment (default scenario, zero action so the episode runs its full length):
CPU time per ``env.step`` (``time.process_time``, best of ``--repeat`` batches of
``--steps`` steps; on a shared machine the wait for a core does not count), reported as

- environment steps per second of CPU;
- simulated seconds per CPU second (a step is one control period);
- the cost of a step in ``pin.aba`` calls on the same model (rigid-body ABA, timed in the
  same process), which compares across machines: a step integrates one control period
  (RK4 substeps of the full hydrodynamic forward dynamics, 4 per substep) and measures.

Also ``gymnasium.vector.SyncVectorEnv`` with 4 copies (steps of all copies per second),
and the native vector environment (``vectorization_mode="vector_entry_point"``) at T = 1
and T = 2 threads as ratios to MuJoCo's ``rollout`` of its twin's plant alone, in wall-clock
time (benchmarks/bench_vector.py).
"""

from __future__ import annotations

import argparse
import json
import time

import gymnasium as gym
import numpy as np
import pinocchio as pin
from bench_vector import run as run_vector
from timing import best_times, one_blas_thread

import uvms_pin.apps.gym  # noqa: F401 - registers the environments

ENVS = ("uvms_pin/ForceTracking-v0", "uvms_pin/StationKeeping-v0")


def aba_time(model: pin.Model, repeat: int) -> float:
    """Best CPU time of one pin.aba call at a random state [s]."""
    data = model.createData()
    rng = np.random.default_rng(0)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v, tau = rng.standard_normal(model.nv), rng.standard_normal(model.nv)
    return best_times({"aba": lambda: pin.aba(model, data, q, v, tau)}, max(repeat, 20))["aba"]


def step_time(env: gym.Env, steps: int, repeat: int) -> float:
    """Best CPU time of one step [s] (zero action; reset between batches, not timed)."""
    zero = np.zeros(env.action_space.shape)
    best = np.inf
    for batch in range(repeat):
        env.reset(seed=batch)
        start = time.process_time()
        for _ in range(steps):
            _, _, terminated, truncated, _ = env.step(zero)
            if terminated or truncated:
                env.reset(seed=batch)
        best = min(best, (time.process_time() - start) / steps)
    return best


def run(steps: int, repeat: int) -> dict[str, dict[str, float]]:
    out = {}
    for env_id in ENVS:
        env = gym.make(env_id).unwrapped
        model = env.scenario.uvms.model
        aba = aba_time(model, repeat)
        step = step_time(env, steps, repeat)
        period = env.scenario.settings.control_period_s
        out[env_id] = {
            "control_period_s": period,
            "step_s": step,
            "steps_per_s": 1.0 / step,
            "simulated_s_per_s": period / step,
            "step_in_aba_calls": step / aba,
            "aba_s": aba,
        }
        vector = gym.make_vec(env_id, num_envs=4, vectorization_mode="sync")
        vector.reset(seed=0)
        zeros = np.zeros((4, *vector.single_action_space.shape))
        start = time.process_time()
        for _ in range(steps):
            vector.step(zeros)
        out[env_id]["sync_vector_4_env_steps_per_s"] = 4 * steps / (time.process_time() - start)
        vector.close()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--vector-envs", type=int, default=64, help="N of the vector env")
    parser.add_argument("--vector-steps", type=int, default=50, help="steps per timed call")
    parser.add_argument("--json", help="also write the results to this file")
    args = parser.parse_args()
    one_blas_thread()
    results = run(args.steps, args.repeat)
    vector = run_vector(args.vector_envs, args.vector_steps, max(args.repeat, 5))
    for env_id, r in results.items():
        print(
            f"{env_id}: {r['steps_per_s']:.0f} steps/s, {r['simulated_s_per_s']:.2f} simulated s/s "
            f"(control period {r['control_period_s'] * 1e3:g} ms), one step = "
            f"{r['step_in_aba_calls']:.0f} pin.aba calls (aba {r['aba_s'] * 1e6:.2f} us); "
            f"SyncVectorEnv x4: {r['sync_vector_4_env_steps_per_s']:.0f} env steps/s"
        )
    print(
        f"vector env (ForceTracking, N = {vector['num_envs']}, wall clock): "
        f"T=1 {vector['vector_T1_per_s']:.0f} env steps/s = "
        f"{vector['vector_over_mujoco_T1']:.2f}x mujoco.rollout ({vector['mujoco_T1_per_s']:.0f} "
        f"periods/s); T=2 {vector['vector_T2_per_s']:.0f} env steps/s = "
        f"{vector['vector_over_mujoco_T2']:.2f}x mujoco.rollout ({vector['mujoco_T2_per_s']:.0f} "
        f"periods/s); T=2 / T=1 = {vector['vector_T2_over_T1']:.2f} "
        f"(mujoco.rollout {vector['mujoco_T2_over_T1']:.2f})"
    )
    if args.json:
        with open(args.json, "w") as f:
            json.dump({**results, "vector_entry_point": vector}, f, indent=2)


if __name__ == "__main__":
    main()
