"""objects.png: the free objects' heights and the jaw's fingers, for runs with free objects."""

from __future__ import annotations

from conftest import ROOT
from matplotlib.figure import Figure

import uvms_pin as up
from uvms_pin.results.figures.objects import objects_figures, plot_objects


def test_a_run_with_a_jaw_and_a_rod_gets_heights_and_fingers(tmp_path):
    scenario = up.load_scenario(
        ROOT / "scenarios" / "gripper_close.toml", {"scenario.duration_s": 0.05}
    )
    rollout = up.simulate(scenario, progress=False)
    fig = plot_objects(rollout)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    heights, fingers = fig.axes
    assert [line.get_label() for line in heights.get_lines()] == ["rod"]
    assert len(fingers.get_lines()) == 2  # one per finger, not their grip forces
    (path,) = objects_figures(rollout, tmp_path)
    assert path == tmp_path / "objects.png" and path.stat().st_size > 1000


def test_a_run_without_free_objects_gets_none(tmp_path):
    scenario = up.load_scenario(
        ROOT / "scenarios" / "passive_still_water.toml", {"scenario.duration_s": 0.1}
    )
    assert objects_figures(up.simulate(scenario, progress=False), tmp_path) == []
