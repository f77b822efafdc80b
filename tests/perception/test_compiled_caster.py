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


@pytest.mark.parametrize("seed", range(2))
def test_meshes_are_cast_by_embree_between_the_cores_casts(seed):
    reference, compiled = _random_casters(seed, meshes=2)
    assert len(compiled._external) == 2  # the meshes are not in the core
    rng = np.random.default_rng(300 + seed)
    d = _sphere_rays(rng, 6000)
    origin = rng.uniform(-0.5, 0.5, 3)
    expected = reference.cast(origin, d)
    meshes = [k + 1 for k in compiled._external]
    assert np.isin(expected.label, meshes).sum() > 5  # the meshes are seen
    # Embree's single precision: the rays put in the mesh's frame in the core, rounded to
    # single precision there, may round the other way (a range one float32 step apart)
    _assert_same(expected, compiled.cast(origin, d), tol=1e-6)


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


def _seen(uvms, backend: str) -> Scene:
    """The benchmark's scene (benchmarks/bench_perception.py: a seabed, five solids and the
    rock mesh), the robot above."""
    scene = Scene(uvms, bench_perception.objects(), backend=backend)
    q = uvms.neutral_configuration()
    q[2] = -9.0
    q[7:] += 0.3  # the arm bent into view
    scene.update(q)
    return scene


@pytest.mark.parametrize("width, height", [(96, 64), (50, 37)])  # whole tiles, and not
def test_the_compiled_camera_gives_the_references_images(reference_uvms, width, height):
    lights = (
        Light((0.1, 0.0, 0.0), intensity=2.0),
        Light((-0.1, 0.05, 0.0), (0.2, 0.1, 1.0), 1.5, half_angle_rad=0.3, edge_rad=0.2),
    )
    spec = CameraSpec("front", width=width, height=height, rpy_rad=(-1.9, 0.0, -1.5708),
                      lights=lights, noise_counts=2.0, water_type="3C")  # fmt: skip
    python, core = _seen(reference_uvms, "python"), _seen(reference_uvms, "core")
    assert not python.compiled and core.compiled
    frames = [Camera(spec, s, np.random.default_rng(7)).render() for s in (python, core)]
    expected, got = frames
    names = {python.names[k - 1] for k in np.unique(expected.label) if k > 0}
    assert {"seabed", "ball", "crate", "rock"} <= names  # the scene is in view
    assert sum(n not in {"seabed", "ball", "crate", "pipe", "egg", "rock"} for n in names) > 0
    np.testing.assert_array_equal(got.label, expected.label)
    np.testing.assert_array_equal(np.isnan(got.depth_m), np.isnan(expected.depth_m))
    met = ~np.isnan(expected.depth_m)
    rock = expected.label == python.names.index("rock") + 1
    np.testing.assert_allclose(got.depth_m[met & ~rock], expected.depth_m[met & ~rock],
                               rtol=TOL, atol=TOL)  # fmt: skip
    np.testing.assert_allclose(got.depth_m[rock], expected.depth_m[rock], rtol=0, atol=1e-6)
    np.testing.assert_allclose(got.normal_world, expected.normal_world, rtol=0, atol=TOL)
    np.testing.assert_allclose(got.radiance, expected.radiance, rtol=0, atol=1e-9)
    np.testing.assert_allclose(got.radiance[~rock], expected.radiance[~rock], rtol=0, atol=TOL)
    np.testing.assert_array_equal(got.rgb, expected.rgb)  # the same noise, drawn once


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


def test_a_firing_records_new_arrays_though_the_compiled_pixels_reuse_their_own(reference_uvms):
    """`Camera.fire` computes in the camera's buffers: what it returned before is kept, and
    it equals a new render's (the same noise draws, written into a buffer or not)."""
    spec = CameraSpec("front", width=48, height=32, rpy_rad=(-1.9, 0.0, -1.5708))
    scene = _seen(reference_uvms, "core")
    firing, rendering = (Camera(spec, scene, np.random.default_rng(3)) for _ in range(2))
    first = firing.fire()
    kept = {key: value.copy() for key, value in first.items()}
    q = reference_uvms.neutral_configuration()
    q[:3] = [0.5, 0.2, -9.3]
    scene.update(q)
    second = firing.fire()
    assert not np.array_equal(second["depth_m"], kept["depth_m"])  # it moved
    for key in kept:
        np.testing.assert_array_equal(first[key], kept[key])  # not overwritten
    q0 = reference_uvms.neutral_configuration()
    q0[2], q0[7:] = -9.0, q0[7:] + 0.3
    scene.update(q0)
    frame = rendering.render()  # the first image again, from a fresh camera of the same seed
    np.testing.assert_array_equal(frame.rgb, kept["rgb"])
    np.testing.assert_array_equal(frame.label, kept["label"])
    np.testing.assert_array_equal(frame.depth_m.astype(np.float32), kept["depth_m"])


def test_an_output_of_another_dtype_is_refused_not_written_into_a_copy():
    compiled = caster_for("core")
    compiled.add("ball", Sphere(1.0), np.eye(3), [3.0, 0.0, 0.0])
    d = np.tile([1.0, 0.0, 0.0], (4, 1))
    with pytest.raises(TypeError):  # int64 labels: the core would write a temporary
        compiled._core.cast(
            np.zeros(3), np.eye(3), d, np.empty(4), np.empty((4, 3)), np.empty(4, dtype=np.int64)
        )
