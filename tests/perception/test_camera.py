"""The camera: depth, labels and colour against the geometry and the formation model."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.camera import (
    TILE_PX,
    Camera,
    CameraSpec,
    pixel_rays,
    tiled_rays,
    tiles,
)
from uvms_pin.perception.optics import JERLOV_KD_PER_M
from uvms_pin.perception.scene import Scene
from uvms_pin.physics.world.objects import plane, solid

DEPTH_M = 5.0  # the vehicle's depth below the surface


#: the scene's backend, set for each test by `_both_backends`
BACKEND = "core"


@pytest.fixture(autouse=True, params=["core", "python"])
def _both_backends(request, monkeypatch):
    """Every test on the compiled caster and on the Python reference."""
    monkeypatch.setattr(sys.modules[__name__], "BACKEND", request.param)


def _scene(uvms, objects) -> Scene:
    scene = Scene(uvms, objects, backend=BACKEND)
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -DEPTH_M]
    scene.update(q)
    return scene


def _wall(distance_m: float):
    """A wall facing the vehicle (its normal along -x) ``distance_m`` ahead."""
    return plane("wall", [distance_m, 0.0, -DEPTH_M], [-1.0, 0.0, 0.0], 0.5, 0.4)


def _camera(uvms, objects, **spec) -> Camera:
    spec = {"name": "front", "width": 41, "height": 31, "noise_counts": 0.0, **spec}
    return Camera(CameraSpec(**spec), _scene(uvms, objects), np.random.default_rng(0))


def test_the_depth_of_a_wall_facing_the_camera_is_its_distance(reference_uvms):
    frame = _camera(reference_uvms, [_wall(3.0)]).render()
    wall = frame.label == 1
    assert wall.mean() > 0.5  # the arm hides a corner
    np.testing.assert_allclose(frame.depth_m[wall], 3.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        frame.normal_world[wall], [[-1.0, 0.0, 0.0]] * wall.sum(), atol=1e-12
    )


def test_the_depth_of_a_sphere_and_a_box_ahead(reference_uvms):
    ball = solid("ball", "sphere", {"radius_m": 0.5}, [3.0, 0.0, -DEPTH_M], [0, 0, 0], 0.5, 0.4)
    crate = solid("crate", "box", {"size_m": [1.0, 1.0, 1.0]}, [6.0, 1.5, -DEPTH_M],
                  [0, 0, 0], 0.5, 0.4)  # fmt: skip
    camera = _camera(reference_uvms, [ball, crate], width=101, height=81)
    frame = camera.render()
    names = camera.scene.names
    centre = frame.label[40, 50]
    assert names[centre - 1] == "ball"  # the optical axis passes through its centre
    assert frame.depth_m[40, 50] == pytest.approx(2.5, abs=1e-9)
    # every ball pixel: the sphere's near side, z-depth = range * cos
    rays = camera.rays.reshape(81, 101, 3)
    on_ball = frame.label == centre
    d = rays[on_ball]  # optical frame: z forward
    centre_optical = np.array([0.0, 0.0, 3.0])
    along = d @ centre_optical
    expected = (along - np.sqrt(0.25 - (9.0 - along**2))) * d[:, 2]
    np.testing.assert_allclose(frame.depth_m[on_ball], expected, rtol=0, atol=1e-6)
    # the crate's front face (x = 5.5 m, y in [1, 2] m, 1 m high) to the left
    at_face = rays * (5.5 / rays[..., 2:3])
    front = (np.abs(-at_face[..., 0] - 1.5) < 0.5) & (np.abs(at_face[..., 1]) < 0.5)
    assert front.sum() > 20
    assert np.all(np.array(names)[frame.label[front] - 1] == "crate")
    np.testing.assert_allclose(frame.depth_m[front], 5.5, rtol=0, atol=1e-9)


def test_the_depth_of_a_cylinders_cap_facing_the_camera(reference_uvms):
    """A cylinder (r = 0.4 m, L = 2 m) 5 m ahead, its axis turned onto the optical axis:
    its near cap, a disc of 0.4 m at 4 m, is at z-depth 4 m on every pixel of it; the pixel
    through the centre sees it, one 0.45 m off the axis at that range does not. Of the
    planes, only the one facing up is a floor (the sand's colour)."""
    pipe = solid("pipe", "cylinder", {"radius_m": 0.4, "length_m": 2.0},
                 [5.0, 0.0, -DEPTH_M], [0.0, math.pi / 2, 0.0], 0.5, 0.4)  # fmt: skip
    seabed = plane("seabed", [0.0, 0.0, -DEPTH_M - 3.0], [0.0, 0.0, 1.0], 0.5, 0.4)
    camera = _camera(reference_uvms, [pipe, seabed, _wall(30.0)], width=101, height=81)
    assert camera.scene.floor_names == {"seabed"}
    frame = camera.render()
    names = camera.scene.names
    on_pipe = frame.label == names.index("pipe") + 1
    assert names[frame.label[40, 50] - 1] == "pipe"
    rays = camera.rays.reshape(81, 101, 3)
    at_cap = rays * (4.0 / rays[..., 2:3])  # where each pixel's ray crosses z = 4 m
    off_axis = np.hypot(at_cap[..., 0], at_cap[..., 1])
    assert on_pipe[off_axis < 0.39].all() and on_pipe[off_axis < 0.39].sum() > 30
    np.testing.assert_allclose(frame.depth_m[off_axis < 0.39], 4.0, rtol=0, atol=1e-9)
    assert not on_pipe[off_axis > 0.45].any()


@pytest.mark.parametrize("distance_m", [1.0, 3.0, 8.0])
def test_a_flat_target_has_the_formation_models_colour(reference_uvms, distance_m):
    rho = (0.8, 0.6, 0.4)
    camera = _camera(reference_uvms, [_wall(distance_m)], reflectance={"wall": rho},
                     water_type="II", exposure=1.5)  # fmt: skip
    frame = camera.render()
    kd = np.asarray(JERLOV_KD_PER_M["II"])
    daylight = np.exp(-kd * DEPTH_M)  # E0 = 1 at the surface; at the wall's (and camera's) depth
    veiling = 0.2 * daylight
    # a vertical wall sees half the sky: E = daylight (1 + 0) / 2
    expected = np.asarray(rho) * 0.5 * daylight * np.exp(-kd * distance_m) + veiling * (
        1.0 - np.exp(-kd * distance_m)
    )
    np.testing.assert_allclose(frame.radiance[15, 20], expected, rtol=1e-12)
    np.testing.assert_array_equal(frame.rgb[15, 20], np.rint(255 * 1.5 * expected).astype(np.uint8))


def test_open_water_reads_the_veiling_light_and_lights_brighten_the_target(reference_uvms):
    dark = _camera(reference_uvms, [_wall(2.0)], surface_irradiance=0.0).render()
    assert np.all(dark.rgb == 0)  # night, no lamp
    from uvms_pin.perception.optics import Light

    lamp = Light(intensity=1.5, half_angle_rad=0.3, edge_rad=0.05)
    rho = np.array([0.8, 0.6, 0.4])
    lit = _camera(reference_uvms, [_wall(2.0)], surface_irradiance=0.0, lights=(lamp,),
                  reflectance={"wall": tuple(rho)}).render()  # fmt: skip
    # on the axis, the lamp at the camera: rho I_L / d^2 exp(-beta_D 2 d), nothing scattered
    beta = np.asarray(JERLOV_KD_PER_M["IB"])
    np.testing.assert_allclose(lit.radiance[15, 20], rho * 1.5 / 4.0 * np.exp(-beta * 4.0), 1e-12)
    assert np.all(lit.radiance[0, 0] == 0.0)  # far off the axis: outside the cone


def test_the_same_seed_gives_the_same_images(reference_uvms):
    def image(seed):
        spec = CameraSpec("front", width=41, height=31, noise_counts=3.0)
        camera = Camera(spec, _scene(reference_uvms, [_wall(3.0)]), np.random.default_rng(seed))
        return camera.render().rgb

    np.testing.assert_array_equal(image(4), image(4))
    assert not np.array_equal(image(4), image(5))


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"width": 0}, "width"),
        ({"horizontal_fov_rad": math.pi}, "horizontal_fov_rad"),
        ({"rate_hz": 0.0}, "rate_hz"),
        ({"water_type": "muddy"}, "water_type"),
        ({"position_m": (0.0, math.nan, 0.0)}, "position_m"),
        ({"reflectance": {"wall": (2.0, 0.0, 0.0)}}, "reflectance.wall"),
    ],
)
def test_a_bad_camera_is_refused_naming_the_key(changes, key):
    with pytest.raises(ParameterError, match=key):
        CameraSpec("front", **changes)


@pytest.mark.parametrize(("width", "height"), [(48, 32), (41, 31)])
def test_tiles_go_back_to_image_order(reference_uvms, width, height):
    """By a transposition of blocks when the tiles cover the image, by a gather otherwise:
    the same pixels either way."""
    camera = _camera(reference_uvms, [_wall(3.0)], width=width, height=height)
    tiled = np.arange(width * height * 3, dtype=float).reshape(-1, 3)
    np.testing.assert_array_equal(camera._untile(tiled), tiled[np.argsort(camera.order)])
    np.testing.assert_array_equal(camera._untile(camera._tiled), camera.rays)


@pytest.mark.parametrize(("width", "height"), [(48, 32), (41, 31), (16, 16), (5, 300)])
def test_the_tiles_are_the_pixels_tile_by_tile_and_their_rays_the_same(width, height):
    """`tiles` (no sort) gives the order of a stable sort by tile, each tile's pixels row by
    row, and `tiled_rays` the same values as `pixel_rays` in that order."""
    spec = CameraSpec("c", width=width, height=height, horizontal_fov_rad=1.7)
    order, starts = tiles(spec)
    v, u = np.divmod(np.arange(width * height), width)
    tile = (v // TILE_PX) * -(-width // TILE_PX) + u // TILE_PX
    np.testing.assert_array_equal(order, np.argsort(tile, kind="stable"))
    counts = np.bincount(tile)
    np.testing.assert_array_equal(starts, np.concatenate([[0], np.cumsum(counts)]))
    np.testing.assert_array_equal(tiled_rays(spec, order), pixel_rays(spec)[order])


def test_the_noise_of_a_uniform_target_has_the_given_deviation(reference_uvms):
    """The rgb of a wall lit evenly: the noiseless counts plus N(0, noise_counts^2), rounded
    (the rounding adds 1/12 count^2 of variance)."""
    camera = _camera(reference_uvms, [_wall(2.0)], width=160, height=120, noise_counts=4.0,
                     exposure=2.0)  # fmt: skip
    frame = camera.render()
    clean = np.rint(255.0 * 2.0 * frame.radiance)
    # the channels of the wall's pixels far from the clipping at 0 and 255
    kept = (frame.label == 1)[..., None] & (clean > 20) & (clean < 235)
    assert kept.sum() > 20000
    error = frame.rgb[kept].astype(float) - clean[kept]
    assert abs(error.mean()) < 0.05
    assert error.std() == pytest.approx(np.sqrt(16.0 + 1.0 / 12.0), rel=0.02)


@pytest.mark.parametrize("width, height, fov", [(320, 240, 1.2), (50, 37, 2.0), (7, 64, 0.3)])
def test_pixel_rays_are_unit_and_through_each_pixels_centre(width, height, fov):
    spec = CameraSpec("c", width=width, height=height, horizontal_fov_rad=fov)
    rays = pixel_rays(spec)
    assert rays.shape == (width * height, 3) and rays.flags.c_contiguous
    np.testing.assert_allclose(np.linalg.norm(rays, axis=1), 1.0, atol=1e-15)
    v, u = np.divmod(np.arange(width * height), width)  # row by row
    f = 0.5 * width / np.tan(0.5 * fov)
    np.testing.assert_allclose(rays[:, 0] / rays[:, 2], (u + 0.5 - 0.5 * width) / f, atol=1e-13)
    np.testing.assert_allclose(rays[:, 1] / rays[:, 2], (v + 0.5 - 0.5 * height) / f, atol=1e-13)


@pytest.mark.parametrize(
    "given, match",
    [
        ({"reflectance": [0.1, 0.2, 0.3]}, "reflectance must be a table"),
        ({"reflectance": "red"}, "reflectance must be a table"),
        ({"reflectance": {"box": "red"}}, r"reflectance must map label names to \(R, G, B\)"),
        ({"reflectance": {"box": [0.1, 0.2]}}, r"reflectance\.box needs 3 numbers"),
        ({"lights": {"intensity": 1.0}}, "lights must be tables"),
        ({"lights": [{"intensity": 1.0}, 3]}, "lights must be tables"),
    ],
)
def test_a_cameras_lights_and_reflectance_of_the_wrong_kind_are_named(given, match):
    """A table's ``lights`` (a list of tables) and ``reflectance`` (a table of R, G, B)
    of another kind: a ParameterError naming them, not an AttributeError of a list."""
    with pytest.raises(ParameterError, match=rf"camera 'c': {match}"):
        CameraSpec.from_dict({"name": "c", **given}, "camera 'c'")


def test_a_reflectance_no_label_answers_to_is_named_and_a_link_answers_for_its_pieces():
    """``reflectance`` keys are label names, or a link's name for its pieces (the Alpha 5's
    label ``tool/collision[0]`` answers to ``tool``); a key no label answers to (a typo) is
    a PerceptionWarning naming it and the labels (it was ignored silently)."""
    from pathlib import Path

    import uvms_pin as up
    from uvms_pin.errors import PerceptionWarning

    root = Path(__file__).resolve().parents[2]
    scene = _scene(up.load_uvms(root / "models" / "uvms_bluerov2_alpha5.urdf"), [_wall(3.0)])
    assert "tool/collision[0]" in scene.names
    with pytest.warns(PerceptionWarning, match=r"'wal'.* no label .*its labels: wall"):
        Camera(CameraSpec("c", reflectance={"wal": (1.0, 0.0, 0.0)}), scene, None)
    colours = {"wall": (1.0, 0.0, 0.0), "tool": (0.0, 0.0, 1.0)}
    camera = Camera(CameraSpec("c", reflectance=colours), scene, None)
    rows = {name: tuple(camera.reflectance[k + 1]) for k, name in enumerate(scene.names)}
    assert rows["wall"] == (1.0, 0.0, 0.0) and rows["tool/collision[0]"] == (0.0, 0.0, 1.0)
