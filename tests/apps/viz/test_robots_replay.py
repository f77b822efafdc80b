"""The replay of several robots (uvms_pin.apps.viz.robots_replay): one page, the other
robots' geometry drawn beside the first's and posed at each sample."""

from __future__ import annotations

import numpy as np
from conftest import ROOT

from uvms_pin.apps.viz.meshcat_scene import ROOT as SCENE_ROOT
from uvms_pin.apps.viz.meshcat_scene import recording_visualizer
from uvms_pin.apps.viz.robots_replay import OtherRobots, robots_replay_html
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.robots_run import simulate_robots


def test_the_other_robots_are_drawn_and_posed_where_they_are():
    scenario = load_scenario(ROOT / "scenarios" / "two_robots.toml", {"scenario.duration_s": 0.2})
    rollouts = simulate_robots(scenario)
    others = OtherRobots([("bravo", rollouts.robot("bravo"))])
    vis, window = recording_visualizer()
    others.build(vis[SCENE_ROOT])
    assert any(b"others/bravo/robot/visuals" in c for c in window.commands)
    bravo, alpha = rollouts.robot("bravo").q, rollouts.robot("alpha").q
    for sample in (0, len(rollouts) - 1):
        poses = others.poses(sample)
        assert poses and all(p.startswith("others/bravo/robot/visuals/") for p in poses)
        where = np.array([pose[0] for pose in poses.values()])
        assert np.all(np.linalg.norm(where - bravo[sample, :3], axis=1) < 1.0)
        assert np.all(np.linalg.norm(where - alpha[sample, :3], axis=1) > 2.0)
    assert np.allclose(others.extent_world_m, bravo[:, :3])
    page = robots_replay_html(rollouts, max_frames=3)
    assert page.startswith("<!DOCTYPE html>") or "<html" in page[:200]
