"""Stable at the defaults, where users go first: the shipped BlueROV2 Heavy + Alpha 5
released with no input (its light wrist against its joint limits), which the compliant stops
make diverge at the default step (refused before the run now: `uvms_pin.sim.stiffness`), runs
on its limits as constraints, compiled;
the station-keeping environment under uniform random actions has no diverged step.
(`scripts/results/stability.py` runs the long versions: 60 s, 64 environments x 3,000 steps.)"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import uvms_pin.apps.gym  # noqa: F401  (registers the environments)
from uvms_pin.results.metrics import joint_limit_metrics
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

PASSIVE = Path(__file__).resolve().parents[2] / "scenarios" / "passive_still_water.toml"
ALPHA5 = {
    "scenario.model": "uvms_bluerov2_alpha5",
    "scenario.duration_s": 4.0,
    "initial.joint_positions_rad": [-0.2, 0.8, 2.2, 0.2],  # within the Alpha 5's limits
}


def test_the_passive_alpha5_holds_on_its_limits_and_on_its_compliant_stops():
    rollout = simulate(load_scenario(PASSIVE, ALPHA5), progress=False)
    assert rollout.metadata["status"] == "ok"
    assert rollout.metadata["closed_loop"]["path"] == "compiled"  # the zero law, the limits
    limits = joint_limit_metrics(rollout)
    assert limits["joint_limit_excess_max_rad"] < 1e-6
    assert limits["time_at_joint_stop_s"] > 0.1  # the arm did fall onto its limits
    assert np.abs(rollout.v).max() < 50.0

    # the same on the compliant stops, which diverged at t = 19.2 s (the wrist at 179 rad/s)
    # before the drives' armature: accepted before the run and held to its end (a wrist
    # without it is refused: tests/sim/test_stiffness.py)
    compliant = {**ALPHA5, "joints.stops": "compliant", "scenario.duration_s": 20.0}
    stops = simulate(load_scenario(PASSIVE, compliant), progress=False)
    assert stops.metadata["status"] == "ok" and stops.metadata["stiff_modes"]["margin"] > 1.0
    assert "alpha_axis_b" in stops.metadata["stiff_modes"]["stiffest"]["what"]
    assert np.all(np.isfinite(stops.v)) and np.abs(stops.v).max() < 50.0


def test_random_actions_do_not_diverge_the_station_keeping_environment():
    envs = gym.make_vec(
        "uvms_pin/StationKeeping-v0", num_envs=8, vectorization_mode="vector_entry_point"
    )
    envs.action_space.seed(3)
    envs.reset(seed=3)
    batch, arm = envs.unwrapped.batch, envs.unwrapped.single_env.scenario.uvms.arm_joints
    diverged, worst_rad, at_limit = 0, -np.inf, 0
    for _ in range(400):
        *_, infos = envs.step(envs.action_space.sample())
        diverged += int(np.sum(infos["diverged"]))
        positions = np.array([arm.positions(q) for q in np.asarray(batch.q)])
        gap = np.minimum(positions - arm.lower, arm.upper - positions)[:, arm.limited]
        worst_rad = max(worst_rad, float(-gap.min()))
        at_limit += int(np.sum(gap.min(axis=1) <= 1e-6))
    envs.close()
    assert diverged == 0
    assert at_limit > 100  # the random torques did drive the arm onto its limits ...
    assert worst_rad <= 1e-9  # ... and the batch's solve held it there


def test_the_limits_solved_in_the_core_are_the_python_loops():
    """The compiled loop against the Python loop on the same compiled plant (the same solve:
    to rounding), and against the Python reference throughout (Pinocchio's ADMM at its 1e-8:
    the arm lands on its limits at the same ticks, the states agree to its tolerance)."""
    short = {**ALPHA5, "scenario.duration_s": 1.5}
    compiled = simulate(load_scenario(PASSIVE, short), progress=False)
    python_loop = simulate(load_scenario(PASSIVE, short), progress=False, compiled_loop=False)
    assert python_loop.metadata["closed_loop"]["path"] == "python"
    np.testing.assert_allclose(python_loop.q, compiled.q, atol=1e-12)
    np.testing.assert_allclose(python_loop.v, compiled.v, atol=1e-10)
    reference = simulate(
        load_scenario(PASSIVE, {**short, "integrator.backend": "python"}), progress=False
    )
    at_limit = [joint_limit_metrics(r)["time_at_joint_stop_s"] for r in (compiled, reference)]
    assert at_limit[0] > 0.1 and at_limit[0] == pytest.approx(at_limit[1], abs=0.05)
    np.testing.assert_allclose(reference.q, compiled.q, atol=1e-4)
