"""The DVL's bottom: a flat depth, or the world's seafloor planes (flat or sloping)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.errors import ScenarioError
from uvms_pin.physics.world.objects import plane
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.navigation.seabed import FlatSeabed, world_seabed

LANDING = ROOT / "scenarios" / "seabed_landing.toml"
DVL = {"noise_m_s": 0.0, "max_altitude_m": 50.0}


def test_a_flat_world_plane_is_the_flat_seabed():
    floor = world_seabed([plane("bottom", [3.0, -2.0, -12.0], [0.0, 0.0, 1.0], 0.5, 0.5)])
    for point in ([0.0, 0.0, -5.0], [7.0, 3.0, -11.0], [1.0, 1.0, -13.0]):
        assert floor.altitude_m(np.array(point)) == pytest.approx(
            FlatSeabed(12.0).altitude_m(np.array(point)), abs=1e-12
        )


def test_a_slope_is_measured_straight_down_and_the_highest_floor_counts():
    angle = np.radians(10.0)  # rising towards +x
    normal = [-np.sin(angle), 0.0, np.cos(angle)]
    slope = plane("slope", [0.0, 0.0, -10.0], normal, 0.5, 0.5)
    flat = plane("shelf", [0.0, 0.0, -9.0], [0.0, 0.0, 1.0], 0.5, 0.5)
    wall = plane("wall", [5.0, 0.0, 0.0], [-1.0, 0.0, 0.0], 0.5, 0.5)
    point = np.array([-4.0, 1.0, -3.0])
    bottom_z = -10.0 + np.tan(angle) * point[0]  # the slope under x = -4
    assert world_seabed([slope, wall]).altitude_m(point) == pytest.approx(point[2] - bottom_z)
    # the shelf at -9 is higher than the slope there (-10.7): the DVL sees the shelf
    assert world_seabed([slope, flat, wall]).altitude_m(point) == pytest.approx(6.0)
    assert world_seabed([wall]) is None  # a wall is not a bottom


def test_with_a_world_the_dvl_measures_above_its_seafloor():
    overrides = {"scenario.duration_s": 0.1, "sensors.dvl": DVL}
    rollout = up.simulate(load_scenario(LANDING, overrides))
    altitude = rollout.signals["dvl"][:, 3]
    normal = np.array([-0.139173, 0.0, 0.990268])
    below = np.einsum("j,ij->i", normal, rollout.q[:, :3] - [0.0, 0.0, -10.0]) / normal[2]
    np.testing.assert_allclose(altitude, below, rtol=1e-12)


def test_a_world_seafloor_and_the_flat_key_at_once_are_refused():
    overrides = {"sensors.dvl": {**DVL, "seabed_depth_m": 10.0}}
    with pytest.raises(ScenarioError, match=r"sensors.dvl.seabed_depth_m.*world has a seafloor"):
        load_scenario(LANDING, overrides)


def test_no_bottom_at_all_is_refused_naming_both_ways():
    overrides = {"sensors.dvl": DVL, "control.period_s": 0.01}
    with pytest.raises(ScenarioError, match=r"seabed_depth_m.*world.objects"):
        load_scenario(ROOT / "scenarios" / "passive_still_water.toml", overrides)
