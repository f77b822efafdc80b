"""The animated wave surface: tiles at the surface elevation, tilted to its slope."""

from __future__ import annotations

import numpy as np
import umsgpack

from uvms_pin.apps.viz.meshcat_scene import recording_visualizer
from uvms_pin.apps.viz.surface import SurfaceView
from uvms_pin.flow import AiryWave, UniformCurrent


def test_tiles_follow_the_elevation_and_slope_of_the_wave():
    wave = AiryWave(0.5, 5.0, heading_rad=0.3)
    view = SurfaceView(wave, np.array([1.0, -2.0]), half_width_m=3.0, tiles_per_side=6)
    assert len(view.names) == 36
    # 6 x 6 tiles of 1 m cover the 6 m square about (1, -2): centres 0.5 m in from its edges
    assert view.cell_m == 1.0
    for axis, centre in enumerate((1.0, -2.0)):
        ticks = np.unique(view.centers_xy_m[:, axis])
        np.testing.assert_allclose(ticks, centre + np.arange(-2.5, 3.0, 1.0), atol=1e-12)
    for t in (0.0, 1.7):
        poses = view.poses(t)
        positions = np.array([poses[n][0] for n in view.names])
        np.testing.assert_allclose(positions[:, :2], view.centers_xy_m)
        np.testing.assert_allclose(positions[:, 2], wave.surface_elevation(t, view.centers_xy_m))
        # the tile's +z axis is the surface normal (-eta_x, -eta_y, 1) / |.|
        k, w = wave.wavenumber_rad_m, 2 * np.pi / 5.0
        e = np.array([np.cos(0.3), np.sin(0.3)])
        theta = k * view.centers_xy_m @ e - w * t
        slope = -0.5 * k * np.sin(theta)[:, None] * e  # grad eta
        expected = np.column_stack([-slope, np.ones(len(slope))])
        expected /= np.linalg.norm(expected, axis=1, keepdims=True)
        for name, normal in zip(view.names, expected, strict=True):
            x, y, z, qw = poses[name][1]
            # rotate +z by the quaternion: third column of its rotation matrix
            z_axis = np.array([2 * (x * z + qw * y), 2 * (y * z - qw * x), 1 - 2 * (x * x + y * y)])
            np.testing.assert_allclose(z_axis, normal, atol=1e-5)


def test_still_water_has_no_surface_to_draw():
    assert not UniformCurrent([0.2, 0, 0]).has_free_surface
    assert (UniformCurrent([0.2, 0, 0]) + AiryWave(0.1, 3.0)).has_free_surface


def test_still_water_tiles_are_placed_once_at_z0_and_not_animated():
    view = SurfaceView(None, np.array([1.0, -2.0]), half_width_m=3.0, tiles_per_side=4)
    assert view.poses(0.0) == {} and view.poses(5.0) == {}
    vis, window = recording_visualizer()
    view.build(vis)
    commands = [umsgpack.unpackb(c) for c in window.commands]
    placed = {c["path"]: c["matrix"] for c in commands if c["type"] == "set_transform"}
    for name, (x, y) in zip(view.names, view.centers_xy_m, strict=True):
        path = next(p for p in placed if p.endswith(name))
        # column-major 4x4: the translation is the last column
        matrix = np.asarray(placed[path], dtype=float).reshape(4, 4).T
        np.testing.assert_allclose(matrix[:3, 3], [x, y, 0.0], atol=1e-6)
        np.testing.assert_allclose(matrix[:3, :3], np.eye(3))
