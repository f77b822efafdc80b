"""A run's cameras and sonars: declared in the scenario, fired over the logged states, kept
beside the rollout."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ParameterError, PerceptionWarning, ScenarioError
from uvms_pin.perception.suite import HUGE_PAGE, firing_rows, fixture_positions, stack_of
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.run import simulate

SEABED = Path(__file__).resolve().parents[2] / "scenarios" / "seabed_landing.toml"
CAMERA = {"name": "front", "width": 64, "height": 48, "rate_hz": 10.0,
          "rpy_rad": [-2.4, 0.0, -1.5708], "noise_counts": 2.0}  # fmt: skip
SONAR = {"name": "fls", "beams": 32, "bins": 64, "rate_hz": 5.0, "rpy_rad": [0.0, 0.5, 0.0]}


def _scenario(sensors=None, duration_s=0.2, seed=7):
    raw = read_toml(SEABED, ScenarioError)
    raw["scenario"].update(duration_s=duration_s, seed=seed)
    raw["sensors"] = copy.deepcopy(sensors or {})
    return scenario_from_dict(raw, SEABED)


def test_firing_rows_are_the_first_logged_samples_at_each_instant():
    times = np.arange(11) * 0.02
    np.testing.assert_array_equal(firing_rows(times, 10.0), [0, 5, 10])
    np.testing.assert_array_equal(firing_rows(times, 7.0), [0, 8])  # 1/7 s -> 0.16 s
    np.testing.assert_array_equal(firing_rows(times, 1000.0), np.arange(11))


def test_fixtures_are_posed_from_their_logged_signals_or_stay_at_their_start():
    """Each fixture's joint positions are the signal named after it; a run that logged
    none of them (or not all) leaves every fixture where it started (None), not a KeyError."""
    rollout = Rollout.allocate(3, 7, 6)
    assert fixture_positions(rollout, []) is None
    assert fixture_positions(rollout, ["panel"]) is None
    rollout.signals["panel"] = np.array([[0.0], [0.1], [0.2]])
    (panel,) = fixture_positions(rollout, ["panel"])
    np.testing.assert_array_equal(panel, [[0.0], [0.1], [0.2]])
    assert fixture_positions(rollout, ["panel", "valve"]) is None


def test_a_run_records_its_cameras_and_sonars_beside_an_unchanged_rollout(tmp_path):
    plain = simulate(_scenario(), progress=False)
    seen = simulate(_scenario({"camera": [CAMERA], "sonar": [SONAR]}), progress=False)
    np.testing.assert_array_equal(plain.q, seen.q)  # the loop is untouched
    camera = seen.camera("front")
    np.testing.assert_allclose(camera.time_s, [0.0, 0.1, 0.2], atol=1e-12)
    assert camera.rgb.shape == (3, 48, 64, 3) and camera.rgb.dtype == np.uint8
    assert camera.depth_m.shape == (3, 48, 64) and camera.label.shape == (3, 48, 64)
    assert "seabed" in [camera.label_names[k - 1] for k in np.unique(camera.label) if k > 0]
    sonar = seen.sonar("fls")
    assert sonar.intensity.shape == (2, 64, 32) and sonar.range_m.shape == (64,)
    assert sonar.bearing_rad.shape == (32,) and sonar.intensity.max() > 0.0
    seen.save(tmp_path)
    assert (tmp_path / "perception.npz").is_file()
    loaded = Rollout.load(tmp_path)
    np.testing.assert_array_equal(loaded.camera("front").rgb, camera.rgb)
    np.testing.assert_array_equal(loaded.sonar("fls").intensity, sonar.intensity)
    assert loaded.camera("front").label_names == camera.label_names
    with pytest.raises(ParameterError, match=r"no camera 'back'.*front"):
        loaded.camera("back")
    plain.save(tmp_path)  # the previous run's images go with it
    assert not (tmp_path / "perception.npz").exists()


def test_the_same_seed_gives_the_same_images():
    def images(seed):
        rollout = simulate(_scenario({"camera": [CAMERA]}, 0.1, seed), progress=False)
        return rollout.camera("front").rgb

    np.testing.assert_array_equal(images(3), images(3))
    assert not np.array_equal(images(3), images(4))


@pytest.mark.parametrize(
    ("sensors", "message"),
    [
        ({"camera": [{**CAMERA, "width": 0}]}, r"sensors\.camera\[0\].*width"),
        ({"camera": [{**CAMERA, "fov": 1.0}]}, r"sensors\.camera\[0\].*unknown key.*fov"),
        ({"camera": [{**CAMERA, "rate_hz": "fast"}]}, "rate_hz"),
        ({"sonar": [{**SONAR, "type": "sidescan"}]}, r"sensors\.sonar\[0\].*type"),
        ({"camera": [CAMERA], "sonar": [{**SONAR, "name": "front"}]}, "distinct names.*front"),
        ({"camera": [{"width": 10}]}, "name is required"),
    ],
)
def test_a_bad_sensor_table_is_refused_naming_the_key(sensors, message):
    with pytest.raises(ScenarioError, match=message):
        _scenario(sensors)


def test_a_sensor_on_a_link_the_model_lacks_is_refused_before_the_run():
    scenario = _scenario({"camera": [{**CAMERA, "link": "mast"}]})
    with pytest.raises(ParameterError, match=r"camera 'front': link 'mast'.*it has: 'universe'"):
        simulate(scenario, progress=False)


def test_a_misspelt_link_is_refused_with_the_frames_it_resembles():
    scenario = _scenario({"sonar": [{**SONAR, "link": "base_lnk"}]})
    with pytest.raises(
        ParameterError, match=r"sonar 'fls': link 'base_lnk'.*did you mean 'base_link'"
    ):
        simulate(scenario, progress=False)


def test_a_sensor_faster_than_the_log_is_warned_of_and_fires_on_its_grid(recwarn):
    """A sensor fires at logged samples: a camera of 100 Hz over the scenario's log of 50 Hz gives 50
    images a second, and says so before the run, naming it and the log period that would
    give its rate; a sonar at the log's rate, and one slower, are not warned of."""
    sonars = [{**SONAR, "rate_hz": 50.0}, {**SONAR, "name": "slow", "rate_hz": 30.0}]
    scenario = _scenario({"camera": [{**CAMERA, "rate_hz": 100.0}], "sonar": sonars})
    rollout = simulate(scenario, progress=False)
    warned = [w for w in recwarn if issubclass(w.category, PerceptionWarning)]
    assert len(warned) == 1, [str(w.message) for w in warned]
    assert str(warned[0].message) == (
        "camera 'front' fires at logged samples: at 50 Hz, not its rate_hz = 100 "
        "(output.log_period_s = 0.02 s; 0.01 s or less gives its rate)"
    )
    np.testing.assert_allclose(rollout.camera("front").time_s, np.arange(11) * 0.02)
    np.testing.assert_allclose(rollout.sonar("fls").time_s, np.arange(11) * 0.02)


def test_images_that_would_not_fit_in_memory_are_refused_before_the_run():
    huge = {**CAMERA, "width": 8192, "height": 8192, "rate_hz": 1000.0}
    scenario = _scenario({"camera": [huge]}, duration_s=100.0)
    with pytest.raises(ParameterError, match=r"images of front.*lower their rate_hz"):
        simulate(scenario, progress=False)


def test_a_camera_faster_than_the_log_is_counted_at_the_logs_rate_before_the_run(
    monkeypatch,
):
    """A 320 x 240 camera asked for 5000 Hz over 12 s fires at the 50 Hz log: 601 images,
    415 MB, not the 60,001 its rate would make (41 GB: a legal run was refused). A camera
    without a log period given is counted at its rate."""
    from uvms_pin.perception import suite
    from uvms_pin.perception.camera import CameraSpec

    counted = []
    monkeypatch.setattr(suite, "check_memory", lambda size, what, how: counted.append(size))
    spec = suite.PerceptionSpec((("camera", CameraSpec("front", rate_hz=5000.0)),))
    model = _scenario().uvms.model
    with pytest.warns(PerceptionWarning, match="fires at logged samples: at 50 Hz"):
        suite.check_mounts(spec, model, 12.0, 0.02)
    assert counted == [601 * 320 * 240 * 9]
    suite.check_mounts(spec, model, 12.0, None)  # no log period given: the rate's count
    assert counted[-1] == 60001 * 320 * 240 * 9


def test_an_in_loop_camera_faster_than_the_control_ticks_is_said_before_the_run(monkeypatch):
    """Its controller reads it at a tick at the most: 250 Hz asked, 100 Hz read at a 10 ms
    period, said in a PerceptionWarning (it was silent); a camera not in the loop, or at
    the ticks' rate, is not."""
    from uvms_pin.perception import suite
    from uvms_pin.perception.camera import CameraSpec

    monkeypatch.setattr(suite, "check_memory", lambda size, what, how: None)
    model = _scenario().uvms.model
    fast = CameraSpec("eye", rate_hz=250.0, in_loop=True)
    with pytest.warns(PerceptionWarning, match=r"'eye' is read by the controller at its ticks: "
                      r"at 100 Hz at the most, not its rate_hz = 250"):  # fmt: skip
        suite.check_mounts(suite.PerceptionSpec((("camera", fast),)), model, 1.0, None, 0.01)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for spec in (
            CameraSpec("eye", rate_hz=250.0),
            CameraSpec("eye", rate_hz=100.0, in_loop=True),
        ):
            suite.check_mounts(suite.PerceptionSpec((("camera", spec),)), model, 1.0, None, 0.01)


def test_a_sensor_above_the_free_surface_is_said_after_the_run():
    """A camera on a 12 m mast above the vehicle 9.5 m down: in the air at every firing. Its
    images are formed as under water (the model has no air), which a PerceptionWarning now
    says, with how many firings and the first's time (it was silent); the same camera below
    the surface, or a sonar there, says nothing."""
    import warnings

    def with_surface(sensors):
        raw = read_toml(SEABED, ScenarioError)
        raw["scenario"].update(duration_s=0.2, seed=7)
        raw["water"]["free_surface"] = True  # seabed_landing's is off (10 m down)
        raw["sensors"] = copy.deepcopy(sensors)
        return scenario_from_dict(raw, SEABED)

    mast = {**CAMERA, "position_m": [0.0, 0.0, 12.0]}
    with pytest.warns(PerceptionWarning, match=r"camera 'front' was above the free surface at "
                      r"3 of its 3 firings \(the first at t = 0 s\)"):  # fmt: skip
        simulate(with_surface({"camera": [mast]}), progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PerceptionWarning)
        simulate(with_surface({"camera": [CAMERA], "sonar": [SONAR]}), progress=False)


def test_the_sensors_are_cast_on_the_plants_backend_with_the_same_images(monkeypatch):
    """`simulate` builds the sensors' scene once, on the plant's backend ([integrator]
    backend); the compiled caster's images are the Python reference's over the same log."""
    import uvms_pin.sim.run as run
    from uvms_pin.perception.scene import scene_of
    from uvms_pin.perception.suite import perceive

    built = []

    def spy(*args, **kwargs):
        scene = scene_of(*args, **kwargs)
        built.append(scene.compiled)
        return scene

    monkeypatch.setattr(run, "scene_of", spy)
    sensors = {"camera": [CAMERA], "sonar": [SONAR]}
    rollout = simulate(_scenario(sensors), progress=False)
    raw = read_toml(SEABED, ScenarioError)
    raw["scenario"].update(duration_s=0.04, seed=7)
    raw["integrator"]["backend"] = "python"
    raw["sensors"] = copy.deepcopy(sensors)
    simulate(scenario_from_dict(raw, SEABED), progress=False)
    assert built == [True, False]
    compiled = {name: dict(images) for name, images in rollout.perception.items()}
    scenario = _scenario(sensors)
    plant = scenario.plant
    reference = scene_of(plant.uvms, plant.world, surface=plant.free_surface, backend="python")
    perceive(rollout, scenario.sensor_config.perception, reference, 7)
    camera, sonar = rollout.perception["front"], rollout.perception["fls"]
    np.testing.assert_array_equal(compiled["front"]["label"], camera["label"])
    # the rock's ranges: Embree's single precision in the reference (float32: a few ulps of
    # the ray's terms, up to ~7e-6 relative at grazing rays), double in the core; the rest
    # to the core's rounding
    rock = camera["label"] == reference.names.index("rock") + 1
    assert rock.any() and (~rock).any()
    depth = compiled["front"]["depth_m"]
    np.testing.assert_allclose(depth[rock], camera["depth_m"][rock], rtol=1e-5)
    np.testing.assert_allclose(depth[~rock], camera["depth_m"][~rock], rtol=1e-9)
    differ = compiled["front"]["rgb"].astype(int) - camera["rgb"]
    assert np.all(np.abs(differ) <= 1) and np.mean(differ != 0) < 1e-3  # a rounding at most
    np.testing.assert_allclose(compiled["fls"]["intensity"], sonar["intensity"], rtol=1e-5)
    assert sonar["intensity"].max() > 0.0


@pytest.mark.parametrize(
    ("shape", "dtype"),
    [((21, 240, 320), np.float32), ((21, 240, 320, 3), np.uint8), ((3, 4), np.int16)],
)
def test_an_image_stack_starts_on_a_huge_page_when_larger_than_one(shape, dtype):
    stack = stack_of(shape, dtype)
    assert stack.shape == shape and stack.dtype == dtype and stack.flags.c_contiguous
    assert stack.flags.writeable
    if stack.nbytes >= HUGE_PAGE:
        assert stack.ctypes.data % HUGE_PAGE == 0
    stack[...] = 7  # all of it is its own
    assert np.all(stack == 7)


def test_the_memory_checked_before_a_run_is_what_its_images_take():
    """Each kind's `bytes(spec)` (what `check_mounts` sums before the run) is what one firing
    keeps: the camera's depth, colour and labels, a sonar's image, a multibeam's detections."""
    from uvms_pin.perception.sensor import SENSORS

    multibeam = {"name": "mb", "type": "multibeam", "beams": 16, "bins": 32, "rate_hz": 5.0,
                 "rpy_rad": [0.0, 1.5708, 0.0]}  # fmt: skip
    scenario = _scenario({"camera": [CAMERA], "sonar": [SONAR, multibeam]})
    rollout = simulate(scenario, progress=False)
    specs = {spec.name: (kind, spec) for kind, spec in scenario.sensor_config.perception.sensors}
    for name, recorded in (("front", rollout.camera("front")), ("fls", rollout.sonar("fls")),
                           ("mb", rollout.sonar("mb"))):  # fmt: skip
        kind, spec = specs[name]
        firings = len(recorded.time_s)
        kept = sum(
            value.nbytes
            for key, value in vars(recorded).items()
            if isinstance(value, np.ndarray) and value.ndim > 1 and len(value) == firings
        )
        assert kept == firings * SENSORS[kind].bytes(spec), name
