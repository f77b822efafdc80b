"""``[[sensors.camera]]``: a pinhole camera's depth, normals, labels and colour.

Its optical frame (z along the optical axis, x right, y down, as ROS cameras) sits at
``position_m``, ``rpy_rad`` in its ``link`` (default: the vehicle's body). Pixel (u, v) of a
``width`` x ``height`` image looks along (x, y, 1) with x = (u + 1/2 - W/2) / f,
y = (v + 1/2 - H/2) / f, f = (W/2) / tan(fov/2) (square pixels, ``horizontal_fov_rad``).
The depth image is the z-depth of the first surface met (range times the ray's z: ROS
depth images), NaN where the ray meets nothing; the colour is the revised underwater image
formation model (`uvms_pin.perception.optics`), scaled by ``exposure`` to 8 bits, with
seeded Gaussian noise of ``noise_counts`` (8-bit counts, the run's seed; drawn by
`uvms_pin.perception.image_noise`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError, PerceptionWarning
from uvms_pin.perception import sensor
from uvms_pin.perception.caster import Bundles
from uvms_pin.perception.compiled_camera import CompiledPixels
from uvms_pin.perception.image_noise import normal_codes, standard_normal_f32
from uvms_pin.perception.optics import Light, WaterOptics, backscatter, cone_of_cosine
from uvms_pin.perception.scene import Scene

__all__ = ["CAMERA", "Camera", "CameraSpec", "Frame", "eight_bit", "reflectance_of"]

#: the reflectance (R, G, B) of a label's name when the camera's ``reflectance`` does not
#: give it: sand for a plane facing up, a dark grey for the robot, a light grey otherwise
SAND = (0.55, 0.5, 0.35)
ROBOT = (0.25, 0.25, 0.28)
OTHER = (0.7, 0.7, 0.7)

#: the side [px] of the square tiles whose rays the caster leaves out together
TILE_PX = 16

#: the rays shaded together: their (n, 3) temporaries stay in the processor's cache
CHUNK_RAYS = 8192


@dataclass(frozen=True)
class CameraSpec:
    """A camera's table (``[[sensors.camera]]``; the checks in `__post_init__`)."""

    name: str
    width: int = 320
    height: int = 240
    horizontal_fov_rad: float = 1.2
    rate_hz: float = 10.0
    link: str | None = None
    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_rad: tuple[float, float, float] = (-math.pi / 2, 0.0, -math.pi / 2)
    water_type: str = "IB"
    attenuation_per_m: tuple[float, float, float] | None = None
    backscatter_per_m: tuple[float, float, float] | None = None
    surface_irradiance: float = 1.0
    backscatter_albedo: float = 0.2
    exposure: float = 1.0
    noise_counts: float = 1.0
    lights: tuple[Light, ...] = ()
    reflectance: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    in_loop: bool = False

    def __post_init__(self) -> None:
        label = f"camera '{self.name}'"
        sensor.check_mount(self, label)
        sensor.check_counts(self, label, {"width": 8192, "height": 8192})
        sensor.check_fields_of_view(self, label, ("horizontal_fov_rad",))
        for key in ("exposure", "noise_counts"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"{label}: {key} must be finite and >= 0, got {value}")
        try:
            self.optics  # noqa: B018 (its own checks)
        except ParameterError as exc:
            raise ParameterError(f"{label}: {exc}") from exc
        for name, rgb in self.reflectance.items():
            if len(rgb) != 3 or not all(0.0 <= c <= 1.0 for c in rgb):
                raise ParameterError(
                    f"{label}: reflectance.{name} needs 3 numbers in [0, 1], got {rgb}"
                )

    @property
    def optics(self) -> WaterOptics:
        return WaterOptics(
            self.water_type,
            self.attenuation_per_m,
            self.backscatter_per_m,
            self.surface_irradiance,
            self.backscatter_albedo,
        )

    @property
    def focal_px(self) -> float:
        return 0.5 * self.width / math.tan(0.5 * self.horizontal_fov_rad)

    @classmethod
    def from_dict(cls, raw: dict[str, Any], label: str) -> CameraSpec:
        """From a table's keys (``lights``: tables of `Light`'s fields; ``reflectance``: a
        label name -> (R, G, B))."""
        raw = dict(raw)
        lights = raw.pop("lights", [])
        reflectance = raw.pop("reflectance", {})
        tables = isinstance(lights, list) and all(isinstance(light, dict) for light in lights)
        if not tables:
            raise ParameterError(
                f"{label}: lights must be tables (of Light's keys), got {lights!r}"
            )
        if not isinstance(reflectance, dict):
            raise ParameterError(
                f"{label}: reflectance must be a table of label names to (R, G, B), "
                f"got {reflectance!r}"
            )
        built = []
        for k, light in enumerate(lights):
            try:
                built.append(sensor.spec_from_dict(Light, light, f"{label}: lights[{k}]"))
            except ParameterError as exc:  # Light's checks say what is wrong, this which light
                where = f"{label}: lights[{k}]"
                raise ParameterError(str(exc) if where in str(exc) else f"{where}: {exc}") from exc
        try:
            colours = {str(k): tuple(float(c) for c in v) for k, v in reflectance.items()}
        except (TypeError, ValueError) as exc:
            raise ParameterError(
                f"{label}: reflectance must map label names to (R, G, B) numbers, "
                f"got {reflectance!r}"
            ) from exc
        return sensor.spec_from_dict(cls, raw, label, lights=tuple(built), reflectance=colours)


@dataclass(frozen=True)
class Frame:
    """One image: ``depth_m`` (H, W) [m] (NaN: nothing met), ``normal_world`` (H, W, 3),
    ``label`` (H, W) (0: nothing), ``radiance`` (H, W, 3) the model's I_c before the
    exposure, ``rgb`` (H, W, 3) uint8."""

    depth_m: np.ndarray
    normal_world: np.ndarray
    label: np.ndarray
    radiance: np.ndarray
    rgb: np.ndarray


def whole_tiles(spec: CameraSpec) -> bool:
    """Whether the tiles of `TILE_PX` cover the image exactly (no tile cut by its edge)."""
    return spec.width % TILE_PX == 0 and spec.height % TILE_PX == 0


def _pixel_coordinates(spec: CameraSpec) -> tuple[np.ndarray, np.ndarray]:
    """(u (W,), v (H,)): the pixel centres' x / z and y / z in the optical frame."""
    f = spec.focal_px
    u = (np.arange(spec.width) + 0.5 - 0.5 * spec.width) / f
    v = (np.arange(spec.height) + 0.5 - 0.5 * spec.height) / f
    return u, v


def pixel_rays(spec: CameraSpec) -> np.ndarray:
    """The unit rays (H W, 3) of every pixel, row by row, in the optical frame."""
    u, v = _pixel_coordinates(spec)
    return _unit_rays(u[None, :], v[:, None], (spec.height, spec.width))


def _unit_rays(x: np.ndarray, y: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """(x, y, 1) / |(x, y, 1)| (prod(shape), 3) of x and y broadcast to ``shape``."""
    # |(x, y, 1)|, summed in that order, x along a row and y down a column (broadcast, no
    # meshgrid: a camera is made for each run)
    length = np.sqrt(x * x + y * y + 1.0)
    out = np.empty((*shape, 3))
    np.divide(x, length, out=out[..., 0])
    np.divide(y, length, out=out[..., 1])
    np.divide(1.0, length, out=out[..., 2])
    return out.reshape(-1, 3)


def tiled_rays(spec: CameraSpec, order: np.ndarray) -> np.ndarray:
    """`pixel_rays` in tile order (``order``, `tiles`'): the same values, each computed in
    its place when the tiles cover the image exactly (no image-order array), else gathered."""
    if not whole_tiles(spec):
        return pixel_rays(spec)[order]
    u, v = _pixel_coordinates(spec)
    across, down = spec.width // TILE_PX, spec.height // TILE_PX
    # the tiles' blocks (tile row, tile column, row in it, column in it)
    x = u.reshape(across, TILE_PX)[None, :, None, :]
    y = v.reshape(down, TILE_PX)[:, None, :, None]
    return _unit_rays(x, y, (down, across, TILE_PX, TILE_PX))


def tiles(spec: CameraSpec) -> tuple[np.ndarray, np.ndarray]:
    """(the pixels in tile order (H W,), where each tile starts in it (tiles + 1,)): square
    tiles of `TILE_PX`, row by row, their pixels row by row."""
    width, height = spec.width, spec.height
    across, down = -(-width // TILE_PX), -(-height // TILE_PX)
    # the pixels' indices in an image padded to whole tiles (-1: padding), its tiles' blocks
    # made rows: each row a tile's pixels, row by row (no sort: a camera is made for each run)
    grid = np.full((down * TILE_PX, across * TILE_PX), -1, dtype=np.intp)
    grid[:height, :width] = np.arange(width * height).reshape(height, width)
    blocks = grid.reshape(down, TILE_PX, across, TILE_PX).swapaxes(1, 2)
    blocks = blocks.reshape(down * across, TILE_PX * TILE_PX)
    if whole_tiles(spec):
        return blocks.reshape(-1), np.arange(0, width * height + 1, TILE_PX * TILE_PX)
    kept = blocks >= 0
    return blocks[kept], np.concatenate([[0], np.cumsum(np.count_nonzero(kept, axis=1))])


def _keys_of(name: str) -> tuple[str, str]:
    """The names a label answers to in a camera's ``reflectance``: its own (a free object's
    pieces ``rock#2`` answering to ``rock``) and its link's (``tool/collision[0]``: a link's
    piece named after its collision geometry answering to ``tool``)."""
    base = name.split("#")[0]
    return base, base.split("/")[0]


def reflectance_of(names: list[str], given: dict[str, tuple], planes: set[str]) -> np.ndarray:
    """(labels + 1, 3): row k the reflectance of label k (row 0: nothing met)."""
    rows = [(0.0, 0.0, 0.0)]
    for name in names:
        base, link = _keys_of(name)
        rows.append(given.get(base, given.get(link, SAND if base in planes else OTHER)))
    return np.asarray(rows, dtype=float)


def eight_bit(radiance: np.ndarray, scale: float, noise_counts: float, noise) -> np.ndarray:
    """The 8-bit counts of ``scale`` radiance + ``noise_counts`` ``noise`` (standard normal
    draws, float32; None: none), rounded to the nearest (to even on a tie), clipped."""
    counts = scale * radiance
    if noise is not None:
        counts += noise_counts * noise
    return np.clip(np.rint(counts, out=counts), 0, 255, out=counts).astype(np.uint8)


class Camera(sensor.Mounted):
    """A `CameraSpec` looking at a `Scene`, its noise drawn from ``rng``."""

    def __init__(self, spec: CameraSpec, scene: Scene, rng: np.random.Generator):
        super().__init__(spec, scene, f"camera '{spec.name}'")
        self.spec, self.rng = spec, rng
        self.order, starts = tiles(spec)
        self._tiled = tiled_rays(spec, self.order)
        self._bundles = Bundles.of(self._tiled, starts)
        self.optics = spec.optics
        robot = {*scene.robot_names, *scene.other_robot_names}
        answered = {key for name in scene.names for key in _keys_of(name)}
        unknown = sorted(set(spec.reflectance) - answered - set(scene.fixture_names))
        if unknown:  # a typo would leave its colour the default, silently
            warnings.warn(
                f"camera '{spec.name}': reflectance of {', '.join(map(repr, unknown))}, which "
                f"no label of the scene answers to (its labels: {', '.join(scene.names)})",
                PerceptionWarning,
                stacklevel=2,
            )
        given = dict(spec.reflectance)
        for name in robot:  # the robots' colour, unless given by the label or its link
            if not any(key in given for key in _keys_of(name)):
                given[name] = ROBOT
        for label, fixture in scene.fixture_of.items():  # a fixture's colour: all its links'
            if fixture in given:
                given.setdefault(label, given[fixture])
        self.reflectance = reflectance_of(scene.names, given, scene.floor_names)
        #: the same pixels computed in the core, when the scene's caster is compiled
        self._compiled = None
        if scene.compiled:
            self._compiled = CompiledPixels(
                scene.caster, self._tiled, self._bundles, self.order, self.reflectance,
                self.optics, spec.lights,
            )  # fmt: skip

    @cached_property
    def rays(self) -> np.ndarray:
        """Its pixels' unit rays (H W, 3) in image order (`pixel_rays`; made when first
        needed: the caster takes them in tile order)."""
        return pixel_rays(self.spec)

    @cached_property
    def _untiled(self) -> np.ndarray:
        """Tile order -> image order: the inverse of `order` (made when first needed)."""
        untiled = np.empty_like(self.order)
        untiled[self.order] = np.arange(len(self.order))
        return untiled

    def _untile(self, tiled: np.ndarray) -> np.ndarray:
        """An array (H W, ...) in tile order, in image order: a transposition of blocks when
        the tiles cover the image exactly, one gather otherwise."""
        spec = self.spec
        if not whole_tiles(self.spec):
            return tiled[self._untiled]
        rest = tiled.shape[1:]
        blocks = tiled.reshape(
            spec.height // TILE_PX, spec.width // TILE_PX, TILE_PX, TILE_PX, *rest
        )
        return blocks.swapaxes(1, 2).reshape(spec.width * spec.height, *rest)

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(R, p) of the optical frame in the world, after the scene's update."""
        placed = self.placement()
        return placed.rotation, placed.translation

    def render(self) -> Frame:
        """The image of the scene as it stands (new arrays)."""
        spec = self.spec
        rotation, position = self.pose()
        if self._compiled is not None:
            depth, normal, label, radiance = self._compiled.pixels(position, rotation)
        else:
            depth, normal, label, radiance = self._pixels(position, rotation)
        noise = None
        if spec.noise_counts > 0.0:
            noise = standard_normal_f32(self.rng, radiance.shape)
        scale = 255.0 * spec.exposure
        if self._compiled is not None:
            rgb = self._compiled.eight_bit(radiance, scale, spec.noise_counts, noise)
        else:
            rgb = eight_bit(radiance, scale, spec.noise_counts, noise)
        shape = (spec.height, spec.width)
        return Frame(
            depth.reshape(shape),
            normal.reshape(*shape, 3),
            label.reshape(shape),
            radiance.reshape(*shape, 3),
            rgb.reshape(*shape, 3),
        )

    def _pixels(self, position, rotation) -> tuple[np.ndarray, ...]:
        """(depth (H W,) [m], normal (H W, 3), label (H W,), radiance (H W, 3)) in image
        order, from the optical frame at (``rotation``, ``position``): the reference."""
        directions = self._tiled @ rotation.T  # tile by tile: the caster culls whole tiles
        hits = self.scene.caster.cast(position, directions, self._bundles.rotated(rotation))
        radiance = np.empty_like(directions)
        for start in range(0, len(directions), CHUNK_RAYS):
            part = slice(start, start + CHUNK_RAYS)
            radiance[part] = self._radiance(
                position, rotation, directions[part],
                hits.range_m[part], hits.normal_world[part], hits.label[part],
            )  # fmt: skip
        untile = self._untile
        range_m = untile(hits.range_m)
        depth = np.where(np.isfinite(range_m), range_m * self.rays[:, 2], np.nan)
        return depth, untile(hits.normal_world), untile(hits.label), untile(radiance)

    def _radiance(self, position, rotation, directions, r, normal, label) -> np.ndarray:
        """I_c (n, 3) of n rays from ``position`` (`uvms_pin.perception.optics`): what they
        met at ranges ``r`` (inf: nothing), its normals and labels."""
        optics = self.optics
        veiling = optics.veiling_light(-position[2])
        met = np.isfinite(r)
        out = np.broadcast_to(veiling, (len(directions), 3)).copy()
        if not met.all():  # the rays that met something; all of them, most often
            if not met.any():
                return out
            out[met] = self._radiance(position, rotation, directions[met], r[met], normal[met],
                                      label[met])  # fmt: skip
            return out
        rho = self.reflectance[label]
        column = r[:, None]
        # daylight E0 exp(-K_d depth) (1 + n_z) / 2 and the direct path's exp(-beta_D r)
        # in one exponential
        depth = np.maximum(-(position[2] + r * directions[:, 2]), 0.0)[:, None]
        sky = (0.5 * optics.surface_irradiance) * (1.0 + normal[:, 2])
        signal = optics.kd_per_m * depth
        signal += optics.beta_d_per_m * column
        np.negative(signal, out=signal)
        np.exp(signal, out=signal)
        signal *= rho
        signal *= sky[:, None]
        for light in self.spec.lights:
            self._lit(signal, light, position, rotation, directions, normal, rho, r)
        signal += backscatter(veiling, r, optics.beta_b_per_m)
        return signal

    def _lit(self, out, light: Light, position, rotation, directions, normal, rho, r) -> None:
        """Adds to ``out`` (n, 3) a light's direct signal from the points met (their
        normals, reflectances, ranges): rho I_L cone max(0, n . l) / d^2 exp(-beta_D (d + r))
        (on every ray: the cone is exactly 0 beyond its edge, adding nothing, and most rays
        are within it, so picking them out would cost more)."""
        source = position + rotation @ np.asarray(light.position_m)
        axis = rotation @ np.asarray(light.direction)
        to_point = r[:, None] * directions
        to_point += position - source
        distance = np.sqrt(np.einsum("ij,ij->i", to_point, to_point))
        reach = np.maximum(distance, 1e-12)
        power = cone_of_cosine((to_point @ axis) / reach, light.half_angle_rad, light.edge_rad)
        facing = np.einsum("ij,ij->i", normal, to_point)
        facing /= reach
        power *= np.maximum(0.0, -facing)
        power *= light.intensity / np.maximum(distance, 1e-6) ** 2
        path = (distance + r)[:, None] * -self.optics.beta_d_per_m
        np.exp(path, out=path)
        path *= power[:, None]
        path *= rho
        out += path

    def fire(self, out: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
        """What a firing records: ``depth_m`` (H, W) float32, ``rgb`` (H, W, 3) and
        ``label`` (H, W) int16 of `render`'s image (its values, the same noise draws);
        written into ``out`` (those arrays, C-contiguous) when given, else new arrays.

        The compiled camera computes only these (`CompiledPixels.record`): no normals,
        radiance or noise array, nothing copied."""
        spec = self.spec
        shape = (spec.height, spec.width)
        layout = {
            "depth_m": (shape, np.float32),
            "rgb": ((*shape, 3), np.uint8),
            "label": (shape, np.int16),
        }
        if out is None:
            out = {key: np.empty(size, dtype=dtype) for key, (size, dtype) in layout.items()}
        for key, (size, dtype) in layout.items():
            given = out.get(key)
            if not (
                isinstance(given, np.ndarray)
                and given.shape == size
                and given.dtype == dtype
                and given.flags.c_contiguous
            ):
                raise ParameterError(
                    f"camera '{spec.name}': out['{key}'] must be a C-contiguous "
                    f"{np.dtype(dtype).name} array of shape {size}"
                )
        if self._compiled is None:
            frame = self.render()
            for key in layout:
                out[key][...] = getattr(frame, key)
            return out
        rotation, position = self.pose()
        n = spec.width * spec.height
        codes = None
        if spec.noise_counts > 0.0:  # the draws `render` makes, in the same order
            codes = normal_codes(self.rng, 3 * n).reshape(n, 3)
        flat = (out["depth_m"].reshape(n), out["label"].reshape(n), out["rgb"].reshape(n, 3))
        self._compiled.record(
            position, rotation, codes, 255.0 * spec.exposure, spec.noise_counts, flat
        )
        return out


CAMERA = sensor.register(
    sensor.PerceptionKind(
        name="camera",
        spec=CameraSpec,
        make=Camera,
        bytes=lambda spec: spec.width * spec.height * (4 + 3 + 2),  # depth, rgb, label
    )
)
