"""[water.current], [water.waves] and [water.sea] in scenario files; the free surface."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import uvms_pin as up
from uvms_pin.flow import AiryWave, GaussMarkovCurrent, IrregularSea, SumFlow, flow_from_record
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

ROOT = Path(__file__).resolve().parents[2]
REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
SEA = ROOT / "scenarios" / "sea_state_force_tracking.toml"
STILL = ROOT / "scenarios" / "passive_still_water.toml"


def test_shipped_sea_scenario_builds_an_irregular_sea():
    scenario = load_scenario(SEA)
    flow = scenario.plant.flow
    assert isinstance(flow, IrregularSea)
    assert flow.significant_height_m == 0.5 and flow.peak_period_s == 5.0
    assert flow.seed == scenario.settings.seed  # the sea's draw is the scenario's seed
    assert flow.has_free_surface


def test_flow_tables_add_up_and_are_recorded():
    overrides = {
        "water.current_world_m_s": [0.1, 0.0, 0.0],
        "water.waves": {"amplitude_m": 0.2, "period_s": 4.0, "water_depth_m": 10.0},
        "water.current": {
            "type": "gauss_markov",
            "mean_velocity_world_m_s": [0.0, 0.1, 0.0],
            "std_m_s": 0.05,
            "time_constant_s": 10.0,
            "bound_m_s": 0.1,
        },
    }
    scenario = load_scenario(REALISTIC, overrides)
    flow = scenario.plant.flow
    assert isinstance(flow, SumFlow)
    assert [type(f) for f in flow.fields] == [GaussMarkovCurrent, AiryWave]
    # what a rollout records (JSON) rebuilds the same whole flow (current included)
    rebuilt = flow_from_record(json.loads(json.dumps(scenario.plant.record()))["flow"])
    p = np.array([[0.3, 0.1, -2.0]])
    np.testing.assert_allclose(
        rebuilt.velocity(1.3, p), scenario.plant.water.velocity(1.3, p), rtol=1e-14
    )


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"water.waves": {"amplitude_m": 0.2}}, "water.waves.period_s: is required"),
        ({"water.waves": {"amplitude_m": 0.2, "period_s": 4.0, "hieght": 1}}, "unknown key"),
        ({"water.sea": {"significant_height_m": 0.5, "peak_period_s": -5.0}}, "positive"),
        (
            {
                "water.sea": {
                    "significant_height_m": 0.5,
                    "peak_period_s": 5.0,
                    "peak_enhancement": 50,
                }
            },
            "gamma",
        ),
        ({"water.current": {"type": "tidal"}}, "must be one of"),
        (
            {
                "water.current": {
                    "type": "profile",
                    "velocity_world_m_s": [1, 0, 0],
                    "depths_m": [1, 0],
                    "factors": [1, 1],
                }
            },
            "increasing",
        ),
    ],
)
def test_bad_flow_tables_name_the_table(overrides, message):
    with pytest.raises(up.ScenarioError, match=message):
        load_scenario(REALISTIC, overrides)


def test_body_reaching_the_surface_stops_the_run_with_its_rollout():
    """A passive vehicle made buoyant (denser water) rises from 0.5 m under small waves: with
    ``stop_at_surface`` (off by default since the free surface is simulated) the run stops
    when a link reaches the surface, says which and when, and keeps the rollout. (A neutral
    vehicle would not: it rides the orbits of the water around it.)"""
    overrides = {
        "water.stop_at_surface": True,
        "water.density_kg_m3": 1150.0,
        "initial.position_world_m": [0.0, 0.0, -0.5],
        "water.waves": {"amplitude_m": 0.1, "period_s": 4.0},
        "scenario.duration_s": 6.0,
    }
    with pytest.raises(up.SimulationError, match="reached the free surface") as info:
        simulate(load_scenario(STILL, overrides))
    rollout = info.value.rollout
    assert rollout.metadata["status"] == "SimulationError"
    assert 0.2 < rollout.time_s[-1] < 6.0
