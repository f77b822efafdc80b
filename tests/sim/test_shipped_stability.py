"""Every shipped model released with no input runs a few seconds at the passive scenario's
default step without diverging, and every shipped scenario its first second: accepted by the
stiff-mode check (`uvms_pin.sim.stiffness`), and stable as run. (`scripts/results/
stability.py` runs the long versions.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ShortenedRunWarning
from uvms_pin.model.resources import shipped_models
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.robots_run import RobotsScenario, shortened_robots, simulate_robots
from uvms_pin.sim.run import shortened, simulate

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
PASSIVE = SCENARIOS / "passive_still_water.toml"
#: at rest, tilted, the arm's joints where the model's defaults put them (0 within limits)
RELEASED = {"position_world_m": [0.0, 0.0, -2.0], "rpy_rad": [0.2, -0.1, 0.0]}


def _checked_run(scenario):
    rollout = simulate(scenario, progress=False)
    assert rollout.metadata["status"] == "ok"
    assert np.all(np.isfinite(rollout.q)) and np.all(np.isfinite(rollout.v))
    record = rollout.metadata["stiff_modes"]
    if record["checked"] and record["stiffest"] is not None:
        assert record["margin"] > 1.0
    return rollout


@pytest.mark.parametrize("model", shipped_models())
def test_every_shipped_model_runs_passive_at_the_default_step(model):
    overrides = {"scenario.model": model, "scenario.duration_s": 5.0, "initial": RELEASED}
    rollout = _checked_run(load_scenario(PASSIVE, overrides))
    assert rollout.time_s[-1] == pytest.approx(5.0)
    assert np.abs(rollout.v).max() < 50.0  # nothing spun up (the Alpha 5's wrist: 14 rad/s)


@pytest.mark.parametrize("path", sorted(SCENARIOS.glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_scenario_runs_its_first_second(path):
    scenario = load_scenario(path)
    with pytest.warns(ShortenedRunWarning):
        if isinstance(scenario, RobotsScenario):  # [[robots]]: every robot's rollout
            scenario = shortened_robots(scenario, {"UVMS_PIN_MAX_DURATION_S": "1"})
        else:
            scenario = shortened(scenario, {"UVMS_PIN_MAX_DURATION_S": "1"})
    if isinstance(scenario, RobotsScenario):
        rollouts = simulate_robots(scenario).rollouts.values()
        assert all(r.metadata["status"] == "ok" for r in rollouts)
    else:
        rollouts = [_checked_run(scenario)]
    for rollout in rollouts:
        assert np.all(np.isfinite(rollout.q)) and np.all(np.isfinite(rollout.v))
        assert rollout.time_s[-1] == pytest.approx(1.0)
