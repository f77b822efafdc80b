"""The ray caster against the analytic geometry: planes, spheres, boxes, cylinders,
ellipsoids and meshes, posed and moved."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import trimesh
from trimesh.ray.ray_triangle import RayMeshIntersector

from uvms_pin.errors import ParameterError
from uvms_pin.perception.caster import RayCaster
from uvms_pin.perception.mesh import TriangleMesh
from uvms_pin.perception.shapes import Cylinder, Ellipsoid, Plane, Sphere, box

RNG = np.random.default_rng(3)


def _rays(n: int, spread: float = 0.4) -> np.ndarray:
    d = np.column_stack([np.ones(n), spread * RNG.uniform(-1, 1, (n, 2))])
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def test_a_plane_is_met_at_its_analytic_range():
    caster = RayCaster()
    rotation = pin.rpy.rpyToMatrix(0.0, -np.pi / 2, 0.0)  # its normal along -x: a wall
    caster.add("wall", Plane(), rotation, [4.0, 0.0, 0.0])
    d = _rays(2000)
    hits = caster.cast(np.zeros(3), d)
    np.testing.assert_allclose(hits.range_m, 4.0 / d[:, 0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(hits.normal_world, np.tile([-1.0, 0, 0], (2000, 1)), atol=1e-12)
    assert np.all(hits.label == 1)
    # from behind it: nothing
    assert np.all(np.isinf(caster.cast(np.array([5.0, 0, 0]), -d).range_m))


def test_a_sphere_is_met_at_its_analytic_range():
    caster = RayCaster()
    centre, radius = np.array([5.0, 0.3, -0.2]), 0.8
    caster.add("ball", Sphere(radius), np.eye(3), centre)
    d = _rays(4000, 0.3)
    hits = caster.cast(np.zeros(3), d)
    along = d @ centre
    miss2 = centre @ centre - along**2  # squared distance of the centre from each ray
    met = miss2 < radius**2
    assert 0.1 < met.mean() < 0.9
    expected = along[met] - np.sqrt(radius**2 - miss2[met])
    np.testing.assert_allclose(hits.range_m[met], expected, rtol=0, atol=1e-6)
    assert np.all(np.isinf(hits.range_m[~met])) and np.all(hits.label[~met] == 0)
    points = d[met] * hits.range_m[met, None]
    np.testing.assert_allclose(hits.normal_world[met], (points - centre) / radius, atol=1e-9)


@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (0.3, -0.2, 0.7)])
def test_a_box_is_met_where_its_triangles_are(rpy):
    half = np.array([0.5, 0.8, 0.3])
    rotation, position = pin.rpy.rpyToMatrix(*rpy), np.array([3.0, 0.2, 0.1])
    caster = RayCaster()
    caster.add("crate", box(half), rotation, position)
    mesh = trimesh.creation.box(extents=2 * half)
    mesh.apply_transform(pin.SE3(rotation, position).homogeneous)
    d = _rays(3000, 0.5)
    hits = caster.cast(np.zeros(3), d)
    reference = RayMeshIntersector(mesh)  # trimesh's own, double precision
    locations, rows, _ = reference.intersects_location(np.zeros((3000, 3)), d, multiple_hits=False)
    expected = np.full(3000, np.inf)
    expected[rows] = np.linalg.norm(locations, axis=1)
    assert np.isfinite(expected).mean() > 0.1
    np.testing.assert_array_equal(np.isfinite(hits.range_m), np.isfinite(expected))
    met = np.isfinite(expected)
    np.testing.assert_allclose(hits.range_m[met], expected[met], rtol=0, atol=1e-6)


def test_a_face_on_box_is_at_its_distance_everywhere_on_the_face():
    caster = RayCaster()
    caster.add("crate", box([0.5, 1.0, 1.0]), np.eye(3), [4.5, 0.0, 0.0])
    d = _rays(2000, 0.2)
    hits = caster.cast(np.zeros(3), d)
    on_face = np.all(np.abs(d[:, 1:] * (4.0 / d[:, :1])) < 1.0, axis=1)
    np.testing.assert_allclose(hits.range_m[on_face] * d[on_face, 0], 4.0, atol=1e-12)


def test_cylinders_and_ellipsoids_meet_their_surfaces():
    caster = RayCaster()
    caster.add("pipe", Cylinder(0.4, 2.0), pin.rpy.rpyToMatrix(0.2, 1.2, 0.0), [4.0, 0.0, 0.0])
    caster.add("egg", Ellipsoid((0.3, 0.5, 0.7)), pin.rpy.rpyToMatrix(0, 0.3, 0.2), [3, 1.5, 0])
    d = _rays(4000, 0.6)
    hits = caster.cast(np.zeros(3), d)
    met = np.isfinite(hits.range_m)
    assert set(np.unique(hits.label[met])) == {1, 2}
    points = d[met] * hits.range_m[met, None]
    pipe = hits.label[met] == 1
    local = (points[pipe] - [4.0, 0, 0]) @ pin.rpy.rpyToMatrix(0.2, 1.2, 0.0)
    on_side = np.abs(np.hypot(local[:, 0], local[:, 1]) - 0.4) < 1e-9
    on_caps = np.abs(np.abs(local[:, 2]) - 1.0) < 1e-9
    assert np.all(on_side | on_caps) and on_side.any() and on_caps.any()
    egg = (points[~pipe] - [3, 1.5, 0]) @ pin.rpy.rpyToMatrix(0, 0.3, 0.2)
    np.testing.assert_allclose(np.sum((egg / [0.3, 0.5, 0.7]) ** 2, axis=1), 1.0, atol=1e-9)


def test_the_nearest_body_wins_and_a_moved_body_moves_its_hits():
    caster = RayCaster()
    caster.add("far", Sphere(1.0), np.eye(3), [8.0, 0, 0])
    near = caster.add("near", Sphere(0.5), np.eye(3), [4.0, 0, 0])
    axis = np.array([[1.0, 0.0, 0.0]])
    assert caster.cast(np.zeros(3), axis).range_m[0] == pytest.approx(3.5, abs=1e-12)
    assert caster.cast(np.zeros(3), axis).label[0] == near + 1
    caster.set_pose(near, np.eye(3), np.array([10.0, 0, 0]))  # behind the far one now
    hits = caster.cast(np.zeros(3), axis)
    assert hits.range_m[0] == pytest.approx(7.0, abs=1e-12) and hits.label[0] == 1


@pytest.mark.parametrize("where", ["rotation", "position"])
def test_a_pose_that_is_not_finite_is_refused_as_the_core_refuses_it(where):
    """A diverged state's NaN pose: the reference caster refuses it in the core's words
    (it cast images of NaN depth, label 0 and black colour, silently)."""
    caster = RayCaster()
    ball = caster.add("ball", Sphere(1.0), np.eye(3), [3.0, 0.0, 0.0])
    rotation, position = np.eye(3), np.array([3.0, 0.0, 0.0])
    (rotation if where == "rotation" else position)[0, ...] = np.nan
    with pytest.raises(ParameterError, match="a body's pose must be finite"):
        caster.set_pose(ball, rotation, position)
    axis = np.array([[1.0, 0.0, 0.0]])
    assert caster.cast(np.zeros(3), axis).range_m[0] == pytest.approx(2.0)  # kept its pose


def test_from_inside_a_solid_nothing_of_it_is_seen():
    caster = RayCaster()
    caster.add("housing", box([0.3, 0.3, 0.3]), np.eye(3), np.zeros(3))
    caster.add("ball", Sphere(0.2), np.eye(3), [2.0, 0, 0])
    hits = caster.cast(np.zeros(3), np.array([[1.0, 0, 0], [-1.0, 0, 0]]))
    assert hits.range_m[0] == pytest.approx(1.8) and hits.label[0] == 2
    assert np.isinf(hits.range_m[1])


def test_embree_meshes_agree_with_trimesh_in_single_precision():
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.7)
    caster = RayCaster()
    rotation = pin.rpy.rpyToMatrix(0.1, 0.2, 0.3)
    caster.add("rock", TriangleMesh(mesh.vertices, mesh.faces), rotation, [3.0, 0.2, 0])
    d = _rays(3000, 0.4)
    hits = caster.cast(np.zeros(3), d)
    placed = mesh.copy()
    placed.apply_transform(pin.SE3(rotation, np.array([3.0, 0.2, 0])).homogeneous)
    locations, rows, _ = RayMeshIntersector(placed).intersects_location(
        np.zeros((3000, 3)), d, multiple_hits=False
    )
    assert len(rows) > 300
    expected = np.linalg.norm(locations, axis=1)
    np.testing.assert_allclose(hits.range_m[rows], expected, rtol=0, atol=2e-5)
    assert np.isfinite(hits.range_m).sum() == pytest.approx(len(rows), abs=3)


@pytest.mark.parametrize("shape", ["box", "cylinder", "sphere"])
def test_rays_from_many_origins_meet_a_solid_each_from_its_own(shape):
    """Parallel rays along +x from origins spread in y (one origin a ray, not one for all):
    a box's face, a cylinder's side (its axis along z) and a sphere at their analytic
    ranges, the ray passing beside it meeting nothing."""
    solid = {"box": box([1.0, 1.0, 1.0]), "cylinder": Cylinder(1.0, 2.0), "sphere": Sphere(1.0)}
    y = np.array([0.0, 0.5, -0.8, 2.0])
    origins = np.column_stack([np.full(4, -5.0), y, np.zeros(4)])
    directions = np.tile([1.0, 0.0, 0.0], (4, 1))
    t, _normal = solid[shape].hit(origins, directions)
    front = np.full(3, -1.0) if shape == "box" else -np.sqrt(1.0 - y[:3] ** 2)
    np.testing.assert_allclose(t[:3], front + 5.0, rtol=0, atol=1e-12)
    assert t[3] == np.inf
