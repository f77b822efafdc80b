"""The one closed-loop engine: its observers, the log it writes, the status it records, the
read-only measurement, and the same trajectory stepped by hand (as the Gymnasium
environment does) or run whole (as ``simulate`` does)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.flow import flow_from_record
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.status import RunStatus, Violation
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.closed_loop import ClosedLoop
from uvms_pin.sim.log import RolloutLog
from uvms_pin.sim.run import simulate
from uvms_pin.sim.sensors import SensorSuite

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
PASSIVE = ROOT / "scenarios" / "passive_current.toml"


class Recorder:
    """An observer keeping every sample it is given."""

    def __init__(self):
        self.samples = []

    def on_sample(self, sample) -> None:
        self.samples.append(sample)


def _short(path=REALISTIC, duration_s=0.2, **overrides):
    return load_scenario(path, {"scenario.duration_s": duration_s, **overrides})


def test_observers_see_every_logged_sample_as_the_log_records_it():
    scenario = _short(**{"sensors.force_noise_N": 0.05})
    recorder = Recorder()
    rollout = simulate(scenario, progress=False, observers=[recorder])
    samples = recorder.samples
    assert [s.time_s for s in samples] == pytest.approx(list(rollout.time_s))
    for k, sample in enumerate(samples):
        np.testing.assert_array_equal(sample.q, rollout.q[k])
        np.testing.assert_array_equal(sample.tau_applied, rollout.tau[k])
        np.testing.assert_array_equal(
            sample.measurement.wrench_world, rollout.wrench_measured_world[k]
        )
        np.testing.assert_array_equal(sample.contact_world, rollout.wrench_contact_world[k])
        np.testing.assert_array_equal(sample.signals["e_x"], rollout.signals["e_x"][k])
        assert not sample.q.flags.writeable and not sample.measurement.v.flags.writeable
    # the noise reached the measurement, not the true contact
    assert np.any(rollout.wrench_measured_world != rollout.wrench_contact_world)


class Meddler(Controller):
    """A controller that tries to change the plant through its measurement."""

    def __init__(self, nv: int):
        self.nv = nv
        self.refused = self.calls = 0

    def compute(self, time_s, measurement):
        self.calls += 1
        for array in (measurement.q, measurement.v, measurement.wrench_world):
            try:
                array[:] = 0.0
            except ValueError:
                self.refused += 1
        return np.zeros(self.nv)


def test_a_measurement_never_aliases_the_plant_state():
    scenario = _short(PASSIVE, 0.1)
    meddler = Meddler(scenario.uvms.nv)
    scenario.controller_factory = lambda uvms: meddler
    rollout = simulate(scenario, progress=False)
    reference = simulate(_short(PASSIVE, 0.1), progress=False)
    assert meddler.calls > 50 and meddler.refused == 3 * meddler.calls  # every array: read-only
    np.testing.assert_array_equal(rollout.q, reference.q)  # the run is untouched
    own = np.ones(3)
    measurement = Measurement(0.0, own, own, np.ones(6))
    assert measurement.q is not own and not measurement.q.flags.writeable
    own[:] = 5.0
    assert np.all(measurement.q == 1.0)  # a copy: the caller's array stays its own


def test_stepping_by_hand_gives_the_run_of_simulate():
    """What the Gymnasium environment does (measure, command, actuate, step, log) is the
    closed loop ``simulate`` runs: the same samples to the last bit on the Python loop, and to
    rounding (1e-12) on the compiled loop (its allocation products sum in another order)."""
    scenario = _short(**{"sensors.force_noise_N": 0.05, "sensors.velocity_noise": 0.01})
    reference = simulate(scenario, progress=False, compiled_loop=False)
    compiled = simulate(scenario, progress=False)
    assert compiled.metadata["closed_loop"]["path"] == "compiled"
    settings = scenario.settings
    controller = scenario.controller_factory(scenario.uvms)
    loop = ClosedLoop(scenario.plant, settings, controller)
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    loop.start(scenario.q0, scenario.v0, sensors)
    log = RolloutLog(scenario.uvms, 8, {})  # grows as it fills
    per_log = settings.ticks_per_log
    for tick in range(round(settings.duration_s / settings.control_period_s) + 1):
        measurement, contact = loop.measure()
        tau = loop.command(measurement)
        applied = loop.actuate(tau)
        if tick % per_log == 0:
            log.on_sample(loop.sample(measurement, contact, tau, applied))
        if tick < settings.duration_s / settings.control_period_s - 0.5:
            loop.step(applied)
    rollout = log.finish()
    assert len(rollout) == len(reference)
    for name in ("time_s", "q", "v", "tau", "wrench_measured_world", "kinetic_energy_J"):
        np.testing.assert_array_equal(getattr(rollout, name), getattr(reference, name))
        scale = max(1.0, float(np.max(np.abs(getattr(reference, name)))))
        np.testing.assert_allclose(
            getattr(compiled, name), getattr(reference, name), rtol=0, atol=1e-12 * scale
        )


def test_the_status_is_typed_saved_and_read_back(tmp_path):
    ok = simulate(_short(PASSIVE, 0.1), progress=False)
    assert ok.status == RunStatus("ok") and ok.status.ok and ok.status.summary() is None
    scenario = _short(
        duration_s=1.0,
        **{"controller.rho_inf_x": [0.01, 0.01, 0.01, 0.2, 0.2, 0.2],
           "controller.l_x_per_s": [3.0, 3.0, 3.0, 1.0, 1.0, 1.0]},
    )  # fmt: skip
    with pytest.raises(up.FunnelViolation) as info:
        simulate(scenario, progress=False)
    stopped = info.value.rollout
    status = stopped.status
    assert status.kind == "FunnelViolation" and status.stopped_early and not status.ok
    assert status.violation == Violation(
        info.value.level,
        info.value.component,
        info.value.time_s,
        info.value.error,
        info.value.bound,
    )
    assert status.time_s == info.value.time_s > stopped.time_s[-1]
    loaded = Rollout.load(stopped.save(tmp_path / "stopped"))
    assert loaded.status == status
    assert (
        json.loads((tmp_path / "stopped" / "rollout.json").read_text())["status"]
        == "FunnelViolation"
    )


def test_the_rollout_records_the_world_as_simulated():
    scenario = _short(
        **{"water.current_world_m_s": [0.1, 0.0, 0.0],
           "water.waves": {"amplitude_m": 0.2, "period_s": 4.0, "water_depth_m": 30.0}},
        **{"initial.position_world_m": [0.0, 0.0, -8.0]},
    )  # fmt: skip
    rollout = simulate(scenario, progress=False)
    world = json.loads(json.dumps(rollout.metadata["world"]))  # as saved
    assert world["water_density_kg_m3"] == scenario.uvms.water_density_kg_m3
    assert world["contact"]["type"] == "spring"
    anchor = scenario.plant.ee_state(rollout.q[0], np.zeros(scenario.uvms.nv))[0]
    np.testing.assert_allclose(world["contact"]["anchor_world_m"], anchor, rtol=0, atol=1e-12)
    flow = flow_from_record(world["flow"])
    points = np.array([[0.3, -0.2, -3.0], [1.0, 2.0, -8.0]])
    for t in (0.0, 1.7):
        np.testing.assert_allclose(
            flow.velocity(t, points), scenario.plant.water.velocity(t, points), rtol=1e-14
        )
        np.testing.assert_allclose(
            flow.surface_elevation(t, points[:, :2]),
            scenario.plant.water.surface_elevation(t, points[:, :2]),
            rtol=1e-14,
        )


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda q, v: (q[:-1], v), "q0 must have"),
        (lambda q, v: (q, np.append(v, 0.0)), "v0 "),
        (lambda q, v: (q, np.where(np.arange(v.size) == 2, np.nan, v)), "non-finite"),
        # a quaternion of zeros was normalised into NaN; a string was numpy's ValueError
        (lambda q, v: (np.concatenate([q[:3], np.zeros(4), q[7:]]), v), "not a rotation"),
        (lambda q, v: ("level", v), "q0 must be"),
    ],
)
def test_a_bad_starting_state_is_refused_by_the_loop_and_the_batch(change, message):
    """The closed loop and the batched plant share one check of a starting state."""
    from uvms_pin.sim.batched_plant import BatchedPlant

    scenario = _short()
    settings = scenario.settings
    loop = ClosedLoop(scenario.plant, settings, scenario.controller_factory(scenario.uvms))
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    q0, v0 = change(scenario.q0.copy(), scenario.v0.copy())
    with pytest.raises(up.ParameterError, match=message):
        loop.start(q0, v0, sensors)
    batch = BatchedPlant(scenario.plant, settings, scenario.sensor_config, 2)
    with pytest.raises(up.ParameterError, match=message):
        batch.reset(1, q0, v0, seed=3)


def test_a_starting_quaternion_is_normalised_in_a_copy():
    scenario = _short()
    settings = scenario.settings
    loop = ClosedLoop(scenario.plant, settings, scenario.controller_factory(scenario.uvms))
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    q0 = scenario.q0.copy()
    q0[3:7] *= 2.0
    given = q0.copy()
    loop.start(q0, scenario.v0, sensors)
    np.testing.assert_array_equal(q0, given)  # the caller's array is not changed
    measurement, _ = loop.measure()
    assert np.linalg.norm(measurement.q[3:7]) == pytest.approx(1.0, abs=1e-12)
