"""The compiled caster and camera against the Python reference: the same hits (range, normal,
label) on random scenes of every analytic shape to 1e-12, the meshes through Embree in both,
the same camera images; the backend chosen once, where the scene is built."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.camera import Camera, CameraSpec, pixel_rays, tiles
from uvms_pin.perception.caster import Bundles, RayCaster
from uvms_pin.perception.compiled_caster import CompiledCaster, caster_for, cones_of
from uvms_pin.perception.mesh import TriangleMesh
from uvms_pin.perception.optics import Light
from uvms_pin.perception.scene import Scene
from uvms_pin.perception.shapes import (
    Cylinder,
    Ellipsoid,
    Plane,
    Sphere,
    box,
    convex_of_points,
)

ROCK = Path(__file__).resolve().parents[2] / "scenarios" / "meshes" / "rock.obj"
sys.path.insert(0, str(ROCK.parents[2] / "benchmarks"))
import bench_perception  # noqa: E402  (its scene is the one benchmarked)

TOL = 1e-12


def _random_shape(rng: np.random.Generator, kind: str):
    if kind == "sphere":
        return Sphere(rng.uniform(0.2, 1.0))
    if kind == "ellipsoid":
        return Ellipsoid(tuple(rng.uniform(0.1, 0.9, 3)))
    if kind == "box":
        return box(rng.uniform(0.1, 0.8, 3))
    if kind == "hull":
        return convex_of_points(rng.normal(scale=0.5, size=(12, 3)))
    if kind == "cylinder":
        return Cylinder(rng.uniform(0.1, 0.6), rng.uniform(0.2, 2.0))
    return Plane()


def _random_casters(seed: int, meshes: int = 0) -> tuple[RayCaster, CompiledCaster]:
    """The same random scene in both casters: every shape at random poses around the origin
    (a third unrotated, so that rays along the axes meet faces edge-on), planes behind and
    before it."""
    rng = np.random.default_rng(seed)
    reference, compiled = RayCaster(), caster_for("core")
    kinds = ["sphere", "ellipsoid", "box", "hull", "cylinder"] * 3 + ["plane"] * 2
    bodies = [(k, _random_shape(rng, k)) for k in kinds]
    if meshes:
        import trimesh

        rock = trimesh.load(ROCK, force="mesh")
        bodies += [("mesh", TriangleMesh(rock.vertices, rock.faces)) for _ in range(meshes)]
    order = rng.permutation(len(bodies))
    for n, j in enumerate(order):
        kind, shape = bodies[j]
        rotation = pin.rpy.rpyToMatrix(*rng.uniform(-math.pi, math.pi, 3))
        if n % 3 == 0:
            rotation = np.eye(3)
        position = rng.uniform(-4.0, 4.0, 3)
        if kind == "plane":  # its normal toward the origin's side, 3 to 6 m away
            normal = rotation[:, 2]
            position = -rng.uniform(3.0, 6.0) * normal
        for caster in (reference, compiled):
            caster.add(f"{kind}{n}", shape, rotation, position)
    return reference, compiled


def _sphere_rays(rng: np.random.Generator, n: int) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    axes = np.vstack([np.eye(3), -np.eye(3)])  # exactly along the axes too
    d = np.vstack([d, axes])
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _assert_same(expected, got, tol: float = TOL) -> None:
    """The same labels; ranges to ``tol`` relative (a plane met at a grazing angle beyond
    1 km, t = -h / (d . n) with d . n near 0, to 1e-9: its rounding grows as t / h);
    normals to 100 ``tol`` (a small sphere's normal, the hit point over its radius, is
    rounded as the point is, over the radius)."""
    np.testing.assert_array_equal(got.label, expected.label)
    met = np.isfinite(expected.range_m)
    np.testing.assert_array_equal(np.isfinite(got.range_m), met)
    near = met & (expected.range_m < 1e3)
    np.testing.assert_allclose(got.range_m[near], expected.range_m[near], rtol=tol, atol=tol)
    far = met & ~near
    np.testing.assert_allclose(got.range_m[far], expected.range_m[far], rtol=1e-9)
    np.testing.assert_allclose(got.normal_world, expected.normal_world, rtol=0, atol=100 * tol)


@pytest.mark.parametrize("seed", range(6))
def test_the_compiled_caster_meets_what_the_reference_meets(seed):
    reference, compiled = _random_casters(seed)
    rng = np.random.default_rng(100 + seed)
    d = _sphere_rays(rng, 4000)
    origin = rng.uniform(-0.5, 0.5, 3)
    expected = reference.cast(origin, d)
    assert 0.5 < np.mean(expected.label > 0) < 1.0  # many hits and some misses
    assert len(set(expected.label.tolist())) > 10  # most bodies seen
    _assert_same(expected, compiled.cast(origin, d))
    # moved: every body at a new pose, set in both
    for k in range(len(reference.names)):
        rotation = pin.rpy.rpyToMatrix(*rng.uniform(-1.0, 1.0, 3)) @ reference._rotations[k]
        position = reference._positions[k] + rng.uniform(-0.3, 0.3, 3)
        for caster in (reference, compiled):
            caster.set_pose(k, rotation, position)
    _assert_same(reference.cast(origin, d), compiled.cast(origin, d))


@pytest.mark.parametrize("seed", range(3))
def test_cones_leave_out_the_same_bodies_in_both(seed):
    """A camera's rays in tiles: the reference's bundles, the core's cones of the optical
    frame rotated in the core (`cast_from`), and both agree with casting every ray."""
    reference, compiled = _random_casters(seed)
    rng = np.random.default_rng(200 + seed)
    spec = CameraSpec("c", width=96, height=64, horizontal_fov_rad=rng.uniform(0.6, 2.5))
    order, starts = tiles(spec)
    rays = pixel_rays(spec)[order]
    bundles = Bundles.of(rays, starts)
    rotation = pin.rpy.rpyToMatrix(*rng.uniform(-math.pi, math.pi, 3))
    origin = rng.uniform(-0.5, 0.5, 3)
    d = rays @ rotation.T
    expected = reference.cast(origin, d, bundles.rotated(rotation))
    assert np.mean(expected.label > 0) > 0.3
    _assert_same(reference.cast(origin, d), expected)  # the cones lose nothing
    _assert_same(expected, compiled.cast(origin, d, bundles.rotated(rotation)))
    _assert_same(expected, compiled.cast_from(origin, rotation, rays, cones_of(bundles)))


@pytest.mark.parametrize("seed", range(4))
def test_a_camera_beside_a_box_leaves_out_only_cones_that_cannot_enter_it(seed):
    """A camera just outside a face of a vehicle-sized box (inside its bounding sphere, so
    no cone is left out by the sphere), and of a hull: the core leaves out the cones that
    move away from a face the camera is outside of; the others still meet the box and the
    hull where every ray cast alone meets them."""
    rng = np.random.default_rng(300 + seed)
    hull = convex_of_points(rng.normal(scale=0.15, size=(16, 3)))
    reference, compiled = RayCaster(), caster_for("core")
    lean = pin.rpy.rpyToMatrix(*rng.uniform(-0.3, 0.3, 3))
    for caster in (reference, compiled):
        caster.add("hull_box", box([0.45, 0.3, 0.2]), lean, [0.0, 0.0, 0.0])
        caster.add("arm", hull, np.eye(3), lean @ [0.9, 0.0, 0.45])
        caster.add("seabed", Plane(), np.eye(3), [0.0, 0.0, -2.0])
    spec = CameraSpec("c", width=96, height=64, horizontal_fov_rad=rng.uniform(1.0, 2.0))
    order, starts = tiles(spec)
    rays = pixel_rays(spec)[order]
    bundles = Bundles.of(rays, starts)
    origin = lean @ [rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2), 0.2 + rng.uniform(0.001, 0.02)]
    met = set()
    for yaw in np.linspace(-math.pi, math.pi, 7):
        for pitch in (-1.2, -0.5, 0.0, 0.6):  # from looking down at the box to up past it
            rotation = (
                lean
                @ pin.rpy.rpyToMatrix(0.0, pitch, yaw)
                @ pin.rpy.rpyToMatrix(-math.pi / 2, 0.0, -math.pi / 2)
            )  # the optical frame: z ahead
            expected = reference.cast(origin, rays @ rotation.T)  # every ray alone
            got = compiled.cast_from(origin, rotation, rays, cones_of(bundles))
            _assert_same(expected, got)
            met |= set(np.unique(expected.label).tolist())
    assert {1, 2, 3} <= met  # the box, the hull and the seabed were all seen


def test_a_solid_holding_the_origin_and_a_plane_behind_it_are_not_seen_by_either():
    reference, compiled = RayCaster(), caster_for("core")
    for caster in (reference, compiled):
        caster.add("housing", Sphere(0.5), np.eye(3), [0.1, 0.0, 0.0])  # holds the origin
        caster.add("port", box([0.2, 0.2, 0.2]), np.eye(3), [0.0, 0.1, 0.0])  # holds it too
        caster.add("floor", Plane(), np.eye(3), [0.0, 0.0, 1.0])  # the origin below it
        caster.add("wall", Cylinder(0.3, 1.0), np.eye(3), [2.0, 0.0, 0.0])
    d = _sphere_rays(np.random.default_rng(0), 2000)
    expected = reference.cast(np.zeros(3), d)
    assert set(np.unique(expected.label)) == {0, 4}  # the cylinder only
    _assert_same(expected, compiled.cast(np.zeros(3), d))


def _meshes(caster: RayCaster) -> list[int]:
    """The labels of ``caster``'s triangle meshes."""
    return [k + 1 for k, shape in enumerate(caster._shapes) if isinstance(shape, TriangleMesh)]


@pytest.mark.parametrize("seed", range(2))
def test_meshes_are_cast_in_the_core_as_embree_casts_them(seed):
    """The core's triangles (double precision, rays without cones grouped in its own) against
    Embree's (single precision, the reference): ranges to 1e-6."""
    reference, compiled = _random_casters(seed, meshes=2)
    assert compiled._external == []  # the meshes are in the core
    rng = np.random.default_rng(300 + seed)
    d = _sphere_rays(rng, 6000)
    origin = rng.uniform(-0.5, 0.5, 3)
    expected = reference.cast(origin, d)
    assert np.isin(expected.label, _meshes(reference)).sum() > 5  # the meshes are seen
    _assert_same(expected, compiled.cast(origin, d), tol=1e-6)


@pytest.mark.parametrize("seed", range(3))
def test_a_cameras_cones_see_the_meshes_as_embree_does(seed):
    """A camera's tiles on the rock: each cone's rays try only the triangles it may meet,
    and meet what Embree meets (ranges to 1e-6), what the core meets without the cones."""
    reference, compiled = RayCaster(), caster_for("core")
    rock = TriangleMesh(*_rock_triangles())
    rng = np.random.default_rng(400 + seed)
    for caster in (reference, compiled):
        caster.add("seabed", Plane(), np.eye(3), [0.0, 0.0, -1.0])
        caster.add("rock", rock, pin.rpy.rpyToMatrix(0.0, 0.0, 0.4), [1.2, 0.1, -0.8])
    spec = CameraSpec("c", width=96, height=64, horizontal_fov_rad=rng.uniform(0.6, 1.0))
    order, starts = tiles(spec)
    rays = pixel_rays(spec)[order]
    bundles = Bundles.of(rays, starts)
    # looking at the rock (near its centre) from about 1 m, above it
    target = np.array([1.2, 0.1, -0.7]) + rng.uniform(-0.1, 0.1, 3)
    origin = target + rng.uniform(0.7, 1.1) * np.array([-0.8, rng.uniform(-0.3, 0.3), 0.6])
    z = (target - origin) / np.linalg.norm(target - origin)  # the optical axis
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)  # right; y = z x x down
    rotation = np.column_stack([x, np.cross(z, x), z])
    expected = reference.cast(origin, rays @ rotation.T, bundles.rotated(rotation))
    assert np.mean(expected.label == 2) > 0.2  # the rock fills much of the view
    got = compiled.cast_from(origin, rotation, rays, cones_of(bundles))
    _assert_same(expected, got, tol=1e-6)
    _assert_same(got, compiled.cast(origin, rays @ rotation.T))  # no cones: the same hits


def _rock_triangles() -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    rock = trimesh.load(ROCK, force="mesh")
    return np.asarray(rock.vertices), np.asarray(rock.faces)


def _cube_mesh(half_m: float) -> TriangleMesh:
    """A cube of half-side ``half_m`` about its origin in 12 triangles, outward."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    faces = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            on = np.flatnonzero(corners[:, axis] == sign)
            # the face's four corners around its normal, counterclockwise seen from outside
            centre = corners[on].mean(axis=0)
            u, v = np.eye(3)[(axis + 1) % 3], np.eye(3)[(axis + 2) % 3]
            angle = np.arctan2((corners[on] - centre) @ v, (corners[on] - centre) @ u)
            ring = on[np.argsort(sign * angle)]
            faces += [[ring[0], ring[1], ring[2]], [ring[0], ring[2], ring[3]]]
    return TriangleMesh(half_m * corners, np.array(faces))


def test_a_mesh_cube_is_met_where_the_box_is_and_not_from_inside():
    """The core's triangles in double precision: a cube's mesh meets the rays where the
    analytic box does (1e-12); from inside the cube, or behind a lone triangle, nothing."""
    cube = _cube_mesh(0.5)
    assert np.all(np.einsum("ij,ij->i", cube.normals, cube.vertices_m[cube.triangles].mean(1)) > 0)
    rotation, position = pin.rpy.rpyToMatrix(0.3, -0.2, 0.7), np.array([2.0, 0.5, -0.3])
    meshed, boxed = caster_for("core"), caster_for("core")
    meshed.add("cube", cube, rotation, position)
    boxed.add("cube", box([0.5, 0.5, 0.5]), rotation, position)
    d = _sphere_rays(np.random.default_rng(11), 20000)
    expected = boxed.cast(np.zeros(3), d)
    assert np.sum(expected.label == 1) > 300
    _assert_same(expected, meshed.cast(np.zeros(3), d))
    assert np.all(meshed.cast(position + 0.1, d).label == 0)  # from inside: its backs
    lone = caster_for("core")
    lone.add("sheet", TriangleMesh(cube.vertices_m, cube.triangles[:1]), rotation, position)
    centroid, normal = cube.vertices_m[cube.triangles[0]].mean(axis=0), cube.normals[0]
    front = lone.cast(position + rotation @ (centroid + normal), d)
    assert np.sum(front.label == 1) > 0  # seen from its front
    np.testing.assert_allclose(front.normal_world[front.label == 1], np.tile(
        rotation @ normal, (np.sum(front.label == 1), 1)), atol=1e-12)  # fmt: skip
    assert np.all(lone.cast(position + rotation @ (centroid - normal), d).label == 0)


class _Ball:
    """A shape the core does not know (not a `Sphere`): cast by its own ``hit``."""

    def __init__(self, radius_m: float):
        self._sphere = Sphere(radius_m)
        self.bound_radius_m = radius_m

    def hit(self, o, d):
        return self._sphere.hit(o, d)


def test_a_shape_the_core_does_not_know_is_cast_by_its_own_hit():
    reference, compiled = _random_casters(4)
    for caster in (reference, compiled):
        caster.add("own", _Ball(0.7), np.eye(3), [1.5, 0.5, 0.0])
    assert compiled._external == [len(compiled.names) - 1]
    rng = np.random.default_rng(9)
    d = _sphere_rays(rng, 4000)
    expected = reference.cast(np.zeros(3), d)
    assert np.sum(expected.label == len(reference.names)) > 50  # it is seen
    _assert_same(expected, compiled.cast(np.zeros(3), d))


def test_many_origins_are_cast_by_the_reference():
    reference, compiled = _random_casters(0)
    rng = np.random.default_rng(5)
    d = _sphere_rays(rng, 500)
    origins = rng.uniform(-0.5, 0.5, (len(d), 3))
    _assert_same(reference.cast(origins, d), compiled.cast(origins, d))


def _seen(uvms, backend: str, surface: bool = True) -> Scene:
    """The benchmark's scene (benchmarks/bench_perception.py: a seabed, five solids and the
    rock mesh), the robot above; the free surface over it or not (``surface``)."""
    scene = Scene(uvms, bench_perception.objects(), surface=surface, backend=backend)
    q = uvms.neutral_configuration()
    q[2] = -9.0
    q[7:] += 0.3  # the arm bent into view
    scene.update(q)
    return scene


@pytest.mark.parametrize(
    "width, height, pitch_rad",
    [(96, 64, -1.9), (50, 37, -1.9), (64, 48, -1.45)],  # whole tiles, and not; above the
)  # horizon too, no surface there (its upper rows meet nothing: the veiling light)
def test_the_compiled_camera_gives_the_references_images(reference_uvms, width, height, pitch_rad):
    lights = (
        Light((0.1, 0.0, 0.0), intensity=2.0),
        Light((-0.1, 0.05, 0.0), (0.2, 0.1, 1.0), 1.5, half_angle_rad=0.3, edge_rad=0.2),
    )
    spec = CameraSpec("front", width=width, height=height, rpy_rad=(pitch_rad, 0.0, -1.5708),
                      lights=lights, noise_counts=2.0, water_type="3C")  # fmt: skip
    surface = pitch_rad < -1.5708
    python = _seen(reference_uvms, "python", surface)
    core = _seen(reference_uvms, "core", surface)
    assert not python.compiled and core.compiled
    frames = [Camera(spec, s, np.random.default_rng(7)).render() for s in (python, core)]
    expected, got = frames
    if not surface:
        missed = np.isnan(expected.depth_m)
        assert 0.1 < np.mean(missed) < 0.9  # both, in one image
    names = {python.names[k - 1] for k in np.unique(expected.label) if k > 0}
    assert {"seabed", "ball", "crate", "rock"} <= names  # the scene is in view
    robot = sum(n not in {"seabed", "ball", "crate", "pipe", "egg", "rock"} for n in names)
    assert robot > 0 or not surface  # the arm too, looking down
    np.testing.assert_array_equal(got.label, expected.label)
    np.testing.assert_array_equal(np.isnan(got.depth_m), np.isnan(expected.depth_m))
    met = ~np.isnan(expected.depth_m)
    rock = expected.label == python.names.index("rock") + 1
    np.testing.assert_allclose(got.depth_m[met & ~rock], expected.depth_m[met & ~rock],
                               rtol=TOL, atol=TOL)  # fmt: skip
    # the rock: Embree's single precision in the reference, the core's triangles in double
    np.testing.assert_allclose(got.depth_m[rock], expected.depth_m[rock], rtol=2e-6)
    np.testing.assert_allclose(got.normal_world, expected.normal_world, rtol=0, atol=TOL)
    np.testing.assert_allclose(got.radiance[rock], expected.radiance[rock], rtol=2e-6)
    np.testing.assert_allclose(got.radiance[~rock], expected.radiance[~rock], rtol=0, atol=TOL)
    np.testing.assert_array_equal(got.rgb[~rock], expected.rgb[~rock])  # the same noise
    differ = got.rgb[rock].astype(int) - expected.rgb[rock]
    assert np.all(np.abs(differ) <= 1) and np.mean(differ != 0) < 0.01  # a rounding at most


def test_the_backend_is_chosen_once_where_the_scene_is_built(reference_uvms):
    assert isinstance(caster_for("core"), CompiledCaster)
    reference = caster_for("python")
    assert type(reference) is RayCaster
    with pytest.raises(ParameterError, match="backend"):
        caster_for("gpu")
    with pytest.raises(ParameterError, match="backend"):
        Scene(reference_uvms, backend="gpu")


def test_the_core_refuses_bad_input_by_name():
    compiled = caster_for("core")
    compiled.add("ball", Sphere(1.0), np.eye(3), [3.0, 0.0, 0.0])
    core = compiled._core
    d = np.tile([1.0, 0.0, 0.0], (4, 1))
    out = (np.empty(4), np.empty((4, 3)), np.empty(4, dtype=np.int32))
    with pytest.raises(ParameterError, match="range_m"):
        core.cast(np.zeros(3), np.eye(3), d, np.empty(3), *out[1:])
    with pytest.raises(ParameterError, match="cones"):
        core.cast(np.zeros(3), np.eye(3), d, *out, np.array([[1.0, 0, 0]]), np.array([0.1]))
    with pytest.raises(ParameterError, match="starts"):
        core.cast(np.zeros(3), np.eye(3), d, *out, np.array([[1.0, 0, 0]]), np.array([0.1]),
                  np.array([0, 3], dtype=np.int64))  # fmt: skip
    with pytest.raises(ParameterError, match="no body 5"):
        compiled.set_pose(5, np.eye(3), np.zeros(3))
    with pytest.raises(ParameterError, match="finite"):
        core.set_pose(0, np.eye(3), np.array([np.nan, 0.0, 0.0]))
    with pytest.raises(ParameterError, match="radius"):
        core.add_sphere(-1.0, np.eye(3), np.zeros(3))
    core.cast(np.zeros(3), np.eye(3), d, *out)  # and what is right is cast
    np.testing.assert_allclose(out[0], 2.0, atol=TOL)


@pytest.mark.parametrize("backend", ["core", "python"])
def test_a_firing_records_renders_image_into_new_or_given_arrays(reference_uvms, backend):
    """`Camera.fire` gives what `render` gives (the same noise draws, in the same order): new
    arrays, or the given ones written into (the run's stack of images), never kept."""
    lights = (Light((0.1, 0.0, 0.0), intensity=2.0),)
    spec = CameraSpec("front", width=48, height=32, rpy_rad=(-1.9, 0.0, -1.5708),
                      lights=lights, noise_counts=3.0, water_type="5C")  # fmt: skip
    scene = _seen(reference_uvms, backend)
    firing, rendering = (Camera(spec, scene, np.random.default_rng(3)) for _ in range(2))
    first = firing.fire()
    kept = {key: value.copy() for key, value in first.items()}
    assert {k: (v.dtype, v.shape) for k, v in first.items()} == {
        "depth_m": (np.float32, (32, 48)), "rgb": (np.uint8, (32, 48, 3)),
        "label": (np.int16, (32, 48)),
    }  # fmt: skip
    stack = {key: np.zeros((2, *value.shape), value.dtype) for key, value in first.items()}
    q = reference_uvms.neutral_configuration()
    q[:3] = [0.5, 0.2, -9.3]
    scene.update(q)
    given = {key: values[1] for key, values in stack.items()}
    assert firing.fire(given) is given
    assert not np.array_equal(stack["depth_m"][1], kept["depth_m"])  # it moved
    assert not stack["rgb"][0].any()  # the other image of the stack untouched
    for key in kept:
        np.testing.assert_array_equal(first[key], kept[key])  # not overwritten
    q0 = reference_uvms.neutral_configuration()
    q0[2], q0[7:] = -9.0, q0[7:] + 0.3
    scene.update(q0)
    frame = rendering.render()  # the first image again, from a fresh camera of the same seed
    assert np.all(np.isnan(frame.depth_m) == np.isnan(kept["depth_m"]))
    np.testing.assert_array_equal(frame.rgb, kept["rgb"])
    np.testing.assert_array_equal(frame.label, kept["label"])
    np.testing.assert_array_equal(frame.depth_m.astype(np.float32), kept["depth_m"])
    scene.update(q)
    second = rendering.render()
    np.testing.assert_array_equal(second.rgb, stack["rgb"][1])
    np.testing.assert_array_equal(second.depth_m.astype(np.float32), stack["depth_m"][1])
    wrong = dict(given, label=np.zeros((32, 48), np.int32))
    with pytest.raises(ParameterError, match="label"):
        firing.fire(wrong)
    with pytest.raises(ParameterError, match="rgb"):
        firing.fire(dict(given, rgb=np.zeros((48, 32, 3), np.uint8).transpose(1, 0, 2)))


def test_the_core_refuses_a_bad_record_by_name():
    scene_rays = pixel_rays(CameraSpec("c", width=16, height=16))
    compiled = caster_for("core")
    compiled.add("ball", Sphere(1.0), np.eye(3), [0.0, 0.0, 3.0])
    n = len(scene_rays)
    hits = compiled.cast(np.zeros(3), scene_rays)
    water = (np.full(3, 0.1), np.full(3, 0.1), np.full(3, 0.1), 1.0, np.full(3, 0.2))
    args = (np.zeros(3), np.eye(3), scene_rays, hits.range_m, hits.normal_world, hits.label,
            np.arange(n), np.full((2, 3), 0.5), *water, np.zeros((0, 9)))  # fmt: skip
    levels = np.zeros(65536, np.float32)
    out = (np.empty(n, np.float32), np.empty(n, np.int16), np.empty((n, 3), np.uint8))
    core = compiled.core
    core.record_camera(*args, None, levels, 255.0, 0.0, *out)
    assert np.all(out[1] == hits.label) and np.all(out[2] > 0)
    with pytest.raises(ParameterError, match="noise_codes"):
        core.record_camera(*args, np.zeros((n, 2), np.uint16), levels, 255.0, 1.0, *out)
    with pytest.raises(ParameterError, match="noise_levels"):
        core.record_camera(*args, None, levels[:10], 255.0, 1.0, *out)
    with pytest.raises(ParameterError, match="rgb"):
        core.record_camera(*args, None, levels, 255.0, 1.0, *out[:2], out[2][:5])
    with pytest.raises(ParameterError, match="mesh"):
        core.RayCaster().add_mesh(np.eye(3), np.array([[0, 1, 3]]), 1.0, np.eye(3), np.zeros(3))


def test_an_output_of_another_dtype_is_refused_not_written_into_a_copy():
    compiled = caster_for("core")
    compiled.add("ball", Sphere(1.0), np.eye(3), [3.0, 0.0, 0.0])
    d = np.tile([1.0, 0.0, 0.0], (4, 1))
    with pytest.raises(TypeError):  # int64 labels: the core would write a temporary
        compiled._core.cast(
            np.zeros(3), np.eye(3), d, np.empty(4), np.empty((4, 3)), np.empty(4, dtype=np.int64)
        )


def _depth(kind: str, size: np.ndarray, point: np.ndarray) -> float:
    """How far inside the solid of ``size`` the ``point`` (its frame) is, by the solid's
    own equations: < 1 inside, > 1 outside (a sphere's radius, an ellipsoid's semi-axes, a
    box's half-extents, a cylinder's radius and half-length)."""
    if kind in ("sphere", "ellipsoid"):
        return float(np.linalg.norm(point / size))
    if kind == "box":
        return float(np.max(np.abs(point) / size))
    return max(math.hypot(point[0], point[1]) / size[0], abs(point[2]) / size[2])


def _solid(kind: str, rng: np.random.Generator):
    """(shape, a point inside it (its rays are cast toward it), a membership test of its
    frame's points: < 1 inside, > 1 outside, and half its extents about that point)."""
    if kind == "hull":  # by scipy's Delaunay of its points, grown and shrunk 1 %
        from scipy.spatial import Delaunay

        points = rng.normal(scale=0.5, size=(12, 3))
        centre = points.mean(axis=0)
        grown, shrunk = (Delaunay(centre + f * (points - centre)) for f in (1.01, 0.99))

        def depth(p: np.ndarray) -> float:
            return 0.0 if shrunk.find_simplex(p) >= 0 else 2.0 if grown.find_simplex(p) < 0 else 1.0

        return convex_of_points(points), centre, depth, np.ptp(points, axis=0) / 2
    size = {
        "sphere": lambda: np.full(3, rng.uniform(0.2, 1.0)),
        "ellipsoid": lambda: rng.uniform(0.1, 0.9, 3),
        "box": lambda: rng.uniform(0.1, 0.8, 3),
        "cylinder": lambda: np.array([*[rng.uniform(0.1, 0.6)] * 2, rng.uniform(0.1, 1.0)]),
    }[kind]()
    shape = {
        "sphere": lambda: Sphere(size[0]),
        "ellipsoid": lambda: Ellipsoid(tuple(size)),
        "box": lambda: box(size),
        "cylinder": lambda: Cylinder(size[0], 2.0 * size[2]),
    }[kind]()
    return shape, np.zeros(3), lambda p: _depth(kind, size, p), size


@pytest.mark.parametrize("kind", ["sphere", "ellipsoid", "box", "cylinder", "hull"])
def test_a_solid_is_seen_from_every_point_outside_it_and_from_none_inside(kind):
    """From points all about a solid at a random pose (its end caps, corners and sides
    included), a ray toward its centre meets it exactly when the point is outside it, in
    both casters; the points within 1 % of its surface are left out (either side holds)."""
    rng = np.random.default_rng(11)
    shape, centre, depth, extent = _solid(kind, rng)
    rotation = pin.rpy.rpyToMatrix(*rng.uniform(-math.pi, math.pi, 3))
    position = rng.uniform(-1.0, 1.0, 3)
    reference, compiled = RayCaster(), caster_for("core")
    for caster in (reference, compiled):
        caster.add(kind, shape, rotation, position)
    sides = {True: 0, False: 0}
    for local in centre + rng.uniform(-1.4, 1.4, (600, 3)) * extent:
        inside = depth(local)
        if abs(inside - 1.0) < 0.01:
            continue
        outside = inside > 1.0
        sides[outside] += 1
        origin = position + rotation @ local
        toward = rotation @ (centre - local)
        toward /= np.linalg.norm(toward)
        for caster in (reference, compiled):
            seen = caster.cast(origin, toward[None, :]).label[0] == 1
            assert seen == outside, f"{type(caster).__name__} from {local} (its frame)"
    assert min(sides.values()) > 40  # both sides sampled


def test_the_core_names_each_ray_toward_a_body_it_does_not_know_once():
    """The rays that may meet an external body (``rays_toward``, rays without cones): every
    ray whose direction is within the body's bounding sphere as seen from the origin, each
    named once, in order, their count at most the rays'."""
    compiled = caster_for("core")
    centre, radius = np.array([1.5, 0.5, 0.0]), 0.7
    compiled.add("own", _Ball(radius), np.eye(3), centre)
    d = _sphere_rays(np.random.default_rng(9), 4000)
    rows = np.full(len(d), -1, dtype=np.int64)
    count = compiled._core.rays_toward(0, np.zeros(3), np.eye(3), d, np.full(len(d), np.inf), rows)
    picked = rows[:count]
    np.testing.assert_array_equal(picked, np.unique(picked))
    off_axis = np.arccos(np.clip(d @ centre / np.linalg.norm(centre), -1.0, 1.0))
    within = np.arcsin(radius / np.linalg.norm(centre))
    assert set(np.flatnonzero(off_axis < within - 1e-9)) <= set(picked.tolist())
    assert np.all(off_axis[picked] < within + 1e-9) and 50 < count < len(d)
