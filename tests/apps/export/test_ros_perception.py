"""A run's cameras and sonars in its ROS 2 bag (uvms_pin.apps.export.ros_perception): a camera
on a moving arm link and sonars looking into open water export as their images, read back by
rosbags equal to the rollout's (tests/ros_bag_check.py); the conversions of "no return"."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.apps.export.ros_perception import camera_info, laser_scan, ros_name
from uvms_pin.errors import VizError
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

pytest.importorskip("rosbags")
pytest.importorskip("mcap_ros2")
from ros_bag_check import check_bag, read_bag

SCENARIO = """
[scenario]
name = "sensors_on_the_arm"
model = "uvms_bluerov2_alpha5"
duration_s = 0.3
seed = 11

[water]
free_surface = false

[initial]
position_world_m = [0.0, 0.0, -5.0]
joint_positions_rad = [0.3, 0.8, 2.2, 0.0]

[[world.objects]]
type = "plane"
name = "seabed"
point_world_m = [0.0, 0.0, -6.0]

[[world.objects]]
type = "box"
name = "crate"
size_m = [0.4, 0.4, 0.4]
position_world_m = [1.2, 0.0, -5.6]

[joints]
hard_stops = true

[[sensors.camera]]
name = "wrist"
link = "alpha_forearm_link"
position_m = [0.02, 0.0, 0.05]
rpy_rad = [0.4, -1.2, 0.3]
width = 40
height = 30
horizontal_fov_rad = 1.3
rate_hz = 20.0

[[sensors.sonar]]
name = "profiler"
type = "multibeam"
beams = 24
bins = 64
horizontal_fov_rad = 2.4
vertical_fov_rad = 0.05
max_range_m = 3.0
rate_hz = 10.0
rays_per_beam = 2
rpy_rad = [0.0, 0.6, 0.0]   # ahead and down: the seabed in the middle beams, open water beyond

[[sensors.sonar]]
name = "altimeter"
type = "altimeter"
link = "ft_sensor_joint"    # a frame that is not a link: hung from its joint's link
beams = 1
bins = 32
horizontal_fov_rad = 0.1
max_range_m = 4.0
rate_hz = 10.0
rpy_rad = [0.0, 1.5708, 0.0]

[[sensors.sonar]]
name = "echosounder"        # on the vehicle, looking down at the seabed 1 m below
type = "altimeter"
rate_hz = 10.0
rpy_rad = [0.0, 1.5707963267948966, 0.0]
"""


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    where = tmp_path_factory.mktemp("sensors")
    path = where / "scenario.toml"
    path.write_text(SCENARIO)
    rollout = simulate(load_scenario(path), progress=False)
    rollout.save(where / "run")
    return where / "run"


def test_a_camera_on_a_moving_link_and_sonars_export_as_their_images(saved, tmp_path):
    """Every image bit for bit, each sensor's frame composed along the TF tree where its
    mount (a link, or a frame fixed to one) and pose put it at every sample, the camera's
    intrinsics projecting each pixel's ray on that pixel; the cases are posed (the arm
    moves, a beam hears nothing)."""
    rollout = Rollout.load(saved)
    assert np.ptp(rollout.q[:, 7], axis=0) > 1e-3  # the camera's link turns in the run
    beams = rollout.perception["profiler"]["beam_range_m"]
    assert np.isnan(beams).any() and np.isfinite(beams).any()
    bag = read_bag(rollout.to_mcap(tmp_path / "run.mcap"))
    check_bag(rollout, bag)
    static = {t.child_frame_id: t.header.frame_id for t in bag["/tf_static"][0][1].transforms}
    assert static["wrist_optical_frame"] == "alpha_forearm_link"
    assert static["profiler_frame"] == "base_link"
    assert static["altimeter_frame"] == "alpha_wrist_link"
    assert len(bag["/wrist/image_raw"]) == 7  # 20 Hz over 0.3 s, t = 0 included
    assert len(bag["/altimeter/image"]) == 4 and "/altimeter/scan" not in bag
    readings = [m.range for _, m in bag["/altimeter/range"]]  # sensor_msgs/Range
    assert readings == [np.inf] * 4  # it looks into open water: +Inf (REP 117)
    altitude = [m.range for _, m in bag["/echosounder/range"]]  # from its origin to z = -6 m
    fired = np.searchsorted(rollout.time_s, rollout.sonar("echosounder").time_s)
    np.testing.assert_allclose(altitude, rollout.q[fired, 2] + 6.0, rtol=1e-4)
    assert np.isinf(bag["/profiler/scan"][0][1].ranges).any()


def test_a_run_saved_before_sensor_specs_were_kept_exports_without_their_topics(saved, tmp_path):
    """An older run's metadata names its sensors without their specs: the bag has every
    other topic, and none of the sensors' (nothing to place their frames by)."""
    rollout = Rollout.load(saved)
    for about in rollout.metadata["perception"].values():
        del about["spec"]
    bag = read_bag(rollout.to_mcap(tmp_path / "old.mcap"))
    check_bag(rollout, bag)
    assert not [topic for topic in bag if topic.startswith(("/wrist", "/profiler", "/altim"))]


def test_a_sensor_on_a_frame_the_model_has_not_is_refused_naming_it(saved, tmp_path):
    """A run exported with another model (``--urdf``) whose frames lack the sensor's mount:
    the export's error names the frame, nothing is written."""
    rollout = Rollout.load(saved)
    rollout.metadata["perception"]["wrist"]["frame"] = "no_such_link"
    with pytest.raises(VizError, match=r"'no_such_link'.*pass --urdf"):
        rollout.to_mcap(tmp_path / "run.mcap")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("sensor", "damage"),
    [("wrist", lambda about: about["spec"].pop("width")),
     ("wrist", lambda about: about["spec"].update(rpy_rad=[0.1, 0.2])),
     ("profiler", lambda about: about["spec"].update(max_range_m="far"))],
    ids=["no width", "two angles", "a word for a range"],
)  # fmt: skip
def test_a_damaged_sensor_record_is_refused_naming_the_sensor(saved, tmp_path, sensor, damage):
    """A run's metadata edited by hand: the export's error names the sensor, no file."""
    rollout = Rollout.load(saved)
    damage(rollout.metadata["perception"][sensor])
    with pytest.raises(VizError, match=f"sensor '{sensor}' is damaged"):
        rollout.to_mcap(tmp_path / "run.mcap")
    assert list(tmp_path.iterdir()) == []


def test_two_sensors_of_one_ros_name_are_refused_naming_both(saved, tmp_path):
    """Sensor names the scenario keeps apart ("echo-sounder", "echo.sounder") but ROS does
    not: one topic and one TF frame would carry both sensors' messages interleaved, so the
    export refuses, naming both, and writes nothing (was: exit 0, one topic of both)."""
    rollout = Rollout.load(saved)
    described = rollout.metadata["perception"]
    for old, new in (("altimeter", "echo-sounder"), ("echosounder", "echo.sounder")):
        rollout.perception[new] = rollout.perception.pop(old)
        described[new] = described.pop(old)
    with pytest.raises(VizError, match=r"'echo-sounder' and 'echo.sounder' .* 'echo_sounder'"):
        rollout.to_mcap(tmp_path / "run.mcap")
    assert list(tmp_path.iterdir()) == []
    for old, new in (("echo-sounder", "echo_a"), ("echo.sounder", "echo_b")):
        rollout.perception[new] = rollout.perception.pop(old)
        described[new] = described.pop(old)
    check_bag(rollout, read_bag(rollout.to_mcap(tmp_path / "run.mcap")))  # apart: exported


def test_a_run_whose_images_were_not_found_says_so_on_read_and_on_export(saved, tmp_path):
    """Its perception.npz not copied with it: ``camera(name)`` says the images were not
    found (it said the run had no such camera, naming it among its cameras), and the
    export warns that it leaves them out (it was silent)."""
    import shutil

    from uvms_pin.errors import ParameterError, PerceptionWarning

    copied = tmp_path / "copied"
    shutil.copytree(saved, copied)
    (copied / "perception.npz").unlink()
    rollout = Rollout.load(copied)
    with pytest.raises(ParameterError, match=r"camera 'wrist' has no images: .*perception.npz"):
        rollout.camera("wrist")
    with pytest.raises(ParameterError, match=r"has no camera 'lens' \(its cameras: wrist\)"):
        rollout.camera("lens")
    with pytest.warns(PerceptionWarning, match=r"'profiler', 'wrist' left out of the bag"):
        rollout.to_mcap(tmp_path / "run.mcap")


def test_a_sensor_name_becomes_a_ros_name():
    """ROS names are letters, digits and underscores, not starting with a digit."""
    assert ros_name("front") == "front"
    assert ros_name("front cam-2") == "front_cam_2"
    assert ros_name("2nd") == "_2nd"
    assert ros_name("caméra") == "cam_ra"


def test_no_return_is_sent_as_infinity_and_the_scan_spans_the_bearings():
    """REP 117: a beam that heard nothing reads +Inf (the rollout's NaN); the scan's angles
    are the beams' bearings, its limits the sonar's."""
    spec = {"rate_hz": 5.0, "min_range_m": 0.1, "max_range_m": 12.0}
    bearing = np.linspace(-1.0, 1.0, 5)
    scan = laser_scan(7, "s", spec, bearing, np.array([1.0, np.nan, 2.5, np.nan, 3.0]), np.ones(5))
    assert scan["ranges"] == [1.0, np.inf, 2.5, np.inf, 3.0]
    assert (scan["angle_min"], scan["angle_max"], scan["angle_increment"]) == (-1.0, 1.0, 0.5)
    assert (scan["range_min"], scan["range_max"], scan["scan_time"]) == (0.1, 12.0, 0.2)


def test_camera_info_is_the_pinhole_of_the_horizontal_field_of_view():
    """f = W / 2 / tan(hfov / 2) on both axes, the principal point at the centre of an odd
    and an even side (ROS's pixel centres are integers), K inside P, no distortion."""
    info = camera_info(0, "c", {"width": 41, "height": 30, "horizontal_fov_rad": np.pi / 2})
    k = np.array(info["k"]).reshape(3, 3)
    np.testing.assert_allclose(k, [[20.5, 0, 20.0], [0, 20.5, 14.5], [0, 0, 1]], rtol=1e-15)
    np.testing.assert_array_equal(np.array(info["p"]).reshape(3, 4)[:, :3], k)
    assert info["d"] == [0.0] * 5 and info["distortion_model"] == "plumb_bob"
