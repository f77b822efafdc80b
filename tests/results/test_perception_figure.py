"""perception.png (uvms_pin.results.figures.perception): what a run's cameras and sonars saw,
drawn from the rollout's own images."""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.apps.outputs import write_figures
from uvms_pin.perception.sonar import SonarSpec
from uvms_pin.perception.suite import PerceptionSpec
from uvms_pin.results.figures.perception import (
    PERCEPTION_FIGURE,
    SONAR_DB_RANGE,
    decibels,
    edges,
    plot_perception,
    snapshot_rows,
)
from uvms_pin.results.status import RunStatus
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

ALTIMETER = {"name": "alt", "type": "altimeter", "beams": 1, "bins": 24, "rate_hz": 10.0,
             "horizontal_fov_rad": 0.1, "max_range_m": 12.0,
             "rpy_rad": [0.0, 1.5708, 0.0]}  # fmt: skip


@pytest.fixture(scope="module")
def survey():
    """The seabed survey's camera, imaging sonar and multibeam, and an altimeter, for 0.7 s."""
    scenario = load_scenario(
        ROOT / "scenarios" / "seabed_survey.toml", {"scenario.duration_s": 0.7}
    )
    given = scenario.sensor_config
    sensors = (*given.perception.sensors, ("sonar", SonarSpec.from_dict(ALTIMETER, "test")))
    config = dataclasses.replace(given, perception=PerceptionSpec(sensors))
    return simulate(dataclasses.replace(scenario, sensor_config=config), progress=False)


def test_snapshots_spread_over_the_run_with_its_first_and_last_firing():
    assert list(snapshot_rows(36)) == [0, 12, 23, 35]
    assert list(snapshot_rows(3)) == [0, 1, 2]  # fewer firings than snapshots: all of them
    assert list(snapshot_rows(1)) == [0]


def test_a_single_firing_is_drawn_one_period_wide():
    """A run shorter than a sensor's period fires it once: its cell spans the period."""
    assert edges(np.array([2.0]), 0.2) == pytest.approx((1.9, 2.1))
    assert edges(np.array([0.0, 0.5, 1.0]), 9.0) == (-0.25, 1.25)


def test_the_sonar_scale_spans_fifty_db_below_the_brightest_echo():
    db, low, high = decibels(np.array([[0.0, 1e-3], [1e-8, 0.5]]))
    assert high == pytest.approx(10 * np.log10(0.5)) and high - low == SONAR_DB_RANGE
    assert db[0, 0] == pytest.approx(-300.0)  # no echo: far below the scale, not -inf
    _, low, high = decibels(np.zeros((2, 2)))  # nothing heard: a scale all the same
    assert np.isfinite(low) and np.isfinite(high)


def test_each_sensor_is_drawn_from_its_own_images(survey):
    """The camera's colour images at the snapshot firings, its depths (NaN masked) on one
    scale; the imaging sonar's dB images with port on the left; the multibeam's swath over
    the run; the altimeter's echogram."""
    fig = plot_perception(survey)
    images = {ax.get_title(): ax.images[0] for ax in fig.axes if ax.images}
    camera = survey.camera("front")
    shown = snapshot_rows(len(camera.time_s))
    for k in shown:
        title = f"camera 'front', t = {camera.time_s[k]:.2f} s"
        np.testing.assert_array_equal(images[title].get_array(), camera.rgb[k])
    depths = [ax.images[0] for ax in fig.axes if ax.get_title() == "z-depth"]
    assert len(depths) == len(shown)
    for image, k in zip(depths, shown, strict=True):
        drawn = image.get_array()
        np.testing.assert_array_equal(drawn.mask, np.isnan(camera.depth_m[k]))
        np.testing.assert_array_equal(drawn.filled(np.nan), camera.depth_m[k])
    assert len({image.get_clim() for image in depths}) == 1
    fls = survey.sonar("fls")
    k = snapshot_rows(len(fls.time_s))[-1]
    drawn = images[f"sonar 'fls', t = {fls.time_s[k]:.2f} s"]
    np.testing.assert_allclose(drawn.get_array(), decibels(fls.intensity[k])[0][:, ::-1])
    left, right, bottom, top = drawn.get_extent()
    half_beam = 0.5 * np.degrees(fls.bearing_rad[1] - fls.bearing_rad[0])
    assert left == pytest.approx(np.degrees(fls.bearing_rad[-1]) + half_beam) and left > 0 > right
    half_bin = 0.5 * (fls.range_m[1] - fls.range_m[0])
    assert (bottom, top) == pytest.approx((fls.range_m[0] - half_bin, fls.range_m[-1] + half_bin))
    swath = images["multibeam 'multibeam': detections"].get_array()
    np.testing.assert_array_equal(swath.filled(np.nan), survey.sonar("multibeam").beam_range_m.T)
    echogram = images["altimeter 'alt': echogram"].get_array()
    np.testing.assert_allclose(echogram, decibels(survey.sonar("alt").intensity)[0][:, :, 0].T)


def test_a_run_without_cameras_or_sonars_has_no_perception_figure(tmp_path):
    plain = simulate(
        load_scenario(
            ROOT / "scenarios" / "passive_still_water.toml", {"scenario.duration_s": 0.1}
        ),
        progress=False,
    )
    assert PERCEPTION_FIGURE not in {p.name for p in write_figures(plain, tmp_path)}


def test_a_stopped_runs_figure_says_where_it_stopped(survey):
    """The stop's reason under the title, a dashed line at its time on the bands drawn
    over time (the swath, the echogram), none on the images."""
    stopped = copy.copy(survey)
    stopped.metadata = dict(survey.metadata)
    stopped.set_status(RunStatus("SimulationError", "a test's stop", time_s=0.45))
    fig = plot_perception(stopped)
    assert "SimulationError: a test's stop" in fig._suptitle.get_text()
    for ax in fig.axes:
        stops = [line for line in ax.get_lines() if np.all(np.asarray(line.get_xdata()) == 0.45)]
        over_time = ax.get_xlabel() == "time [s]"
        assert bool(stops) == over_time, ax.get_title()


def test_a_camera_that_sees_only_water_says_so():
    """Looking down in open water from 2 m ahead of the vehicle (no seabed, no object, the
    arm behind), the depth panels would be blank: each says "nothing in view"."""
    down = {"name": "down", "width": 32, "height": 24, "horizontal_fov_rad": 0.3,
            "rpy_rad": [3.1416, 0.0, 0.0], "position_m": [2.0, 0.0, 0.0]}  # fmt: skip
    rollout = _open_water({"sensors.camera": [down]})
    assert np.all(np.isnan(rollout.camera("down").depth_m))
    fig = plot_perception(rollout)
    depths = [ax for ax in fig.axes if ax.get_title() == "z-depth"]
    assert depths and all([t.get_text() for t in ax.texts] == ["nothing in view"] for ax in depths)


def test_an_altimeter_that_hears_nothing_says_so():
    """An altimeter with nothing within its range (open water) draws an empty echogram and
    says so."""
    rollout = _open_water({"sensors.sonar": [ALTIMETER]})
    assert not np.any(rollout.sonar("alt").intensity)
    (ax,) = [a for a in plot_perception(rollout).axes if a.get_title().startswith("altimeter")]
    assert len(ax.texts) == 1 and ax.texts[0].get_text().startswith("no echo within 12")


def _open_water(sensors: dict):
    """passive_still_water (no seabed, no object) for 0.3 s with ``sensors``."""
    path = ROOT / "scenarios" / "passive_still_water.toml"
    return simulate(load_scenario(path, {"scenario.duration_s": 0.3, **sensors}), progress=False)


def test_panels_with_something_in_view_have_no_note(survey):
    fig = plot_perception(survey)
    depths = [ax for ax in fig.axes if ax.get_title() == "z-depth"]
    assert depths and not any(ax.texts for ax in depths)
    (echogram,) = [ax for ax in fig.axes if ax.get_title().startswith("altimeter")]
    assert not echogram.texts


def test_a_one_beam_imaging_sonar_is_drawn_as_an_echogram_under_its_own_type():
    """An imaging sonar of one beam has no fan to draw: its echogram over time, titled as the
    imaging sonar it is (not as an altimeter), without a reading (it detects nothing)."""
    one_beam = {"name": "pencil", "type": "imaging", "beams": 1, "bins": 32,
                "horizontal_fov_rad": 0.1, "max_range_m": 12.0,
                "rpy_rad": [0.0, 1.5708, 0.0]}  # fmt: skip
    scenario = load_scenario(
        ROOT / "scenarios" / "seabed_survey.toml",
        {"scenario.duration_s": 0.3, "sensors.sonar": [one_beam], "sensors.camera": []},
    )
    rollout = simulate(scenario, progress=False)
    assert np.any(rollout.sonar("pencil").intensity)  # it hears the seabed below
    fig = plot_perception(rollout)
    (ax,) = [a for a in fig.axes if "pencil" in a.get_title()]
    assert ax.get_title() == "imaging 'pencil': echogram"
    np.testing.assert_allclose(
        ax.images[0].get_array(), decibels(rollout.sonar("pencil").intensity)[0][:, :, 0].T
    )
    assert not ax.lines
