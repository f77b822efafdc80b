"""Your own metrics: ``[metrics] extra = ["module:function"]`` reach metrics.json and study
tables; bad references and bad results are clear errors naming the function."""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.apps.cli.main import main
from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

PASSIVE = ROOT / "scenarios" / "passive_still_water.toml"

MODULE = '''
import numpy as np


def arm_travel(rollout):
    """The arm joints' total travel [rad] and the vehicle's lowest z [m]."""
    travel = np.abs(np.diff(rollout.q[:, 7:], axis=0)).sum()
    return {"arm_travel_rad": float(travel), "vehicle_z_min_m": float(rollout.q[:, 2].min())}


def clashing(rollout):
    return {"n_samples": 3.0}


def not_a_mapping(rollout):
    return [1.0]


def nan_valued(rollout):
    return {"broken": float("nan")}


def raising(rollout):
    raise RuntimeError("no data")


def unnamed(rollout):
    return {"": 1.0}


def numbered(rollout):
    return {3: 1.0}


def flagged(rollout):
    return {"touched": True}


NOT_CALLABLE = 3
'''


@pytest.fixture
def scenario_dir(tmp_path):
    (tmp_path / "my_metrics.py").write_text(textwrap.dedent(MODULE))
    text = PASSIVE.read_text().replace('model = "uvms_lbv150"', 'model = "uvms_lbv150"', 1)
    text = text.replace("duration_s = 10.0", "duration_s = 0.2")
    (tmp_path / "run.toml").write_text(text + '\n[metrics]\nextra = ["my_metrics:arm_travel"]\n')
    return tmp_path


def test_extra_metrics_enter_metrics_json(scenario_dir, capsys):
    out = scenario_dir / "out"
    assert main(["run", str(scenario_dir / "run.toml"), "--out", str(out), "--quiet"]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    rollout = Rollout.load(out)
    travel = np.abs(np.diff(rollout.q[:, 7:], axis=0)).sum()
    assert metrics["arm_travel_rad"] == pytest.approx(travel) and travel > 0.01
    assert metrics["vehicle_z_min_m"] == pytest.approx(rollout.q[:, 2].min())
    # a loaded rollout computes them again, the same way
    assert rollout.metrics()["arm_travel_rad"] == pytest.approx(travel)


@pytest.mark.parametrize(
    "reference, match",
    [
        ("my_metrics:arm_travl", "has no 'arm_travl'; did you mean 'arm_travel'"),
        ("no_such_module:f", "module 'no_such_module' not found"),
        ("my_metrics", "expected 'package.module:function'"),
        ("my_metrics:NOT_CALLABLE", "not a function"),
    ],
)
def test_bad_references_are_scenario_errors(scenario_dir, reference, match):
    text = (scenario_dir / "run.toml").read_text().replace("my_metrics:arm_travel", reference)
    (scenario_dir / "bad.toml").write_text(text)
    with pytest.raises(ScenarioError, match=rf"bad.toml: metrics.extra: .*{match}"):
        load_scenario(scenario_dir / "bad.toml")
    with pytest.raises(ScenarioError, match=rf"override 'metrics.extra': .*{match}"):
        load_scenario(scenario_dir / "run.toml", {"metrics.extra": [reference]})
    with pytest.raises(ScenarioError, match=r"override 'metrics\.extra': must be a list"):
        load_scenario(scenario_dir / "run.toml", {"metrics.extra": "my_metrics:arm_travel"})


@pytest.mark.parametrize(
    "reference, match",
    [
        ("clashing", "'n_samples' is already a metric"),
        ("not_a_mapping", "must return a mapping"),
        ("nan_valued", "'broken' is NaN"),
        ("raising", "raised RuntimeError: no data"),
        ("unnamed", "a metric name must be text, got ''"),
        ("numbered", "a metric name must be text, got 3"),
        ("flagged", "'touched' must be a real number, got True"),
    ],
)
def test_bad_results_name_the_function(scenario_dir, reference, match):
    scenario = load_scenario(
        scenario_dir / "run.toml", {"metrics.extra": [f"my_metrics:{reference}"]}
    )
    rollout = simulate(scenario, progress=False)
    with pytest.raises(ParameterError, match=f"metric 'my_metrics:{reference}'.*{match}"):
        rollout.metrics()


def test_a_metric_that_fails_is_an_input_error_that_keeps_the_run(scenario_dir, capsys):
    """Your metric raising after a run of an hour must not lose the hour: the rollout, its
    figures and the built-in metrics are written (``metrics.json`` saying what failed), the
    command exits 2 with your metric's traceback, and the saved rollout computes your
    metrics once the function is fixed."""
    out = scenario_dir / "o"
    code = main(["run", str(scenario_dir / "run.toml"), "--out", str(out),
                 "--quiet", "--set", 'metrics.extra=["my_metrics:raising"]'])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2
    assert "your code raised; its traceback" in err and "RuntimeError: no data" in err
    assert f"kept in {out}: rollout.npz, rollout.json, metrics.json, pose.png" in err
    metrics = json.loads((out / "metrics.json").read_text())
    assert (
        metrics["extra_metrics_error"] == "metric 'my_metrics:raising' raised RuntimeError: no data"
    )
    assert metrics["n_samples"] > 0 and "arm_travel_rad" not in metrics
    rollout = Rollout.load(out)
    with pytest.raises(ParameterError, match="raised RuntimeError"):
        rollout.metrics()  # still the broken function
    rollout.metadata["extra_metrics"] = ["my_metrics:arm_travel"]  # as once fixed
    assert rollout.metrics()["arm_travel_rad"] > 0.0


def test_a_metric_that_fails_in_a_run_of_several_robots_keeps_every_robot(scenario_dir, capsys):
    """Each robot's rollout and the run's metrics.json are written before the error is
    said (the first robot's used to be written and the second's not)."""
    from uvms_pin.results.robots import RobotRollouts

    doc = (scenario_dir / "run.toml").read_text()
    robots = doc.replace('model = "uvms_lbv150"', "", 1).replace("[initial]", "[robots.initial]")
    robots = robots.replace(
        "[metrics]",
        '[[robots]]\nname = "b"\nmodel = "uvms_lbv150"\n[robots.initial]\nposition_world_m = [3.0, 0.0, -2.0]\n[metrics]',
    )
    robots = robots.replace(
        "[robots.initial]", '[[robots]]\nname = "a"\nmodel = "uvms_lbv150"\n[robots.initial]', 1
    )
    (scenario_dir / "two.toml").write_text(robots)
    out = scenario_dir / "two"
    code = main(["run", str(scenario_dir / "two.toml"), "--out", str(out), "--quiet",
                 "--set", 'metrics.extra=["my_metrics:raising"]'])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2, err
    assert "raised RuntimeError: no data" in err and f"the run is kept in {out}" in err
    saved = RobotRollouts.load(out)
    assert saved.names == ["a", "b"]
    blocks = json.loads((out / "metrics.json").read_text())["robots"]
    assert all("raised RuntimeError" in blocks[n]["extra_metrics_error"] for n in ("a", "b"))
