"""The native vector environment against MuJoCo's ``rollout`` of its twin's plant alone.

Environment steps per second of ``gym.make_vec("uvms_pin/ForceTracking-v0",
vectorization_mode="vector_entry_point", num_threads=T)`` (random actions; the full step:
actuation, plant, contact, sensor noise, observation, reward, autoreset) and 2 ms control
periods per second of ``mujoco.rollout`` on the MuJoCo twin of the same vehicle and arm
(benchmarks/bench_mujoco.py: RK4 at 0.5 ms, 4 ``mj_step`` per period, random generalized
forces in ``qfrc_applied``, ``num_envs`` trajectories on T threads, many periods per call),
each as the best of interleaved rounds of wall-clock time (threads: CPU time would add
them up). Reported as ratios uvms-pin / MuJoCo at each T and T = 2 / T = 1.
"""

from __future__ import annotations

import math
import time

import gymnasium as gym
import mujoco
import numpy as np
from bench_mujoco import CONTROL_PERIOD_S, REFERENCE_URDF, build_system, mujoco_data
from mujoco import rollout

import uvms_pin as up
import uvms_pin.apps.gym

ENV = "uvms_pin/ForceTracking-v0"


def vector_case(num_envs: int, num_threads: int, steps: int):
    """A call running ``steps`` steps of the vector environment; its env steps."""
    envs = gym.make_vec(
        ENV, num_envs=num_envs, vectorization_mode="vector_entry_point", num_threads=num_threads
    )
    envs.reset(seed=0)
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1.0, 1.0, (steps, *envs.action_space.shape))

    def run() -> None:
        for a in actions:
            envs.step(a)

    return run, num_envs * steps


def mujoco_case(num_envs: int, num_threads: int, periods: int):
    """A call rolling ``num_envs`` twins out over ``periods`` control periods on
    ``num_threads`` threads; its periods."""
    uvms = up.load_uvms(REFERENCE_URDF)
    q0 = uvms.neutral_configuration()
    q0[7:] = [-0.2, 1.0, -0.8, 0.2]  # the realistic scenario's arm
    system = build_system("reference", uvms, REFERENCE_URDF.read_text(), q0)
    model = system.mj_model
    data = mujoco_data(system, system.q0, system.v0)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    steps = round(CONTROL_PERIOD_S / model.opt.timestep) * periods
    rng = np.random.default_rng(0)
    control = rng.uniform(-5.0, 5.0, (num_envs, steps, model.nv))
    datas = [mujoco.MjData(model) for _ in range(num_threads)]
    initial = np.tile(state, (num_envs, 1))
    out = np.empty((num_envs, steps, state.size))

    def run() -> None:
        rollout.rollout(
            model, datas if num_threads > 1 else datas[0], initial, control,
            control_spec=mujoco.mjtState.mjSTATE_QFRC_APPLIED, state=out,
            persistent_pool=num_threads > 1,
        )  # fmt: skip

    return run, num_envs * periods


def best_rates(cases: dict, repeat: int) -> dict[str, float]:
    """Best units per wall second of each (call, units) case over interleaved rounds."""
    for run, _ in cases.values():
        run()  # first calls build caches and pools
    best = dict.fromkeys(cases, math.inf)
    for _ in range(repeat):
        for name, (run, _) in cases.items():
            start = time.perf_counter()
            run()
            best[name] = min(best[name], time.perf_counter() - start)
    return {name: cases[name][1] / best[name] for name in cases}


def run(num_envs: int, steps: int, repeat: int) -> dict[str, float]:
    cases = {}
    for threads in (1, 2):
        cases[f"vector_T{threads}"] = vector_case(num_envs, threads, steps)
        cases[f"mujoco_T{threads}"] = mujoco_case(num_envs, threads, steps)
    rates = best_rates(cases, repeat)
    out = {f"{name}_per_s": rate for name, rate in rates.items()}
    for threads in (1, 2):
        out[f"vector_over_mujoco_T{threads}"] = (
            rates[f"vector_T{threads}"] / rates[f"mujoco_T{threads}"]
        )
    out["vector_T2_over_T1"] = rates["vector_T2"] / rates["vector_T1"]
    out["mujoco_T2_over_T1"] = rates["mujoco_T2"] / rates["mujoco_T1"]
    out["num_envs"] = num_envs
    return out
