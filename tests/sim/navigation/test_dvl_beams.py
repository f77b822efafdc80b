"""The DVL's four beams cast at the world: the bottom, the objects on it, the lock lost when
a beam leaves the DVL's altitudes, and the estimator that then takes no DVL update."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from tests.sim.estimation.trajectory import NAVIGATION, run
from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.sim.estimation.spec import EstimatorSpec
from uvms_pin.sim.navigation.dvl import Dvl, DvlSpec, janus_beams
from uvms_pin.sim.navigation.seabed import FlatSeabed, world_seabed

VELOCITY = np.array([0.3, -0.1, 0.05])


def _dvl(seabed, **spec) -> Dvl:
    return Dvl(DvlSpec(beams=4, min_altitude_m=0.5, max_altitude_m=30.0, **spec), seabed,
               np.random.default_rng(1))  # fmt: skip


def test_the_beams_form_a_janus_x_at_their_angle_from_down():
    beams = janus_beams(0.5)
    np.testing.assert_allclose(np.linalg.norm(beams, axis=1), 1.0, rtol=1e-15)
    np.testing.assert_allclose(beams[:, 2], -np.cos(0.5), rtol=1e-15)
    np.testing.assert_allclose(beams.sum(axis=0)[:2], 0.0, atol=1e-15)  # symmetric


@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (0.1, -0.25, 1.0)])
def test_over_a_flat_bottom_the_beams_read_the_altitude_level_or_tilted(rpy):
    dvl = _dvl(FlatSeabed(40.0))
    rotation = pin.rpy.rpyToMatrix(*rpy)
    out = dvl.measure(np.array([1.0, 2.0, -32.0]), VELOCITY, rotation)
    assert out[4] == 1.0
    np.testing.assert_array_equal(out[:3], VELOCITY)  # noise 0
    assert out[3] == pytest.approx(8.0, abs=1e-12)  # every beam's hit is 8 m below


def test_the_lock_is_lost_out_of_the_altitudes_as_for_the_vertical_ping():
    for depth_m, locked in ((39.8, 0.0), (35.0, 1.0), (5.0, 0.0)):
        out = _dvl(FlatSeabed(40.0)).measure(np.array([0.0, 0.0, -depth_m]), VELOCITY)
        assert out[4] == locked
        assert out[3] == pytest.approx(40.0 - depth_m, abs=1e-12)
        if not locked:
            np.testing.assert_array_equal(out[:3], 0.0)


def test_the_beams_see_an_object_on_the_seabed_and_lose_the_lock_on_a_high_one():
    seabed = plane("seabed", [0.0, 0.0, -20.0], [0.0, 0.0, 1.0], 0.5, 0.4)
    # one beam (azimuth 45 degrees: +x +y) reaches the seabed 3 m below at 3 tan 30 deg
    # = 1.73 m out, at (1.22, 1.22); a box there 1 m high, then 2.8 m high
    low = solid("low", "box", {"size_m": [1.0, 1.0, 2.0]}, [1.22, 1.22, -20.0], [0, 0, 0],
                0.5, 0.4)  # fmt: skip
    dvl = _dvl(world_seabed([seabed, low]))
    out = dvl.measure(np.array([0.0, 0.0, -17.0]), VELOCITY, np.eye(3))
    assert out[4] == 1.0
    # three beams 3 m, the fourth meets the box's top 2 m below
    assert out[3] == pytest.approx((3 * 3.0 + 2.0) / 4, abs=1e-12)
    # a box whose top is 0.4 m below the DVL, under the same beam
    high = solid("high", "box", {"size_m": [2.0, 2.0, 2.6]}, [1.1, 1.1, -18.7], [0, 0, 0],
                 0.5, 0.4)  # fmt: skip
    blocked = _dvl(world_seabed([seabed, high])).measure(
        np.array([0.0, 0.0, -17.0]), VELOCITY, np.eye(3)
    )
    assert blocked[4] == 0.0  # its top 0.4 m below: under the DVL's 0.5 m
    np.testing.assert_array_equal(blocked[:3], 0.0)


def test_a_beam_into_open_water_loses_the_lock():
    seabed = plane("seabed", [0.0, 0.0, -20.0], [0.0, 0.0, 1.0], 0.5, 0.4)
    dvl = _dvl(world_seabed([seabed]))
    rolled = pin.rpy.rpyToMatrix(1.2, 0.0, 0.0)  # two beams point above the horizon
    out = dvl.measure(np.array([0.0, 0.0, -15.0]), VELOCITY, rolled)
    assert out[4] == 0.0
    assert out[3] == pytest.approx(5.0, abs=1e-12)  # the two beams that met the bottom


@pytest.mark.parametrize(
    ("changes", "key"), [({"beams": 3.0}, "beams"), ({"beam_angle_rad": 1.6}, "beam_angle_rad")]
)
def test_a_bad_beam_setting_is_refused_naming_it(changes, key):
    with pytest.raises(ParameterError, match=key):
        DvlSpec(**changes)


def test_the_estimator_takes_no_dvl_update_while_the_lock_is_lost():
    """The bottom 20 m below a DVL rated to 15 m: the lock never holds, and the estimate is
    bit for bit the one without a DVL; rated to 30 m it holds and the estimate changes."""
    spec = EstimatorSpec(controller_input="estimate")
    lost = replace(NAVIGATION, dvl=DvlSpec(noise_m_s=0.01, beams=4, max_altitude_m=15.0))
    held = replace(NAVIGATION, dvl=DvlSpec(noise_m_s=0.01, beams=4, max_altitude_m=30.0))
    without = replace(NAVIGATION, dvl=None)
    a, b, c = (run(3, spec, navigation=n, duration_s=4.0) for n in (lost, without, held))
    np.testing.assert_array_equal(a.errors, b.errors)
    np.testing.assert_array_equal(a.covariances, b.covariances)
    assert np.abs(c.errors - b.errors).max() > 1e-6


@pytest.mark.parametrize("normal", [(0.0, 0.0, 1.0), (0.2, -0.1, 1.0)])
def test_a_bottom_of_planes_alone_is_seen_as_the_worlds_plane_is(normal):
    """A `PlaneSeabed` given by its planes alone (no world objects): the beams are cast at
    its planes, the same reading as the world's plane of that pose gives."""
    from uvms_pin.sim.navigation.seabed import PlaneSeabed

    n = np.asarray(normal) / np.linalg.norm(normal)
    alone = PlaneSeabed(((1.0, -2.0, -40.0),), (tuple(n),))
    world = world_seabed([plane("seabed", [1.0, -2.0, -40.0], list(n), 0.5, 0.4)])
    rotation = pin.rpy.rpyToMatrix(0.1, -0.2, 0.7)
    position = np.array([3.0, 1.0, -31.0])
    got = _dvl(alone).measure(position, VELOCITY, rotation)
    assert got[4] == 1.0
    np.testing.assert_allclose(got, _dvl(world).measure(position, VELOCITY, rotation), atol=1e-12)
