"""A camera's pixels in the compiled core: what `Camera._pixels` computes, in two core calls.

The rays are cast from the optical frame (`CompiledCaster.cast_from`: the camera's tiles as
cones, its rays rotated in the core, a mesh's rays by Embree in between), then shaded by
``_core.shade_camera`` (src/uvms_core/camera_shading.cpp): each pixel's z-depth (range times
the ray's optical z), normal, label and the revised underwater image formation model's
radiance (`uvms_pin.perception.optics`: daylight, the camera's lights, backscatter), written
in image order; ``_core.eight_bit`` makes the 8-bit counts. What stays in Python is per
image, not per pixel: the pose, the lights' placement, the veiling light, and the noise,
drawn by the camera's own generator (`Camera.render`): the same draws for both backends. The pixels agree with the reference's to
rounding (tests/perception/test_compiled_caster.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.perception.caster import Bundles, Hits
from uvms_pin.perception.compiled_caster import cones_of
from uvms_pin.perception.optics import Light, WaterOptics

__all__ = ["CompiledPixels"]


class CompiledPixels:
    """A camera's pixels computed in the core by ``caster`` (a `CompiledCaster`).

    Args:
        rays: the camera's unit rays (n, 3) in its optical frame, in the caster's (tile) order.
        bundles: their cones (`Bundles`, optical frame). pixel_of: each ray's pixel (n,).
        reflectance: (labels + 1, 3), row k label k's. optics: the water (`WaterOptics`).
        lights: the camera's `Light`s.
    """

    def __init__(
        self,
        caster: Any,
        rays: np.ndarray,
        bundles: Bundles,
        pixel_of: np.ndarray,
        reflectance: np.ndarray,
        optics: WaterOptics,
        lights: tuple[Light, ...],
    ):
        self.caster, self.core = caster, caster.core
        self.rays = np.ascontiguousarray(rays, dtype=float)
        self.cones = cones_of(bundles)
        self.pixel_of = np.ascontiguousarray(pixel_of, dtype=np.int64)
        self.reflectance = np.ascontiguousarray(reflectance, dtype=float)
        self.optics, self.lights = optics, lights
        n = len(self.rays)  # what the rays met, overwritten by each image
        self._hits = Hits(np.empty(n), np.empty((n, 3)), np.empty(n, dtype=np.int32))
        self.water = (
            np.asarray(optics.kd_per_m, dtype=float),
            np.asarray(optics.beta_d_per_m, dtype=float),
            np.asarray(optics.beta_b_per_m, dtype=float),
            float(optics.surface_irradiance),
        )

    def buffers(self) -> tuple[np.ndarray, ...]:
        """Arrays for `pixels` to write into (depth, normal, label, radiance) and for the
        noise (H W, 3) float32."""
        n = len(self.rays)
        return (
            np.empty(n),
            np.empty((n, 3)),
            np.empty(n, dtype=np.int32),
            np.empty((n, 3)),
            np.empty((n, 3), dtype=np.float32),
        )

    def pixels(
        self, position: np.ndarray, rotation: np.ndarray, buffers: tuple | None = None
    ) -> tuple[np.ndarray, ...]:
        """(depth (H W,) [m], normal (H W, 3), label (H W,), radiance (H W, 3)) in image
        order, from the optical frame at (``rotation``, ``position``) in the world; written
        into ``buffers`` (`buffers`), or new arrays."""
        hits = self.caster.cast_from(position, rotation, self.rays, self.cones, self._hits)
        depth, normal, label, radiance = (buffers or self.buffers())[:4]
        lights = np.array(
            [
                [
                    *(position + rotation @ np.asarray(light.position_m)),
                    *(rotation @ np.asarray(light.direction)),
                    light.intensity,
                    light.half_angle_rad,
                    light.edge_rad,
                ]
                for light in self.lights
            ],
            dtype=float,
        ).reshape(-1, 9)
        veiling = self.optics.veiling_light(-position[2])
        self.core.shade_camera(
            position, rotation, self.rays, hits.range_m, hits.normal_world, hits.label,
            self.pixel_of, self.reflectance, *self.water, veiling, lights,
            depth, normal, label, radiance,
        )  # fmt: skip
        return depth, normal, label, radiance

    def eight_bit(self, radiance: np.ndarray, scale: float, noise_counts: float, noise):
        """`uvms_pin.perception.camera.eight_bit` in the core: the same counts."""
        rgb = np.empty(radiance.shape, dtype=np.uint8)
        self.core.eight_bit(radiance, scale, noise_counts, noise, rgb)
        return rgb
