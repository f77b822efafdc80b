"""Cameras and sonars in a run of several robots (``[[robots]]``): each robot's own sensors,
fired after the run over its logged states, see the other robots where their rollouts put
them; a camera in the loop sees them where they are at its tick."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError
from uvms_pin.perception.camera import Camera
from uvms_pin.perception.scene import scene_of
from uvms_pin.perception.suite import SceneLog, perceive
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.robots_run import robot_seed, simulate_robots

#: alpha's camera looks to its left, at bravo 3 m away (optical z along alpha's body y)
CAMERA = """
[[robots.sensors.camera]]
name = "left"
width = 64
height = 48
horizontal_fov_rad = 1.2
rate_hz = 5.0
rpy_rad = [-1.5708, 0.0, 0.0]
noise_counts = 0.0
"""


def _scenario(tmp_path, camera: str = CAMERA, duration_s: float = 0.6, robot: int = 0):
    """two_robots with ``camera`` among robot ``robot``'s sensors (0: alpha, 1: bravo)."""
    text = (ROOT / "scenarios" / "two_robots.toml").read_text()
    text = text.replace("../models/", f"{ROOT}/models/")
    sensors = -1
    for _ in range(robot + 1):
        sensors = text.index("[robots.sensors]", sensors + 1)
    end = text.index("[robots.actuation]", sensors)  # the robot's sensors' table ends
    text = text[:end] + camera + "\n" + text[end:]
    path = tmp_path / "two.toml"
    path.write_text(text)
    return load_scenario(path, {"scenario.duration_s": duration_s})


def scene_of_alpha(scenario):
    """alpha's scene: its world, and bravo (at its neutral configuration until posed)."""
    robot = scenario.robots[0]
    return scene_of(robot.uvms, robot.plant.world, surface=robot.plant.free_surface,
                    others=[("bravo", scenario.robots[1].uvms)])  # fmt: skip


def spec_of(scenario):
    return scenario.robots[0].sensor_config.perception.sensors[0][1]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    scenario = _scenario(tmp_path_factory.mktemp("robots"))
    return scenario, simulate_robots(scenario)


def test_a_robots_camera_sees_the_other_robot_where_its_rollout_puts_it(run):
    """alpha's images label bravo's links ``bravo.<link>``, and equal a camera rendering the
    scene at each firing's row with bravo at its own logged configuration (moved: bravo
    draws its circle); bravo, without sensors that see, has no images."""
    scenario, rollouts = run
    alpha, bravo = rollouts.robot("alpha"), rollouts.robot("bravo")
    record = alpha.camera("left")
    assert len(record.time_s) == 4  # 5 Hz over 0.6 s, t = 0 included
    seen = {record.label_names[k - 1] for k in np.unique(record.label) if k > 0}
    assert "bravo.base_link" in seen
    camera_of_run = Camera(spec_of(scenario), scene_of_alpha(scenario), np.random.default_rng(0))
    bravo_label = camera_of_run.scene.names.index("bravo.base_link") + 1
    own_label = camera_of_run.scene.names.index("base_link") + 1
    np.testing.assert_array_equal(  # shaded as a robot, as alpha's own links
        camera_of_run.reflectance[bravo_label], camera_of_run.reflectance[own_label]
    )
    assert not bravo.perception
    assert np.ptp(bravo.q[:, 0]) + np.ptp(bravo.q[:, 7:]) > 1e-4  # bravo moves
    scene = scene_of_alpha(scenario)
    camera = Camera(spec_of(scenario), scene, np.random.default_rng(0))
    for k, t in enumerate(record.time_s):
        row = int(np.searchsorted(alpha.time_s, t))
        scene.update(alpha.q[row], (), None, [bravo.q[row]])
        np.testing.assert_array_equal(camera.render().label, record.label[k])
    # bravo left at its neutral configuration instead: another image (the log is read)
    scene.update(alpha.q[-1], (), None, [scenario.robots[1].uvms.neutral_configuration()])
    assert not np.array_equal(camera.render().label, record.label[-1])


def test_a_robots_images_are_drawn_from_its_own_seed(run, tmp_path):
    """The same scenario run again gives the same images; with noise, bravo's images (robot
    1) are the ones its own seed (`robot_seed` of the scenario's and 1) gives when fired
    again over its log, not the scenario's seed (robot 0's)."""
    scenario, rollouts = run
    again = simulate_robots(scenario).robot("alpha").camera("left")
    np.testing.assert_array_equal(again.rgb, rollouts.robot("alpha").camera("left").rgb)
    noisy = CAMERA.replace("noise_counts = 0.0", "noise_counts = 3.0")
    noisy = _scenario(tmp_path, noisy.replace("[-1.5708,", "[1.5708,"), 0.2, robot=1)
    both = simulate_robots(noisy)
    bravo = both.robot("bravo")
    own = noisy.robots[1]
    assert own.settings.seed == robot_seed(noisy.settings.seed, 1) != noisy.settings.seed
    scene = scene_of(own.uvms, own.plant.world, surface=own.plant.free_surface,
                     others=[("alpha", noisy.robots[0].uvms)])  # fmt: skip
    for seed, same in ((own.settings.seed, True), (noisy.settings.seed, False)):
        fired = copy.copy(bravo)
        fired.perception, fired.metadata = {}, dict(bravo.metadata)
        log = SceneLog(bravo.q, np.zeros((len(bravo), 0, 7)), None, [both.robot("alpha").q])
        perceive(fired, own.sensor_config.perception, scene, seed, log=log)
        assert np.array_equal(fired.camera("left").rgb, bravo.camera("left").rgb) == same


class Watching(Controller):
    """A robot's own controller, keeping the images of its cameras in the loop it is given."""

    def __init__(self, inner: Controller):
        self.inner, self.seen = inner, []

    def compute(self, time_s, measurement):
        image = measurement.images.get("left")
        if image is not None and (not self.seen or self.seen[-1][0] != image.time_s):
            self.seen.append((image.time_s, image.label.copy()))
        return self.inner.compute(time_s, measurement)

    def reset(self) -> None:
        self.inner.reset()
        self.seen = []

    def signals(self):
        return self.inner.signals()


def test_a_camera_in_the_loop_sees_the_other_robot_as_it_moves(tmp_path):
    """alpha's controller is given images of bravo where bravo is at that tick: each equals
    a rendering of the scene with both robots at that tick's logged state (the ticks at
    the log's samples), and bravo's controller, without cameras, is given none."""
    scenario = _scenario(tmp_path, CAMERA + "in_loop = true\n", 0.6)
    watchers = [Watching(robot.controller_factory(robot.uvms)) for robot in scenario.robots]
    rollouts = simulate_robots(scenario, controllers=watchers)
    alpha, bravo = rollouts.robot("alpha"), rollouts.robot("bravo")
    seen = watchers[0].seen
    assert [t for t, _ in seen] == pytest.approx([0.0, 0.2, 0.4, 0.6])
    assert watchers[1].seen == []
    scene = scene_of_alpha(scenario)
    camera = Camera(spec_of(scenario), scene, np.random.default_rng(0))
    bravo_label = scene.names.index("bravo.base_link") + 1
    for t, label in seen:
        row = int(np.argmin(np.abs(alpha.time_s - t)))
        assert alpha.time_s[row] == pytest.approx(t)
        scene.update(alpha.q[row], (), None, [bravo.q[row]])
        np.testing.assert_array_equal(camera.render().label, label)
        assert (label == bravo_label).any()
    # the images fired over the log after the run are the same scene's
    np.testing.assert_array_equal(alpha.camera("left").label[-1], seen[-1][1])


def test_a_robots_camera_on_a_link_its_model_lacks_is_refused_naming_the_robot(tmp_path):
    on_nothing = CAMERA + 'link = "no_link"\n'
    with pytest.raises(ParameterError, match=r"robot 'alpha': camera 'left': link 'no_link'"):
        simulate_robots(_scenario(tmp_path, on_nothing, 0.1))


BALL = """
[[world.objects]]
type = "sphere"
name = "ball"
radius_m = 0.25
density_kg_m3 = 2000.0
position_world_m = [-0.5, 0.0, -1.8]
"""


def test_a_camera_in_the_loop_sees_the_first_robots_free_object_where_it_falls(tmp_path):
    """A ball (a free object of the world, which the first robot's system holds) sinks
    between the robots, in view of alpha's camera in the loop: each image alpha's controller
    is given has the ball where alpha's log puts it at that tick (a rendering of the scene
    with the ball, alpha and bravo at that tick's logged states), and the ball moved."""
    scenario = _scenario(tmp_path, CAMERA + "in_loop = true\n", 0.6)
    text = scenario.path.read_text()
    scenario.path.write_text(text.replace("[[robots]]", BALL + "\n[[robots]]", 1))
    # the ball against alpha's light jaw is a stiff pair at the RK4 step of 2.5 ms (refused
    # before the run, `uvms_pin.sim.stiffness`): 2 ms
    scenario = load_scenario(
        scenario.path, {"scenario.duration_s": 0.6, "integrator.step_s": 0.002}
    )
    watchers = [Watching(robot.controller_factory(robot.uvms)) for robot in scenario.robots]
    rollouts = simulate_robots(scenario, controllers=watchers)
    alpha, bravo = rollouts.robot("alpha"), rollouts.robot("bravo")
    ball_q = alpha.signals["free_objects"][:, :7]
    assert ball_q[0, 2] - ball_q[-1, 2] > 0.3  # it sank
    scene = scene_of_alpha(scenario)
    camera = Camera(spec_of(scenario), scene, np.random.default_rng(0))
    ball_label = scene.names.index("ball") + 1
    seen = watchers[0].seen
    assert len(seen) == 4
    for t, label in seen:
        row = int(np.argmin(np.abs(alpha.time_s - t)))
        scene.update(alpha.q[row], [ball_q[row]], None, [bravo.q[row]])
        np.testing.assert_array_equal(camera.render().label, label)
        assert (label == ball_label).sum() > 20
    assert not np.array_equal(seen[0][1], seen[-1][1])  # the ball's image moved
