"""Solids that meet along a face or an edge touch at the vertices of coal's contact patch
(`uvms_pin.physics.world.gaps.patch_candidates`, src/uvms_core/object_contacts.cpp): the
patch's geometry, and what one point left undone: a crate set down on a shelf, a post or
another crate rests there, on both backends (it rocked between the shelf's edges and turned
about its normal under the friction there, tens of degrees in 12 s)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.physics.world.gaps import PATCH_CORNER, patch_candidates
from uvms_pin.physics.world.objects import WorldObject


class _Piece:
    def __init__(self, shape):
        self.shape = shape


def _on(piece_shape, object_shape, position, yaw=0.0, reach=0.01):
    c, s = np.cos(yaw), np.sin(yaw)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    obj = WorldObject("o", "solid", object_shape, pin.SE3.Identity(), 0.0, 0.5, 0.4)
    where = pin.SE3(rotation, np.asarray(position, dtype=float))
    return patch_candidates(3, 5, _Piece(piece_shape), where, obj, reach)


def test_a_box_on_a_box_touches_at_the_corners_of_their_faces_overlap():
    """A 0.3 m square face 0.5 mm above a 0.4 m one, shifted 0.15 m: the overlap is the
    rectangle x in [0, 0.2], |y| <= 0.15, its four corners on the upper box's face, the
    normal up, the gap 0.5 mm."""
    found = _on(coal.Box(0.3, 0.3, 0.2), coal.Box(0.4, 0.4, 0.2), [0.15, 0.0, 0.2005])
    assert len(found) == 4
    points = np.array([c.point_world_m for c in found])
    expected = {(x, y) for x in (0.0, 0.2) for y in (-0.15, 0.15)}
    assert {(round(x, 9), round(y, 9)) for x, y in points[:, :2]} == expected
    np.testing.assert_allclose(points[:, 2], 0.1005, atol=1e-9)  # on the piece's face
    for c in found:
        np.testing.assert_allclose(c.normal_world, [0.0, 0.0, 1.0], atol=1e-9)
        assert c.gap_m == pytest.approx(5e-4, abs=1e-9)
        assert (c.piece, c.obj) == (3, 5)
    assert sorted(c.corner for c in found) == [PATCH_CORNER - k for k in (3, 2, 1, 0)]


def test_a_turned_box_touches_at_the_octagon_of_the_two_squares():
    """The same squares, one turned by 45 degrees about their common axis: an octagon."""
    found = _on(coal.Box(0.3, 0.3, 0.2), coal.Box(0.3, 0.3, 0.2), [0.0, 0.0, 0.2005], np.pi / 4)
    points = np.array([c.point_world_m for c in found])
    assert len(found) == 8
    np.testing.assert_allclose(np.abs(points[:, :2]).max(axis=1), 0.15, atol=1e-9)


@pytest.mark.parametrize("piece_is_the_box", [True, False])
def test_a_box_and_a_cylinders_disc_touch_at_the_square_whichever_is_the_piece(
    piece_is_the_box,
):
    """A 0.3 m square on a 0.3 m-radius disc (the square within it): its four corners,
    whichever body is the piece (coal 3.0 gives one point in one of the two orders, which
    left a crate on a post turning at 0.3 rad/s)."""
    box, post = coal.Box(0.3, 0.3, 0.2), coal.Cylinder(0.3, 0.2)
    pair = (box, post) if piece_is_the_box else (post, box)
    position = [0.0, 0.0, 0.2005] if piece_is_the_box else [0.0, 0.0, -0.2005]
    found = _on(*pair, position)
    assert len(found) == 4
    points = np.array([c.point_world_m for c in found])
    np.testing.assert_allclose(np.abs(points[:, :2]), 0.15, atol=1e-9)
    face = 0.1005 if piece_is_the_box else -0.1005  # the piece's own face
    np.testing.assert_allclose(points[:, 2], face, atol=1e-9)
    up_or_down = 1.0 if piece_is_the_box else -1.0  # out of the object towards the piece
    for c in found:
        np.testing.assert_allclose(c.normal_world, [0.0, 0.0, up_or_down], atol=1e-9)


def test_a_curved_piece_and_a_pair_beyond_the_reach_keep_coals_one_point():
    """A sphere on a box touches at one point; a box 5 cm above a box, beyond a 1 cm reach,
    is coal's nearest point (the caller drops it)."""
    ball = _on(coal.Sphere(0.1), coal.Box(1.0, 1.0, 0.2), [0.01, 0.0, 0.2005])
    assert len(ball) == 1 and ball[0].corner == -1
    far = _on(coal.Box(0.3, 0.3, 0.2), coal.Box(0.3, 0.3, 0.2), [0.0, 0.0, 0.25])
    assert len(far) == 1 and far[0].gap_m == pytest.approx(0.05)


def _crate_on(support: dict, backend: str, moving: str | None = None):
    """(the run of a crate set down on ``support``, the water's density [kg/m^3])."""
    crate = {
        "type": "box", "name": "crate", "size_m": [0.3, 0.3, 0.2], "density_kg_m3": 1500.0,
        "position_world_m": [2.05, 0.02, -4.7],
    }  # fmt: skip
    world = {"objects": [support, crate]}
    if moving is not None:
        world["objects"].insert(0, {"type": "plane", "name": "seabed", "point_world_m": [0, 0, -5]})
        world["moving_contact"] = moving
    doc = {
        "scenario": {"model": "bluerov2_heavy", "duration_s": 3.0},
        "initial": {"position_world_m": [0.0, 0.0, -3.0]},
        "water": {"free_surface": False},
        "integrator": {"backend": backend},
        "control": {"period_s": 0.01},
        "output": {"log_period_s": 0.01},
        "world": world,
    }
    scenario = up.scenario_from_dict(doc, path="crate.toml")
    return up.simulate(scenario, progress=False), scenario.uvms.water_density_kg_m3


SUPPORTS = {
    "shelf": {"type": "box", "name": "shelf", "size_m": [0.3, 0.3, 0.2],
              "position_world_m": [2.0, 0.0, -4.9]},
    "post": {"type": "cylinder", "name": "post", "radius_m": 0.3, "length_m": 0.2,
             "position_world_m": [2.0, 0.0, -4.9]},
}  # fmt: skip


def _still(rollout: up.Rollout, name: str) -> None:
    frame = rollout.to_dataframe()
    omega = frame[[f"free_objects.{name}_{c}_rad_s" for c in "pqr"]].to_numpy()
    position = frame[[f"free_objects.{name}_{c}_m" for c in "xyz"]].to_numpy()
    quaternion = frame[[f"free_objects.{name}_q{c}" for c in "xyzw"]].to_numpy()
    assert rollout.status.kind == "ok"
    assert np.abs(omega).max() < 1e-6, np.abs(omega).max(axis=0)
    assert np.abs(position - position[0]).max() < 1e-5
    np.testing.assert_allclose(np.abs(quaternion[-1]), [0.0, 0.0, 0.0, 1.0], atol=1e-6)


@pytest.mark.parametrize("backend", ["core", "python"])
@pytest.mark.parametrize("support", sorted(SUPPORTS))
def test_a_crate_set_down_off_centre_on_a_fixed_solid_rests_there(support, backend):
    """Its footprint 5 cm off the shelf's (overhanging on one side) or within the post's
    disc: still to 1e-6 rad/s over 3 s, the contact the crate's weight in water at its
    footprint's centre of pressure under its centre."""
    rollout, water = _crate_on(SUPPORTS[support], backend)
    _still(rollout, "crate")
    frame = rollout.to_dataframe()
    pair = f"free_object_contact.crate|{support}"
    force = frame[[f"{pair}.f{c}_N" for c in "xyz"]].to_numpy()[-1]
    weight = 0.3 * 0.3 * 0.2 * (1500.0 - water) * 9.81
    np.testing.assert_allclose(force, [0.0, 0.0, weight], rtol=1e-3, atol=1e-6)
    centre = frame[[f"{pair}.{c}_m" for c in "xy"]].to_numpy()[-1]
    np.testing.assert_allclose(centre, [2.05, 0.02], atol=1e-6)


@pytest.mark.parametrize("backend", ["core", "python"])
def test_a_crate_on_a_free_crate_on_rigid_moving_contacts_rests(backend):
    """Two crates stacked on the seabed, the pair between them a rigid moving contact: the
    upper one rests (it rocked and turned, ~40 degrees in 12 s)."""
    lower = {"type": "box", "name": "lower", "size_m": [0.3, 0.3, 0.2],
             "position_world_m": [2.0, 0.0, -4.9], "density_kg_m3": 1500.0}  # fmt: skip
    rollout, _ = _crate_on(lower, backend, moving="rigid")
    _still(rollout, "crate")
    _still(rollout, "lower")
