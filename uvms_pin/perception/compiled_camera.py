"""A camera's pixels in the compiled core: what `Camera._pixels` computes, in two core calls.

The rays are cast from the optical frame (`CompiledCaster.cast_from`: the camera's tiles as
cones, its rays rotated in the core, the meshes cast there too), then shaded by
``_core.shade_camera`` (src/uvms_core/camera_shading.cpp): each pixel's z-depth (range times
the ray's optical z), normal, label and the revised underwater image formation model's
radiance (`uvms_pin.perception.optics`: daylight, the camera's lights, backscatter), written
in image order; ``_core.eight_bit`` makes the 8-bit counts. What stays in Python is per
image, not per pixel: the pose, the lights' placement, the veiling light, and the noise,
drawn by the camera's own generator (`Camera.render`): the same draws for both backends.
The pixels agree with the reference's to rounding (tests/perception/test_compiled_caster.py).

A firing (`Camera.fire`) records the depth, labels and colour only: ``_core.record_camera``
shades and makes the 8-bit counts in one pass, looking the noise's codes up itself
(`uvms_pin.perception.image_noise`), and writes them where the run keeps them, with no
normals, radiance or noise array in between: the same values as `Camera.render`'s.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.perception.caster import Bundles, Hits
from uvms_pin.perception.compiled_caster import cones_of
from uvms_pin.perception.image_noise import normal_levels
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

    def _shading(self, position: np.ndarray, rotation: np.ndarray) -> tuple:
        """The shading's arguments from the optical frame at (``rotation``, ``position``):
        the rays cast, what they met, and the water and lights as the camera stands."""
        hits = self.caster.cast_from(position, rotation, self.rays, self.cones, self._hits)
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
        return (
            position, rotation, self.rays, hits.range_m, hits.normal_world, hits.label,
            self.pixel_of, self.reflectance, *self.water, veiling, lights,
        )  # fmt: skip

    def pixels(
        self, position: np.ndarray, rotation: np.ndarray, buffers: tuple | None = None
    ) -> tuple[np.ndarray, ...]:
        """(depth (H W,) [m], normal (H W, 3), label (H W,), radiance (H W, 3)) in image
        order, from the optical frame at (``rotation``, ``position``) in the world; written
        into ``buffers`` (`buffers`), or new arrays."""
        depth, normal, label, radiance = (buffers or self.buffers())[:4]
        self.core.shade_camera(*self._shading(position, rotation), depth, normal, label, radiance)
        return depth, normal, label, radiance

    def record(
        self,
        position: np.ndarray,
        rotation: np.ndarray,
        noise_codes: np.ndarray | None,
        scale: float,
        noise_counts: float,
        out: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> None:
        """What a firing records, from the optical frame at (``rotation``, ``position``),
        written into ``out`` = (depth (H W,) float32 [m], label (H W,) int16, rgb (H W, 3)
        uint8), in image order: `pixels` and `eight_bit` in one core call, the noise
        ``noise_counts`` times `normal_levels`()[``noise_codes``] ((H W, 3) uint16, or None)
        looked up there; the same values, no normals or radiance kept."""
        depth, label, rgb = out
        self.core.record_camera(
            *self._shading(position, rotation), noise_codes, normal_levels(), scale,
            noise_counts, depth, label, rgb,
        )  # fmt: skip

    def eight_bit(self, radiance: np.ndarray, scale: float, noise_counts: float, noise):
        """`uvms_pin.perception.camera.eight_bit` in the core: the same counts."""
        rgb = np.empty(radiance.shape, dtype=np.uint8)
        self.core.eight_bit(radiance, scale, noise_counts, noise, rgb)
        return rgb
