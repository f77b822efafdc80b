"""A stopped run's figures and replay say where it stopped: the violation (time, component,
bound) marked, since its state is not a logged sample."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.apps.viz.replay import write_replay
from uvms_pin.results.figures import paper as paper_figures
from uvms_pin.results.figures import standard as plots
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


@pytest.fixture(scope="module")
def violated():
    """The force funnel shrunk below the noise: f_x leaves it at t ~ 0.17 s."""
    scenario = load_scenario(
        REALISTIC,
        {
            "scenario.duration_s": 1.0,
            "controller.rho_inf_x": [0.01, 0.01, 0.01, 0.2, 0.2, 0.2],
            "controller.rho0_x": [1.0, 1.0, 1.0, 0.9, 0.9, 0.9],
            "controller.l_x_per_s": [3.0, 3.0, 3.0, 1.0, 1.0, 1.0],
        },
    )
    with pytest.raises(up.FunnelViolation) as info:
        simulate(scenario)
    return info.value


def test_the_summary_names_time_component_and_bound(violated):
    rollout = violated.rollout
    text = rollout.status.summary()
    assert text.startswith("FunnelViolation at t = ")
    assert f"'{violated.component}'" in text and f"{violated.bound:.4g}" in text
    assert rollout.status.time_s == violated.time_s > rollout.time_s[-1]
    ok = up.Rollout.allocate(2, 1, 1, {"status": "ok"})
    assert ok.status.summary() is None and ok.status.time_s is None


def _captured_figures(monkeypatch) -> list:
    figures = []

    def keep(fig, path):
        figures.append(fig)
        return path

    monkeypatch.setattr(paper_figures, "save_figure", keep)
    monkeypatch.setattr(plots, "save_figure", keep)
    return figures


def test_every_figure_marks_the_stop_and_the_violated_funnel(violated, tmp_path, monkeypatch):
    rollout = violated.rollout
    figures = _captured_figures(monkeypatch)
    paper_figures.paper_figures(rollout, tmp_path)
    plots.standard_figures(rollout, tmp_path)
    assert len(figures) == 6
    for fig in figures:
        assert rollout.status.summary() in fig._suptitle.get_text()
        for ax in (a for a in fig.axes if a.get_visible()):
            xs = [line.get_xdata() for line in ax.get_lines()]
            assert any(np.all(np.asarray(x) == violated.time_s) for x in xs), "no stop line"
    # the violated component's axes hold the error at the violation time and +-rho there
    level = 1 if violated.level == "first" else 2
    markers = [
        line
        for ax in figures[level].axes
        for line in ax.get_lines()
        if line.get_marker() in ("x", "_")
    ]
    points = {
        (float(x), float(y))
        for line in markers
        for x, y in zip(np.ravel(line.get_xdata()), np.ravel(line.get_ydata()), strict=True)
    }
    assert (violated.time_s, violated.error) in points
    assert {(violated.time_s, violated.bound), (violated.time_s, -violated.bound)} <= points


def test_the_replay_header_says_where_it_stopped(violated, tmp_path):
    page = write_replay(violated.rollout, tmp_path / "replay.html").read_text()
    assert "uvms-stopped" in page
    assert f"FunnelViolation at t = {violated.time_s:.6g} s" in page
    assert violated.component in page
