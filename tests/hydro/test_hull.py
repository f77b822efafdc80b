"""A hull fitted to a body's volume and centre of buoyancy, and its wetting under a surface:
the wet fraction and how it changes with the body's motion and the surface's."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.hull import Hull, HullPiece, SurfaceAt
from uvms_pin.hydro.submerged import Ellipsoid, Polyhedron, Sphere
from uvms_pin.hydro.submerged_cylinder import Cylinder

RNG = np.random.default_rng(7)


def _random_rotation() -> np.ndarray:
    return pin.exp3(RNG.normal(size=3))


def _hull(volume=0.03, cob=(0.05, -0.02, 0.1)) -> Hull:
    pieces = (
        HullPiece(Polyhedron.box((0.6, 0.4, 0.3)), _random_rotation(), np.array([0.1, 0.0, 0.0])),
        HullPiece(Cylinder(0.08, 0.5), _random_rotation(), np.array([-0.4, 0.1, 0.05])),
        HullPiece(Sphere(0.1), np.eye(3), np.array([0.45, 0.0, 0.1])),
        HullPiece(Ellipsoid((0.2, 0.1, 0.05)), _random_rotation(), np.array([0.0, 0.3, -0.1])),
    )
    return Hull.fitted(pieces, volume, np.array(cob))


def test_a_fitted_hull_gives_the_model_volume_at_the_model_centre_of_buoyancy():
    hull = _hull()
    deep = hull.wet(np.eye(3), np.array([0.0, 0.0, -10.0]), SurfaceAt())
    assert deep.volume_m3 == pytest.approx(0.03, rel=1e-13)
    assert deep.fraction == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(deep.center_of_buoyancy_m, [0.05, -0.02, 0.1], atol=1e-14)
    np.testing.assert_allclose(deep.fraction_gradient, 0.0, atol=1e-15)
    dry = hull.wet(_random_rotation(), np.array([0.0, 0.0, 10.0]), SurfaceAt())
    assert dry.volume_m3 == 0.0 and dry.fraction == 0.0
    # the bounding sphere holds every piece, at any attitude
    for _ in range(20):
        rotation = _random_rotation()
        top = hull.wet(
            rotation,
            np.array([0.0, 0.0, -(rotation @ hull.bound_center_m)[2] - hull.bound_radius_m]),
            SurfaceAt(),
        )
        assert top.fraction == pytest.approx(1.0, abs=1e-12)


def test_an_equivalent_sphere_has_the_volume_at_the_centre_of_buoyancy():
    hull = Hull.equivalent_sphere_of(2e-4, np.array([0.1, 0.2, 0.3]))
    assert hull.equivalent_sphere and hull.volume_scale == pytest.approx(1.0, rel=1e-14)
    assert hull.bound_radius_m == pytest.approx((3 * 2e-4 / (4 * math.pi)) ** (1 / 3))
    half = hull.wet(np.eye(3), np.array([0.0, 0.0, -0.3]), SurfaceAt())  # centre on z = 0
    assert half.fraction == pytest.approx(0.5, abs=1e-14)


def _surface(point_xy, time_s):
    """A sloped, rising plane: eta = 0.02 + 0.1 x - 0.05 y + 0.3 t."""
    x, y = point_xy
    return SurfaceAt(0.02 + 0.1 * x - 0.05 * y + 0.3 * time_s, 0.3, 0.1, -0.05)


def _fraction(hull, rotation, translation, time_s):
    reference = rotation @ hull.bound_center_m + translation
    return hull.wet(rotation, translation, _surface(reference[:2], time_s)).fraction


def test_the_wet_fraction_changes_as_its_gradient_and_rate_say():
    """df/dt = g . nu + f_t for a body moving with twist nu (body frame) under a moving,
    sloped surface, against central differences along the motion."""
    hull = _hull()
    h = 1e-6
    checked = 0
    for _ in range(60):
        rotation = _random_rotation()
        translation = np.array([0.2, -0.1, RNG.uniform(-0.3, 0.3)])
        wetting = hull.wet(
            rotation, translation, _surface((rotation @ hull.bound_center_m + translation)[:2], 0.0)
        )
        if not 0.0 < wetting.fraction < 1.0:
            continue
        nu = RNG.normal(size=6)
        moved = [
            (rotation @ pin.exp3(s * h * nu[3:]), translation + rotation @ (s * h * nu[:3]))
            for s in (1.0, -1.0)
        ]
        rate = (_fraction(hull, *moved[0], h) - _fraction(hull, *moved[1], -h)) / (2 * h)
        assert rate == pytest.approx(
            wetting.fraction_gradient @ nu + wetting.fraction_rate, abs=1e-6
        )
        checked += 1
    assert checked > 20


def test_a_mesh_away_from_its_origin_is_fitted_by_its_own_centroid():
    """A mesh whose volume lies off its frame's origin (as collision meshes do): the fitted
    hull's wet centroid, deep, is the model's centre of buoyancy; the bound holds it."""
    box = Polyhedron.box((0.4, 0.2, 0.1))
    offset = Polyhedron(box.vertices_m + np.array([0.3, -0.1, 0.2]), box.triangles)
    np.testing.assert_allclose(offset.centroid_m, [0.3, -0.1, 0.2], atol=1e-15)
    piece = HullPiece(offset, _random_rotation(), np.array([0.1, 0.0, 0.0]))
    hull = Hull.fitted((piece,), 0.004, np.array([0.4, -0.2, 0.1]))
    deep = hull.wet(np.eye(3), np.array([0.0, 0.0, -5.0]), SurfaceAt())
    np.testing.assert_allclose(deep.center_of_buoyancy_m, [0.4, -0.2, 0.1], atol=1e-14)
    assert deep.volume_m3 == pytest.approx(0.004)
    for _ in range(20):
        rotation = _random_rotation()
        below = -(rotation @ hull.bound_center_m)[2] - hull.bound_radius_m
        assert hull.wet(
            rotation, np.array([0.0, 0.0, below]), SurfaceAt()
        ).fraction == pytest.approx(1.0, abs=1e-12)
        above = -(rotation @ hull.bound_center_m)[2] + hull.bound_radius_m
        assert hull.wet(rotation, np.array([0.0, 0.0, above]), SurfaceAt()).fraction == 0.0


def test_a_piece_and_a_hull_placed_in_another_frame_move_by_that_pose():
    """x' = R x + t: a placed piece's centroid and a placed hull's centroid and bounding centre
    (the fits that follow in the loaders would hide a wrong translation: tested here alone)."""
    rotation, translation = _random_rotation(), np.array([0.3, -0.7, 1.1])
    piece = HullPiece(Ellipsoid((0.2, 0.1, 0.05)), _random_rotation(), np.array([0.1, 0.2, -0.3]))
    moved = piece.placed(rotation, translation)
    np.testing.assert_allclose(
        moved.centroid_m, rotation @ piece.centroid_m + translation, atol=1e-12
    )
    np.testing.assert_allclose(moved.rotation, rotation @ piece.rotation, atol=1e-12)
    hull = _hull()
    placed = hull.placed(rotation, translation)
    np.testing.assert_allclose(
        placed.bound_center_m, rotation @ hull.bound_center_m + translation, atol=1e-12
    )
    for before, after in zip(hull.pieces, placed.pieces, strict=True):
        np.testing.assert_allclose(
            after.centroid_m, rotation @ before.centroid_m + translation, atol=1e-12
        )


@pytest.mark.parametrize(
    "rotation, translation, needle",
    [
        (2.0 * np.eye(3), np.zeros(3), "rotation must be a 3x3 rotation"),
        (np.eye(2), np.zeros(3), "rotation must be a 3x3 rotation"),
        (np.eye(3), [0.0, math.nan, 0.0], "translation must be 3 finite numbers"),
        (np.eye(3), [0.0, 1.0], "translation must be 3 finite numbers"),
    ],
)
def test_a_piece_refuses_what_is_not_a_pose(rotation, translation, needle):
    with pytest.raises(ParameterError, match=needle):
        HullPiece(Sphere(0.1), rotation, translation)
