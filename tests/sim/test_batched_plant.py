"""The compiled batch of plants (uvms_pin.sim.batched_plant): each environment is one ClosedLoop of
its own (actuation, one control period, contact, seeded sensor noise) to 1e-12, whatever
the number of threads."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.apps.gym.env import scenario_path
from uvms_pin.errors import ParameterError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.batched_plant import DIVERGED, RUNNING, BatchedPlant
from uvms_pin.sim.closed_loop import ClosedLoop
from uvms_pin.sim.sensors import SensorSuite

# force tracking: a spring contact, force noise, thrusters; station keeping: current,
# disturbance, noise on every state channel (orientation and joints through integrate)
NOISY_STATE = {
    "sensors.position_noise_m": 0.01,
    "sensors.orientation_noise_rad": 0.02,
    "sensors.joint_noise_rad": 0.01,
    "sensors.velocity_noise": 0.02,
    "sensors.torque_noise_Nm": 0.05,
    "sensors.distribution": "gaussian",
}
CASES = {
    "realistic_force_tracking": {"scenario.duration_s": 0.03},
    "gym_station_keeping": {"scenario.duration_s": 0.2, **NOISY_STATE},
    # the arm joints' Coulomb friction as a constraint, solved at each period's end
    "gym_station_keeping:coulomb": {"scenario.duration_s": 0.2, "joints.coulomb_Nm": [0.8] * 4},
}


def _scenario(name: str):
    return load_scenario(scenario_path(name.split(":")[0]), CASES[name])


def _starts(scenario, num_envs: int, seed: int):
    """Perturbed initial states, one per environment."""
    rng = np.random.default_rng(seed)
    q0 = np.tile(scenario.q0, (num_envs, 1))
    q0[:, :3] += rng.uniform(-0.05, 0.05, (num_envs, 3))
    q0[:, 7:] += rng.uniform(-0.05, 0.05, (num_envs, q0.shape[1] - 7))
    return q0, np.tile(scenario.v0, (num_envs, 1))


def _commands(scenario, num_envs: int, steps: int, seed: int) -> np.ndarray:
    """Commands that saturate thrusters and joints now and then."""
    actuation = scenario.plant.actuation
    scale = np.concatenate([np.full(6, 40.0), actuation.joint_effort_limits_Nm * 1.5])
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, (steps, num_envs, scenario.uvms.nv)) * scale


def _single(name: str, q0, v0, seed: int, commands: np.ndarray):
    """One environment through ClosedLoop: (true q, measured q, v, wrench, tau applied)."""
    scenario = _scenario(name)
    loop = ClosedLoop(scenario.plant, scenario.settings)
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, scenario.settings.duration_s, seed
    )
    loop.start(q0, v0, sensors)
    rows = []
    measurement, contact = loop.measure()
    rows.append((loop.q, measurement.q, measurement.v, measurement.wrench_world, contact, None))
    for tau in commands:
        applied = loop.actuate(tau)
        loop.step(applied)
        measurement, contact = loop.measure()
        rows.append((loop.q, measurement.q, measurement.v, measurement.wrench_world, contact,
                     applied))  # fmt: skip
    return rows


def _batched(name: str, q0, v0, seeds, commands, num_threads: int):
    scenario = _scenario(name)
    batch = BatchedPlant(scenario.plant, scenario.settings, scenario.sensor_config,
                         len(seeds), num_threads)  # fmt: skip
    for i, seed in enumerate(seeds):
        batch.reset(i, q0[i], v0[i], seed)
    fields = ("q", "q_measured", "v_measured", "wrench_measured", "contact_world")
    rows = [(*tuple(getattr(batch, f).copy() for f in fields), None)]
    for tau in commands:
        batch.step(tau)
        assert np.all(batch.status == RUNNING)
        rows.append((*tuple(getattr(batch, f).copy() for f in fields), batch.tau_applied.copy()))
    return rows


@pytest.mark.parametrize("name", sorted(CASES))
def test_each_environment_is_a_closed_loop_of_its_own(name):
    num_envs, steps = 3, 8
    scenario = _scenario(name)
    q0, v0 = _starts(scenario, num_envs, seed=1)
    commands = _commands(scenario, num_envs, steps, seed=2)
    seeds = [7, 8, 1234]
    batched = _batched(name, q0, v0, seeds, commands, num_threads=2)
    for i, seed in enumerate(seeds):
        single = _single(name, q0[i], v0[i], seed, commands[:, i])
        for k, (expected, got) in enumerate(zip(single, batched, strict=True)):
            for field, (a, b) in enumerate(zip(expected, got, strict=True)):
                if a is None:
                    continue
                np.testing.assert_allclose(
                    b[i], a, rtol=1e-12, atol=1e-12, err_msg=f"env {i} step {k} field {field}"
                )
    # the commands saturated something: the applied input differs from the command
    assert not np.allclose(batched[-1][-1], commands[-1])
    # the noise is there (on the wrench, and on the state when asked), each environment's own
    true_q, measured_q, _, measured_wrench, contact, _ = batched[-1]
    noise = np.hstack([measured_wrench - contact, measured_q - true_q])
    assert np.all(np.abs(noise).max(axis=1) > 0.0)
    assert not np.allclose(noise[0], noise[1])


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_threads_do_not_change_a_number(name):
    num_envs, steps = 5, 4
    scenario = _scenario(name)
    q0, v0 = _starts(scenario, num_envs, seed=3)
    commands = _commands(scenario, num_envs, steps, seed=4)
    seeds = list(range(num_envs))
    runs = [_batched(name, q0, v0, seeds, commands, t) for t in (1, 2, 4, 16)]
    for run in runs[1:]:
        for expected, got in zip(runs[0], run, strict=True):
            for a, b in zip(expected, got, strict=True):
                if a is not None:
                    np.testing.assert_array_equal(b, a)


def test_a_masked_environment_does_not_move_and_a_diverged_one_keeps_its_state():
    scenario = load_scenario(scenario_path("passive_still_water"), {"control.period_s": 0.002})
    batch = BatchedPlant(scenario.plant, scenario.settings, scenario.sensor_config, 3, 2)
    for i in range(3):
        batch.reset(i, scenario.q0, scenario.v0, i)
    before = batch.q.copy()
    tau = np.zeros((3, scenario.uvms.nv))
    tau[1] = 1e15  # unlimited actuation: this one blows up
    batch.step(tau, np.array([False, True, True]))
    np.testing.assert_array_equal(batch.q[0], before[0])
    np.testing.assert_array_equal(batch.tick, [0, 0, 1])
    np.testing.assert_array_equal(batch.status, [RUNNING, DIVERGED, RUNNING])
    np.testing.assert_array_equal(batch.q[1], before[1])  # the last finite state
    assert np.all(np.isfinite(batch.q_measured))


def test_bad_arguments_are_clear_errors():
    scenario = _scenario("gym_station_keeping")
    args = (scenario.plant, scenario.settings, scenario.sensor_config)
    for kw, match in (({"num_envs": 0}, "num_envs"), ({"num_envs": 2, "num_threads": 0},
                                                       "num_threads")):  # fmt: skip
        with pytest.raises(ParameterError, match=match):
            BatchedPlant(*args, **{"num_threads": 1, **kw})
    batch = BatchedPlant(*args, num_envs=2)
    with pytest.raises(ParameterError, match="tau_commanded"):
        batch.step(np.zeros((3, scenario.uvms.nv)))
    with pytest.raises(ParameterError, match="non-finite"):
        batch.step(np.full((2, scenario.uvms.nv), np.inf))
    with pytest.raises(ParameterError, match="q0"):
        batch.reset(0, np.zeros(3), scenario.v0, 0)


_PEAK_SCRIPT = """
import json, sys
from uvms_pin.apps.gym.env import scenario_path
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.batched_plant import BatchedPlant, batch_bytes

def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith(key))

envs, seconds = int(sys.argv[1]), float(sys.argv[2])
overrides = {**json.loads(sys.argv[3]), "scenario.duration_s": seconds}
scenario = load_scenario(scenario_path("gym_station_keeping"), overrides)
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")  # the peak resident memory starts again from what is resident now
start = status("VmRSS")
batch = BatchedPlant(scenario.plant, scenario.settings, scenario.sensor_config, envs, 1)
for i in range(envs):
    batch.reset(i, scenario.q0, scenario.v0, i)
uvms = scenario.uvms
print(status("VmHWM") - start, batch_bytes(batch._rows, uvms.nq, uvms.nv, envs, 1))
"""


@pytest.mark.skipif(not Path("/proc/self/clear_refs").exists(), reason="Linux's peak memory")
@pytest.mark.skipif(
    "libasan" in os.environ.get("LD_PRELOAD", ""),
    reason="under AddressSanitizer (make sanitize) its shadow memory is not the batch's",
)
@pytest.mark.parametrize(("envs", "seconds"), [(4, 500.0), (1, 200.0), (32, 50.0)])
def test_the_memory_estimate_bounds_what_a_batch_takes_at_its_peak(envs, seconds):
    """A batch with every noise channel drawn (its tables the most of its memory), built and
    every environment reset in a fresh process: its peak resident memory grows by no more
    than `batch_bytes` says, and by more than two thirds of it (an estimate far above
    would refuse batches that fit)."""
    noisy = {**NOISY_STATE, "sensors.force_noise_N": 0.1}
    done = subprocess.run(
        [sys.executable, "-c", _PEAK_SCRIPT, str(envs), str(seconds), json.dumps(noisy)],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    grown, estimate = (int(x) for x in done.stdout.split())
    assert grown <= estimate
    assert grown > 2 / 3 * estimate
