"""The closed loop stops cleanly: every divergence is a SimulationError with the partial
rollout (finite, up to the last good sample) attached and its status recorded."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

PAPER = ROOT / "scenarios" / "paper_force_tracking.toml"
REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
PASSIVE = ROOT / "scenarios" / "passive_still_water.toml"

# the blow-ups of issue 10, each in its first steps (0.2 s runs). (Its water density of 1e9
# kg/m^3 and current of 1e5 m/s are refused at load now, as no water can be that:
# tests/scenario/test_plausibility.py; tests/sim/test_integrators.py checks that a failed
# adaptive pass keeps its states.)
BLOW_UPS = {
    "stiffness 1e12, continuous LSODA": (PAPER, {"environment.stiffness_N_m": [1e12] * 3}),
    "water density 15000, sampled RK4": (REALISTIC, {"water.density_kg_m3": 15000.0}),
    "current 1400 m/s": (REALISTIC, {"water.current_world_m_s": [1400.0, 0.0, 0.0]}),
    "current 1400 m/s, no controller": (PASSIVE, {"water.current_world_m_s": [1400.0, 0.0, 0.0]}),
}
# the blow-ups of a spring too stiff for the fixed step: refused before the run now, the
# environment named (`uvms_pin.sim.stiffness`)
TOO_STIFF = {
    "stiffness 1e12, sampled RK4": (REALISTIC, {"environment.stiffness_N_m": [1e12] * 3}),
    "stiffness 1e7, no controller, RK4 at 0.5 ms": (
        PASSIVE,
        {
            "environment.type": "spring",
            "environment.stiffness_N_m": [1e7] * 3,
            "integrator.step_s": 0.0005,
        },
    ),
}


@pytest.mark.parametrize("case", list(BLOW_UPS), ids=list(BLOW_UPS))
def test_a_blow_up_is_a_simulation_error_with_the_partial_rollout(case):
    path, overrides = BLOW_UPS[case]
    scenario = load_scenario(path, {**overrides, "scenario.duration_s": 0.2})
    with pytest.raises(up.SimulationError) as info:
        simulate(scenario)
    exc = info.value
    partial = exc.rollout
    assert partial.metadata["status"] == type(exc).__name__
    assert partial.metadata["error"] == str(exc)
    assert 1 <= len(partial) < scenario.settings.n_log  # t = 0 at least, never the whole run
    assert partial.time_s[0] == 0.0
    for name in ("time_s", "q", "v", "tau", "kinetic_energy_J"):
        assert np.all(np.isfinite(getattr(partial, name))), name
    assert partial.metadata["simulated_time_s"] == partial.time_s[-1]


@pytest.mark.parametrize("case", list(TOO_STIFF), ids=list(TOO_STIFF))
def test_a_spring_too_stiff_for_the_step_is_refused_before_the_run(case):
    path, overrides = TOO_STIFF[case]
    scenario = load_scenario(path, {**overrides, "scenario.duration_s": 0.2})
    with pytest.raises(up.ParameterError, match="the end-effector on its environment spring"):
        simulate(scenario)


def test_a_funnel_violation_records_what_broke():
    """The violation's time, component and bound are in the metadata (figures mark them)."""
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.2})
    scenario.v0[0] = 5.0  # surge far outside its velocity funnel at t = 0
    with pytest.raises(up.FunnelViolation) as info:
        simulate(scenario)
    exc = info.value
    violation = exc.rollout.metadata["violation"]
    assert violation == {
        "level": exc.level,
        "component": exc.component,
        "time_s": exc.time_s,
        "error": exc.error,
        "bound": exc.bound,
    }
    json.dumps(violation)  # stored in rollout.json


def test_cli_exits_3_and_saves_the_partial_rollout_of_a_blow_up(tmp_path):
    from conftest import run

    text = PASSIVE.read_text().replace(
        "current_world_m_s = [0.0, 0.0, 0.0]", "current_world_m_s = [1400.0, 0.0, 0.0]"
    )
    scenario = tmp_path / "swept.toml"
    scenario.write_text(text.replace("duration_s = 10.0", "duration_s = 0.2"))
    out = tmp_path / "out"
    result = run("run", str(scenario), "--out", str(out), "--quiet")
    assert result.returncode == 3, result.stderr
    assert "Traceback" not in result.stderr
    assert "simulation diverged between t = 0 s and 0.002 s" in result.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "SimulationError"
    assert len(up.Rollout.load(out)) == 1


@pytest.mark.parametrize("seed", [-1, 2**63, 1.5])
def test_a_seed_no_generator_takes_is_refused_where_it_is_given(seed):
    from uvms_pin.flow import GaussMarkovCurrent, IrregularSea
    from uvms_pin.sim.integrators import RK4
    from uvms_pin.sim.settings import SimulationSettings

    with pytest.raises(up.ParameterError, match="seed must be an integer in"):
        SimulationSettings(1.0, RK4(0.01), seed=seed)
    with pytest.raises(up.ParameterError, match="seed must be an integer in"):
        IrregularSea(0.5, 6.0, seed=seed)
    with pytest.raises(up.ParameterError, match="seed must be an integer in"):
        GaussMarkovCurrent([0.1, 0, 0], 0.05, 10.0, 0.2, seed=seed)


@pytest.mark.parametrize("given", ["scenarios/passive_still_water.toml", ROOT, None, 3.0])
def test_simulate_refuses_what_is_not_a_scenario_and_says_to_load_a_path(given):
    """A path (the first thing a user passes) is refused with the call that loads it;
    anything else that is not a scenario by its type: both ParameterErrors, not an
    AttributeError on ``settings``."""
    match = "load it first" if isinstance(given, str | type(ROOT)) else "takes a Scenario"
    with pytest.raises(up.ParameterError, match=match):
        simulate(given)
