"""The free surface drawn in meshcat: translucent tiles that follow eta(t, x, y) (level at
z = 0 in still water).

Meshcat animates transforms, not vertices, so the surface is a grid of thin tiles, each
placed at the elevation of its centre and tilted to the local slope (normal
(-d eta/dx, -d eta/dy, 1)). A 12 x 12 grid of 0.5 m tiles reads well for waves tens of
metres long and keeps a 10 s replay small.
"""

from __future__ import annotations

import meshcat
import meshcat.geometry as mg
import numpy as np

from uvms_pin.flow import FlowField

_SLOPE_STEP_M = 0.05
_SURFACE_BLUE = 0x9AD4F5
_Z = np.array([0.0, 0.0, 1.0])


def _quaternion_z_to(normals: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w) (n, 4) turning +z onto unit normals (n, 3) (never -z here)."""
    axis = np.cross(np.broadcast_to(_Z, normals.shape), normals)
    w = 1.0 + normals[:, 2]
    quat = np.column_stack([axis, w])
    return quat / np.linalg.norm(quat, axis=1, keepdims=True)


def surface_view_of(
    flow: FlowField | None, free_surface: bool, center_xy_m: np.ndarray
) -> SurfaceView | None:
    """The surface a scene shows: the waves of a flow that has them, the level water line
    z = 0 of a run with a free surface in still water, else None."""
    if flow is not None and flow.has_free_surface:
        return SurfaceView(flow, center_xy_m)
    return SurfaceView(None, center_xy_m) if free_surface else None


class SurfaceView:
    """Tiles over a square of ``half_width_m`` around ``center_xy_m`` showing the free surface
    of ``flow`` (a field with ``has_free_surface``; None: the level surface z = 0)."""

    def __init__(
        self,
        flow: FlowField | None,
        center_xy_m: np.ndarray,
        half_width_m: float = 3.0,
        tiles_per_side: int = 12,
    ):
        self.flow = flow
        cell = 2.0 * half_width_m / tiles_per_side
        ticks = (np.arange(tiles_per_side) + 0.5) * cell - half_width_m
        gx, gy = np.meshgrid(ticks, ticks, indexing="ij")
        self.centers_xy_m = np.column_stack([gx.ravel(), gy.ravel()]) + np.asarray(center_xy_m)[:2]
        self.cell_m = cell
        self.names = [f"surface/tile{k:03d}" for k in range(len(self.centers_xy_m))]

    @property
    def still(self) -> bool:
        """Level water (no waves): the tiles are placed once and never animated (animating
        144 motionless tiles made a still-water replay four times larger)."""
        return self.flow is None

    def build(self, root: meshcat.Visualizer) -> None:
        material = mg.MeshPhongMaterial(color=_SURFACE_BLUE, transparent=True, opacity=0.45)
        for name, (x, y) in zip(self.names, self.centers_xy_m, strict=True):
            root[name].set_object(mg.Box([self.cell_m, self.cell_m, 0.004]), material)
            if self.still:
                at_z0 = np.eye(4)
                at_z0[:2, 3] = (x, y)
                root[name].set_transform(at_z0)

    def elevation_and_normal(self, time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """eta (n,) [m] at the tile centres and the unit surface normals (n, 3)."""
        xy, h = self.centers_xy_m, _SLOPE_STEP_M
        if self.flow is None:
            return np.zeros(len(xy)), np.tile(_Z, (len(xy), 1))
        eta = self.flow.surface_elevation(time_s, xy)
        dx = (
            self.flow.surface_elevation(time_s, xy + np.array([h, 0.0]))
            - self.flow.surface_elevation(time_s, xy - np.array([h, 0.0]))
        ) / (2 * h)
        dy = (
            self.flow.surface_elevation(time_s, xy + np.array([0.0, h]))
            - self.flow.surface_elevation(time_s, xy - np.array([0.0, h]))
        ) / (2 * h)
        normal = np.column_stack([-dx, -dy, np.ones_like(dx)])
        return eta, normal / np.linalg.norm(normal, axis=1, keepdims=True)

    def poses(self, time_s: float) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """The tiles' poses at ``time_s``; none in still water (placed once by `build`)."""
        if self.still:
            return {}
        eta, normal = self.elevation_and_normal(time_s)
        quats = _quaternion_z_to(normal)
        one = np.ones(3)
        return {
            name: (np.array([x, y, z]), q, one)
            for name, (x, y), z, q in zip(self.names, self.centers_xy_m, eta, quats, strict=True)
        }
