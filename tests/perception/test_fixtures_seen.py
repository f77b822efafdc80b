"""Fixtures as the sensors see them (uvms_pin.perception.scene): a camera sees a fixture's
links, labelled ``<fixture>.<link>``, where its joints put them; in a run, at the joint
positions the run logged."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.perception.camera import Camera, CameraSpec
from uvms_pin.perception.loop import LoopCameras
from uvms_pin.perception.scene import scene_of
from uvms_pin.perception.suite import PerceptionSpec, perceive
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

#: the valve panel's quarter-turn handle (a bar 0.2 m across) seen from the vehicle 0.85 m off
PANEL = ROOT / "scenarios" / "valve_panel.toml"
CAMERA = CameraSpec("front", width=96, height=72, horizontal_fov_rad=1.0, noise_counts=0.0,
                    reflectance={"panel": (0.9, 0.5, 0.1)})  # fmt: skip


def _extent(mask: np.ndarray) -> tuple[int, int]:
    """(rows, columns) the pixels of ``mask`` span."""
    rows, columns = np.nonzero(mask)
    return int(np.ptp(rows)) + 1, int(np.ptp(columns)) + 1


@pytest.mark.parametrize("backend", ["core", "python"])
def test_a_camera_sees_a_fixtures_links_where_its_joint_puts_them(backend):
    """The panel and its handle are labelled by their links; turning the valve a quarter
    turn turns the handle's bar in the image from across to upright (the joint's axis
    points at the camera); the fixture's colour is its links'."""
    scenario = load_scenario(PANEL)
    scene = scene_of(scenario.uvms, scenario.plant.world, surface=False, backend=backend)
    scene.update(scenario.q0)
    camera = Camera(CAMERA, scene, np.random.default_rng(0))
    names = scene.names
    handle = [k + 1 for k, name in enumerate(names) if name == "panel.handle"]
    panel = names.index("panel.panel") + 1
    closed = camera.render()
    assert np.count_nonzero(closed.label == panel) > 500
    across = np.isin(closed.label, handle)
    rows, columns = _extent(across)
    assert columns > 2 * rows  # the bar lies across
    scene.update(scenario.q0, (), [np.array([np.pi / 2])])
    opened = camera.render()
    rows, columns = _extent(np.isin(opened.label, handle))
    assert rows > 2 * columns  # upright
    np.testing.assert_array_equal(camera.reflectance[handle[0]], (0.9, 0.5, 0.1))
    np.testing.assert_array_equal(camera.reflectance[panel], (0.9, 0.5, 0.1))
    # the panel's face is a plane 0.85 m ahead: its depth where the handle does not hide it
    face = (closed.label == panel) & (opened.label == panel)
    assert np.ptp(closed.depth_m[face]) < 0.05


def test_a_runs_images_see_the_fixture_at_its_logged_joint_positions():
    """A run's firings are posed from its log, the fixture's joints too: the run's images
    show the closed handle; the same log with the valve a quarter turn open, fired again,
    shows it upright."""
    scenario = load_scenario(PANEL, {"scenario.duration_s": 0.2})
    spec = PerceptionSpec((("camera", dataclasses.replace(CAMERA, rate_hz=10.0)),))
    config = dataclasses.replace(scenario.sensor_config, perception=spec)
    rollout = simulate(dataclasses.replace(scenario, sensor_config=config), progress=False)
    scene = scene_of(scenario.uvms, scenario.plant.world, surface=False)
    handle = np.array([k + 1 for k, name in enumerate(scene.names) if name == "panel.handle"])
    closed = rollout.camera("front").label
    assert np.allclose(rollout.signals["panel"], 0.0, atol=1e-3)  # nothing turns it
    rows, columns = _extent(np.isin(closed[-1], handle))
    assert columns > 2 * rows
    rollout.signals["panel"][:] = np.pi / 2
    rollout.perception.clear()
    perceive(rollout, spec, scene, seed=0)
    opened = rollout.camera("front").label
    assert len(opened) == len(closed) == 3
    for image in opened:
        rows, columns = _extent(np.isin(image, handle))
        assert rows > 2 * columns


def test_a_camera_in_the_loop_sees_the_fixture_where_the_loop_says():
    """`LoopCameras.update` with the fixtures' joint positions of the tick: the image of the
    valve a quarter turn open shows the handle upright; without them the fixture stays where
    it was."""
    scenario = load_scenario(PANEL)
    scene = scene_of(scenario.uvms, scenario.plant.world, surface=False)
    handle = np.array([k + 1 for k, name in enumerate(scene.names) if name == "panel.handle"])
    cameras = LoopCameras([dataclasses.replace(CAMERA, rate_hz=10.0)], scene, seed=0)
    cameras.update(0.0, scenario.q0, (), [np.array([np.pi / 2])])
    rows, columns = _extent(np.isin(cameras.images["front"].label, handle))
    assert rows > 2 * columns
    cameras.update(0.1, scenario.q0, ())
    rows, columns = _extent(np.isin(cameras.images["front"].label, handle))
    assert rows > 2 * columns and cameras.images["front"].time_s == 0.1
