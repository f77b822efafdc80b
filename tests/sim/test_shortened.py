"""UVMS_PIN_MAX_DURATION_S shortens scenario runs, and never silently: the warning, the
rollout's record, the command line's last line; bad values are clear errors; published
results refuse it."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

import gymnasium as gym
import pytest
from conftest import ROOT, run

import uvms_pin.apps.gym  # noqa: F401 - registers the environments
from uvms_pin.errors import ParameterError, ScenarioError, ShortenedRunWarning
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate
from uvms_pin.sim.shortened import MAX_DURATION_ENV, max_duration_s, shortened_duration_s

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"  # 10 s, logged every 10 ms


def test_the_cap_is_read_from_the_environment():
    assert max_duration_s({}) is None
    assert max_duration_s({MAX_DURATION_ENV: " "}) is None
    assert max_duration_s({MAX_DURATION_ENV: "2.5"}) == 2.5


@pytest.mark.parametrize("text", ["abc", "0", "-1", "inf", "nan", "1s"])
def test_a_bad_cap_is_an_error_naming_the_variable(text):
    with pytest.raises(ParameterError, match=f"{MAX_DURATION_ENV}={text!r}"):
        max_duration_s({MAX_DURATION_ENV: text})


@pytest.mark.parametrize(
    ("duration_s", "log_period_s", "cap_s", "expected_s"),
    [
        (10.0, 0.005, 1.0, 1.0),
        (10.0, 0.3, 1.0, 0.9),  # whole log periods within the cap
        (10.0, 0.1, 0.3, 0.3),  # 0.3 / 0.1 = 2.999...: still 3 periods
        (10.0, 2.0, 1.0, 2.0),  # at least one log period
        (0.5, 0.005, 1.0, None),  # not longer than the cap: unchanged
        (1.0, 0.005, 1.0, None),
        (2.0, 2.0, 1.0, None),  # one period is all it has
    ],
)
def test_the_shortened_duration_is_whole_log_periods(duration_s, log_period_s, cap_s, expected_s):
    got = shortened_duration_s(duration_s, log_period_s, cap_s)
    assert got == (None if expected_s is None else pytest.approx(expected_s, rel=1e-12))


def test_a_loaded_scenario_is_shortened_loudly_and_the_rollout_says_so(monkeypatch):
    monkeypatch.setenv(MAX_DURATION_ENV, "0.25")
    with pytest.warns(ShortenedRunWarning) as caught:
        scenario = load_scenario(REALISTIC)
    message = str(caught[0].message)
    assert str(REALISTIC) in message and "0.25 s of the scenario's 10 s" in message
    assert scenario.settings.duration_s == pytest.approx(0.25)
    assert scenario.raw["scenario"]["duration_s"] == pytest.approx(0.25)  # what is recorded
    assert scenario.shortened_from_s == 10.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShortenedRunWarning)  # already short: no second warning
        rollout = simulate(scenario, progress=False)
    assert rollout.time_s[-1] == pytest.approx(0.25)
    assert rollout.metadata["shortened_from_s"] == 10.0
    assert rollout.metadata["parameters"]["scenario"]["duration_s"] == pytest.approx(0.25)


def test_without_the_variable_nothing_changes(monkeypatch):
    monkeypatch.delenv(MAX_DURATION_ENV, raising=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShortenedRunWarning)
        scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.05})
        rollout = simulate(scenario, progress=False)
    assert scenario.shortened_from_s is None and "shortened_from_s" not in rollout.metadata
    assert rollout.time_s[-1] == pytest.approx(0.05)


def test_simulate_shortens_a_scenario_it_is_given(monkeypatch):
    monkeypatch.delenv(MAX_DURATION_ENV, raising=False)
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 1.0})
    monkeypatch.setenv(MAX_DURATION_ENV, "0.1")
    with pytest.warns(ShortenedRunWarning, match="0.1 s of the scenario's 1 s"):
        rollout = simulate(scenario, progress=False)
    assert rollout.time_s[-1] == pytest.approx(0.1)
    assert rollout.metadata["shortened_from_s"] == 1.0


def test_a_bad_value_stops_a_load_naming_the_file(monkeypatch):
    monkeypatch.setenv(MAX_DURATION_ENV, "soon")
    with pytest.raises(ScenarioError, match=f"{REALISTIC}.*{MAX_DURATION_ENV}='soon'"):
        load_scenario(REALISTIC)


def test_a_gym_episode_is_shortened_too(monkeypatch):
    monkeypatch.setenv(MAX_DURATION_ENV, "0.1")
    with pytest.warns(ShortenedRunWarning):
        env = gym.make("uvms_pin/ForceTracking-v0").unwrapped
    assert env.max_steps == 50  # 0.1 s of 2 ms periods
    env.reset(seed=0)
    assert env.episode_rollout().metadata["shortened_from_s"] == 10.0


def test_the_command_line_prints_it(tmp_path, monkeypatch):
    monkeypatch.setenv(MAX_DURATION_ENV, "0.2")
    done = run("run", str(REALISTIC), "--out", str(tmp_path / "r"), "--quiet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "simulated 0.200 s" in done.stdout
    assert f"SHORTENED from 10 s by {MAX_DURATION_ENV}" in done.stdout
    assert f"uvms-pin: warning: {REALISTIC}: {MAX_DURATION_ENV}=0.2 is set" in done.stderr
    assert Rollout.load(tmp_path / "r").metadata["shortened_from_s"] == 10.0
    monkeypatch.setenv(MAX_DURATION_ENV, "-3")
    bad = run("run", str(REALISTIC), "--out", str(tmp_path / "bad"), cwd=tmp_path)
    assert bad.returncode == 2 and f"{MAX_DURATION_ENV}='-3'" in bad.stderr
    assert "Traceback" not in bad.stderr and not (tmp_path / "bad").exists()


@pytest.mark.parametrize(
    "script", ["scripts/make_results.py", "scripts/results/paper.py"], ids=lambda s: s
)
def test_published_results_refuse_shortened_runs(script, tmp_path):
    env = {**_environment(), MAX_DURATION_ENV: "1"}
    done = subprocess.run(
        [sys.executable, str(ROOT / script)], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"{MAX_DURATION_ENV} is set" in done.stderr
    assert "$ uvms-pin" not in done.stdout and "==" not in done.stdout  # nothing ran


def _environment() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k != MAX_DURATION_ENV}
