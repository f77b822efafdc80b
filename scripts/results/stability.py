"""Stable at the defaults: the shipped UVMS released with no input for 60 s at the default
step (how far a joint ever went past its limit), and the Gymnasium environments driven by
uniform random actions (64 environments x 3,000 steps each: how many episodes diverged, how
fast the arms' joints turn)."""

from __future__ import annotations

import importlib
import time

import gymnasium as gym
import numpy as np
from _common import ROOT, producer_cli, scratch, uvms_pin, write_result

import uvms_pin as up
from uvms_pin.results.metrics import joint_limit_metrics

PASSIVE = "scenarios/passive_still_water.toml"
#: each model with a start within its joint limits (the scenario's velocity swings the arm)
MODELS = {"uvms_bluerov2_alpha5": "[-0.2, 0.8, 2.2, 0.2]", "uvms_lbv150": "[0.0, 0.5, -0.5, 0.0]"}
#: each environment as registered, and station keeping on the BlueROV2 Heavy + Alpha 5
ENVIRONMENTS = (
    ("uvms_pin/StationKeeping-v0", None),
    ("uvms_pin/ForceTracking-v0", None),
    ("uvms_pin/StationKeeping-v0", "scenarios/bluerov_alpha5_force_tracking.toml"),
)
NUM_ENVS, STEPS, SEED = 64, 3000, 2026

importlib.import_module("uvms_pin.apps.gym")  # registers the environments


def passive_rows() -> list[str]:
    rows = []
    for model, joints in MODELS.items():
        out = scratch(f"stability/{model}")
        result = uvms_pin(
            "run", PASSIVE, "--out", str(out), "--quiet",
            "--set", f'scenario.model="{model}"', "--set", "scenario.duration_s=60",
            "--set", f"initial.joint_positions_rad={joints}",
        )  # fmt: skip
        rollout = up.Rollout.load(out)
        meta, world = rollout.metadata, rollout.metadata["world"]
        limits = joint_limit_metrics(rollout)
        kind = (
            "constraints"
            if world["joint_limits"]
            else "compliant"
            if world["joint_stops"]
            else "none"
        )
        rows.append(
            f"| {model} | {meta['status']} (exit {result.returncode}) | "
            f"{rollout.time_s[-1]:.2f} | {kind} | {meta['closed_loop']['path']} | "
            f"{limits['joint_limit_excess_max_rad']:.1e} | {limits['time_at_joint_stop_s']:.2f} | "
            f"{np.abs(rollout.v[:, 6:]).max():.2f} | {meta['real_time_factor']:.0f} |"
        )
    return rows


def random_action_rows() -> list[str]:
    rows = []
    for env_id, scenario in ENVIRONMENTS:
        kwargs = {} if scenario is None else {"scenario": str(ROOT / scenario)}
        envs = gym.make_vec(
            env_id, num_envs=NUM_ENVS, vectorization_mode="vector_entry_point", **kwargs
        )
        envs.action_space.seed(SEED)
        envs.reset(seed=SEED)
        diverged = episodes = 0
        # each step's fastest arm joint over the environments [rad/s]: what random torques
        # at the effort limits make of the arm's inertia (its drives' armature included)
        joint_rates = np.empty(STEPS)
        start = time.perf_counter()
        for k in range(STEPS):
            _, _, terminated, truncated, infos = envs.step(envs.action_space.sample())
            diverged += int(np.sum(infos["diverged"]))
            episodes += int(np.sum(terminated | truncated))
            joint_rates[k] = np.abs(envs.batch.v[:, 6:]).max()
        wall_s = time.perf_counter() - start
        envs.close()
        rows.append(
            f"| `{env_id}`{'' if scenario is None else f' on `{scenario}`'} "
            f"| {NUM_ENVS} x {STEPS} | {episodes} | {diverged} "
            f"| {np.median(joint_rates):.2f} | {joint_rates.max():.1f} | {wall_s:.1f} |"
        )
    return rows


def main() -> None:
    passive = passive_rows()
    random = random_action_rows()
    body = (
        f"`uvms-pin run {PASSIVE} --set scenario.model=... --set scenario.duration_s=60`: "
        "no controller, RK4 at the scenario's 2 ms step (a passive run is sampled at the "
        "integrator's step, its joint limits solved implicitly at each):\n\n"
        "| model | status | simulated [s] | joint limits | loop | largest excess past a limit "
        "[rad] | time some joint is at a limit [s] | fastest joint rate [rad/s] "
        "| real-time factor |\n|---|---|---|---|---|---|---|---|---|\n"
        + "\n".join(passive)
        + "\n\nThe vector environments (`gym.make_vec(..., vectorization_mode="
        '"vector_entry_point")`) driven by `action_space.sample()` (seed '
        f"{SEED}), autoreset on; a step's fastest arm joint is the largest |qdot| over the "
        "environments after it (the URDFs' velocity limits: the reference arm's 1.5 and 2 "
        "rad/s, the Alpha 5's 0.5 and 1 rad/s):\n\n"
        "| environment | environments x steps | episodes ended | diverged steps "
        "| a step's fastest arm joint, median [rad/s] | fastest arm joint [rad/s] "
        "| wall [s] |\n|---|---|---|---|---|---|---|\n" + "\n".join(random) + "\n"
    )
    write_result(
        "stability",
        "Stable at the defaults: passive models and random actions",
        "python scripts/results/stability.py",
        body,
    )


if __name__ == "__main__":
    producer_cli(__doc__)
    main()
