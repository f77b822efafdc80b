"""Whether a run is compiled (uvms_pin.sim.pipeline): one list of reasons, asked once before a
run starts, the same for the compiled loop (recorded in the rollout) and the batched plant
(its refusal)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ParameterError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.batched_plant import BatchedPlant
from uvms_pin.sim.integrators import Adaptive
from uvms_pin.sim.pipeline import REASONS, Pipeline, RunParts, why_not_compiled
from uvms_pin.sim.run import simulate
from uvms_pin.sim.sample import ProgressReport
from uvms_pin.sim.system import System
from uvms_pin.sim.system.period import why_not_compiled_system

STATION = ROOT / "scenarios" / "gym_station_keeping.toml"
REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def _gust(time_s: float) -> np.ndarray:
    """A disturbance written in Python: the core has no counterpart of it."""
    return np.full(6, 0.1)


def _parts(scenario, **kw) -> RunParts:
    system = System(scenario.plant)
    system.start(system.initial_state(scenario.q0, scenario.v0))
    return RunParts(system, scenario.settings, scenario.sensor_config, **kw)


def _station(overrides=None):
    return load_scenario(STATION, {"scenario.duration_s": 0.1, **(overrides or {})})


def test_a_compiled_scenario_has_no_reason_for_either_pipeline():
    parts = _parts(_station())
    assert why_not_compiled(parts, Pipeline.LOOP) is None
    assert why_not_compiled(parts, Pipeline.BATCH) is None


@pytest.mark.parametrize(
    ("overrides", "reason"),
    [
        ({"control.period_s": None}, "continuous-time control"),
        ({"water.stop_at_surface": True}, "stop_at_surface"),
    ],
)
def test_each_part_without_a_counterpart_is_named_for_both_pipelines(overrides, reason):
    scenario = _station({k: v for k, v in overrides.items() if v is not None})
    if overrides.get("control.period_s", 0) is None:
        scenario.settings = dataclasses.replace(scenario.settings, control_period_s=None)
    parts = _parts(scenario)
    assert why_not_compiled(parts, Pipeline.LOOP) == reason
    assert why_not_compiled(parts, Pipeline.BATCH) == reason


def test_a_python_plant_part_and_an_adaptive_integrator_are_named():
    scenario = _station()
    scenario.plant.disturbance = _gust
    with pytest.warns(Warning, match="disturbance"):
        reason = why_not_compiled(_parts(scenario), Pipeline.LOOP)
    assert "_gust" in reason
    scenario = _station()
    scenario.settings = dataclasses.replace(scenario.settings, integrator=Adaptive())
    assert why_not_compiled(_parts(scenario), Pipeline.BATCH) == "the integrator Adaptive"


def test_a_reason_applies_only_to_the_pipelines_it_names():
    """An observer keeps the loop in Python (it needs every sample), not the batch; a flow
    keeps the batch in Python, not the loop."""
    scenario = _station()
    parts = _parts(scenario, observers=[object()])
    assert why_not_compiled(parts, Pipeline.LOOP) == "an observer that needs every sample"
    assert why_not_compiled(parts, Pipeline.BATCH) is None
    quiet = _parts(scenario, observers=[ProgressReport(lambda t, d: None, 1.0)])
    assert why_not_compiled(quiet, Pipeline.LOOP) is None
    waves = load_scenario(ROOT / "scenarios" / "sea_state_force_tracking.toml")
    parts = _parts(waves)
    assert why_not_compiled(parts, Pipeline.LOOP) is None
    assert "a flow" in why_not_compiled(parts, Pipeline.BATCH)


def test_every_reason_is_asked_in_one_list_and_names_its_pipelines():
    assert len(REASONS) >= 10
    for pipelines, check in REASONS:
        assert pipelines & Pipeline.ALL and callable(check)


def test_the_system_period_asks_the_same_list():
    """The period of a system of bodies (`Pipeline.SYSTEM`) is decided by the list the loop
    asks: the Python integration asked for (the loop's flag, worded for each), an integrator
    without a counterpart, the Python backend; none for a plant that compiles."""
    scenario = _station()
    system = System(scenario.plant, compiled=False)
    parts = RunParts(system, scenario.settings, scenario.sensor_config)
    assert why_not_compiled(parts, Pipeline.LOOP) == "the Python loop was asked for"
    assert why_not_compiled(parts, Pipeline.BATCH) is None
    assert why_not_compiled_system(system, None) == "the Python integration was asked for"
    system = System(scenario.plant)
    assert why_not_compiled_system(system, None) is None
    assert why_not_compiled_system(system, Adaptive()) == "the integrator Adaptive"
    system = System(dataclasses.replace(scenario.plant, backend="python"))
    assert why_not_compiled_system(system, Adaptive()) == "the Python backend"


def test_the_loop_records_and_the_batch_refuses_with_the_same_reason():
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.05})
    scenario.plant.stop_at_surface = True
    rollout = simulate(scenario, progress=False)
    assert rollout.metadata["closed_loop"]["reason"] == "stop_at_surface"
    station = _station()
    station.plant.stop_at_surface = True
    with pytest.raises(ParameterError, match="the batched plant does not simulate stop_at_surface"):
        BatchedPlant(station.plant, station.settings, station.sensor_config, 2)


def test_joint_limits_as_constraints_are_compiled_in_both_pipelines():
    scenario = load_scenario(
        ROOT / "scenarios" / "bluerov_alpha5_force_tracking.toml",
        {"scenario.duration_s": 0.1, "joints.stops": "implicit"},
    )
    assert scenario.plant.joint_limits is not None and scenario.plant.joint_stops is None
    parts = _parts(scenario)
    for pipeline in (Pipeline.LOOP, Pipeline.BATCH):
        assert why_not_compiled(parts, pipeline) is None
