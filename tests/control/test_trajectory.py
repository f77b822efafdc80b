"""Reference paths: velocities and accelerations are the derivatives of the positions
(central differences), the minimum-jerk boundary conditions hold, closed curves close."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.control.tracking.trajectory import (
    Circle,
    Helix,
    Hold,
    Lemniscate,
    MinimumJerk,
    Waypoints,
    minimum_jerk,
    plane_axes,
)
from uvms_pin.errors import ParameterError

START = np.array([0.3, -0.2, -1.5])
PATHS = {
    "circle": Circle(START, 0.1, 20.0, ramp_s=2.0),
    "circle_tilted": Circle(START, 0.25, 7.0, normal=[1.0, 1.0, 0.5], ramp_s=1.5),
    "helix": Helix(START, 0.1, 10.0, 0.05, normal=[0, 1, 0], ramp_s=3.0),
    "lemniscate": Lemniscate(START, 0.2, 12.0, ramp_s=2.0),
    "min_jerk": MinimumJerk(START, START + np.array([0.2, -0.1, 0.3]), 4.0, start_s=1.0),
    "waypoints": Waypoints(
        START + np.array([[0, 0, 0], [0.1, 0, 0], [0.1, 0.2, -0.1]]), [0.5, 3.0, 6.0]
    ),
}


@pytest.mark.parametrize("name", sorted(PATHS))
def test_derivatives_are_those_of_the_position(name):
    path, h = PATHS[name], 1e-5
    for t in np.linspace(0.013, 15.0, 97):
        p_minus, v_minus, _ = path.at(t - h)
        p_plus, v_plus, _ = path.at(t + h)
        _, v, a = path.at(t)
        np.testing.assert_allclose(v, (p_plus - p_minus) / (2 * h), atol=1e-8)
        np.testing.assert_allclose(a, (v_plus - v_minus) / (2 * h), atol=1e-6)


@pytest.mark.parametrize("name", sorted(PATHS))
def test_starts_at_the_start_point_at_rest_when_ramped(name):
    p, v, a = PATHS[name].at(0.0)
    np.testing.assert_allclose(p, START, atol=1e-15)
    np.testing.assert_allclose(v, 0.0, atol=1e-15)
    np.testing.assert_allclose(a, 0.0, atol=1e-15)


def test_minimum_jerk_boundary_conditions():
    s0, ds0, dds0 = minimum_jerk(0.0)
    s1, ds1, dds1 = minimum_jerk(1.0)
    assert (s0, ds0, dds0) == (0.0, 0.0, 0.0) and (s1, ds1, dds1) == (1.0, 0.0, 0.0)
    # just inside: continuous with the outside values (position, velocity, acceleration)
    for tau, target in ((1e-7, 0.0), (1 - 1e-7, 1.0)):
        s, ds, dds = minimum_jerk(tau)
        assert abs(s - target) < 1e-12 and abs(ds) < 1e-9 and abs(dds) < 1e-4
    assert minimum_jerk(0.5) == pytest.approx((0.5, 1.875, 0.0))  # symmetric, peak speed 15/8
    path = PATHS["min_jerk"]
    np.testing.assert_allclose(path.at(5.0)[0], START + np.array([0.2, -0.1, 0.3]), atol=1e-15)
    np.testing.assert_allclose(path.at(3.0)[0], START + 0.5 * np.array([0.2, -0.1, 0.3]))


def test_waypoints_reached_at_their_times_at_rest():
    path = PATHS["waypoints"]
    for point, time_s in zip(
        START + np.array([[0, 0, 0], [0.1, 0, 0], [0.1, 0.2, -0.1]]), [0.5, 3.0, 6.0], strict=True
    ):
        p, v, a = path.at(time_s)
        np.testing.assert_allclose(p, point, atol=1e-14)
        np.testing.assert_allclose(v, 0.0, atol=1e-14)
        np.testing.assert_allclose(a, 0.0, atol=1e-12)


def test_circle_radius_speed_and_closure():
    circle = Circle(START, 0.1, 20.0, ramp_s=0.0)
    e1, e2 = plane_axes([0, 0, 1])
    np.testing.assert_allclose([e1, e2], [[1, 0, 0], [0, 1, 0]])
    for t in np.linspace(0.1, 40.0, 50):
        p, v, a = circle.at(t)
        assert np.linalg.norm(p - circle.center) == pytest.approx(0.1, abs=1e-14)
        assert np.linalg.norm(v) == pytest.approx(0.1 * 2 * math.pi / 20.0, rel=1e-12)
        assert np.linalg.norm(a) == pytest.approx(0.1 * (2 * math.pi / 20.0) ** 2, rel=1e-12)
        assert abs(p[2] - START[2]) < 1e-15  # stays in the horizontal plane
    np.testing.assert_allclose(circle.at(20.0)[0], circle.at(1e-12)[0], atol=1e-12)
    # ramped: a full turn once the phase has advanced by 2 pi, T_r / 2 later
    ramped = PATHS["circle"]
    np.testing.assert_allclose(ramped.at(21.0)[0], START, atol=1e-12)


def test_helix_rises_one_pitch_per_turn_and_lemniscate_closes():
    helix = Helix(START, 0.1, 10.0, 0.05, ramp_s=0.0)
    np.testing.assert_allclose(helix.at(10.0)[0], START + np.array([0, 0, 0.05]), atol=1e-12)
    eight = Lemniscate(START, 0.2, 12.0)
    np.testing.assert_allclose(eight.at(6.0)[0], START, atol=1e-12)  # crossing point
    np.testing.assert_allclose(eight.at(12.0)[0], START, atol=1e-12)
    assert np.linalg.norm(eight.at(3.0)[0] - START) == pytest.approx(0.2, rel=1e-12)


def test_hold_is_still():
    p, v, a = Hold(START).at(3.0)
    np.testing.assert_allclose(p, START)
    assert not v.any() and not a.any()


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda: Circle(START, -0.1, 20.0), "radius_m"),
        (lambda: Circle(START, 0.1, 0.0), "period_s"),
        (lambda: Circle(START, 0.1, 1.0, normal=[0, 0, 0]), "normal"),
        (lambda: Circle(START, 0.1, 1.0, ramp_s=-1), "ramp_s"),
        (lambda: Waypoints([[0, 0, 0], [1, 0, 0]], [1.0, 1.0]), "increase"),
        (lambda: Waypoints([[0, 0, 0]], [1.0]), "points"),
        (lambda: MinimumJerk(START, [np.nan, 0, 0], 1.0), "goal"),
    ],
)
def test_bad_paths_are_refused(make, match):
    with pytest.raises(ParameterError, match=match):
        make()
