"""``[[sensors.sonar]]``: a forward-looking imaging sonar, a multibeam profiler and a
single-beam altimeter.

The sonar's frame sits at ``position_m``, ``rpy_rad`` in its ``link`` (default: the vehicle's
body), x along its acoustic axis, y to port, z up. An ``imaging`` sonar has ``beams`` beams at
bearings spread evenly over ``horizontal_fov_rad`` (about z, positive to port); each beam is
sampled by ``rays_per_beam`` rays over its ``vertical_fov_rad`` fan. An ``altimeter`` has one
beam, a cone of ``horizontal_fov_rad`` sampled by the rays of a ``rays_per_beam`` x
``rays_per_beam`` grid of bearings and elevations that lie within it (about pi / 4 of
them). A ray that meets a surface at range r with incidence theta (to its normal) returns,
into the range bin of r,

    mu cos^2(theta) w(e) 10^(-2 alpha r / 10) / r^2

Lambert's law of bottom backscatter (mu cos^2 theta: R. J. Urick, Principles of Underwater
Sound, 3rd ed. 1983, ch. 8), the elevation beam pattern w(e) = exp(-(e / (fov_v / 2))^2 ln 2)
(half power at the fan's edge), two-way absorption alpha [dB/m] and spherical spreading.
Across beams the returns are blurred by the array's pattern, sinc^2 of the beam spacing in
beamwidths (taps at +-1, +-2 beams), and each cell's intensity is multiplied by an
exponential draw (fully developed speckle: the intensity of a Rayleigh amplitude; J. W.
Goodman, Speckle Phenomena in Optics, 2007), seeded by the run's seed when ``speckle``.

A ``multibeam`` profiler has the imaging sonar's fan (mounted looking down, its fan across
the track) and detects the bottom in each beam: its range is the echo-weighted mean of its
rays' ranges, sum_i e_i r_i / sum_i e_i (the centre of gravity of the beam's echo, amplitude
detection: X. Lurton, An Introduction to Underwater Acoustics, 2nd ed. 2010, ch. 8), plus
Gaussian noise of ``range_noise_m``; its intensity the sum of its echoes (speckled as a
cell). A beam that hears nothing within its ranges reads NaN. An ``altimeter`` detects the
bottom in its one beam by the echo's first arrival, the distance an echosounder reports: the
nearest range at which its rays hear a surface (the leading edge of the echo), plus the same
noise; its intensity the sum of its echoes. Over a flat bottom at altitude h it reads h (to
its rays' spacing about the axis), where the centre of gravity of its 25 degree cone's echo
would read 1.3 % more.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.perception import sensor
from uvms_pin.perception.scene import Scene

__all__ = ["SONAR", "Sonar", "SonarSpec"]

TYPES = ("imaging", "multibeam", "altimeter")
#: the types that detect the bottom in each beam (``beam_range_m``, ``beam_intensity``)
DETECTING = ("multibeam", "altimeter")

#: The keys whose defaults depend on the type, and those defaults: a fan of 256 beams over
#: 2 rad (about 115 degrees) for an imaging sonar or a multibeam; an altimeter's one beam a
#: cone of 0.44 rad (25 degrees, the Blue Robotics Ping echosounder's beam width, the
#: altimeter of the BlueROV2 this project starts from)
DEFAULTS_BY_TYPE = {
    "imaging": {"beams": 256, "horizontal_fov_rad": 2.0},
    "multibeam": {"beams": 256, "horizontal_fov_rad": 2.0},
    "altimeter": {"beams": 1, "horizontal_fov_rad": 0.44},
}


@dataclass(frozen=True)
class SonarSpec:
    """A sonar's table (``[[sensors.sonar]]``; the checks in `__post_init__`). ``beams`` and
    ``horizontal_fov_rad`` left None take their type's defaults (`DEFAULTS_BY_TYPE`)."""

    name: str
    type: str = "imaging"
    beams: int | None = None
    bins: int = 512
    horizontal_fov_rad: float | None = None
    vertical_fov_rad: float = 0.35
    max_range_m: float = 20.0
    min_range_m: float = 0.1
    rate_hz: float = 10.0
    link: str | None = None
    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rays_per_beam: int = 32
    absorption_db_per_m: float = 0.1
    reflectivity: float = 0.5
    speckle: bool = True
    range_noise_m: float = 0.0

    def __post_init__(self) -> None:
        label = f"sonar '{self.name}'"
        sensor.check_mount(self, label)
        if self.type not in TYPES:
            raise ParameterError(
                f"{label}: type must be one of {', '.join(TYPES)}, got {self.type!r}"
            )
        for key, default in DEFAULTS_BY_TYPE[self.type].items():
            if getattr(self, key) is None:  # frozen: set once, here
                object.__setattr__(self, key, default)
        sensor.check_counts(self, label, {"beams": 4096, "bins": 8192, "rays_per_beam": 1024})
        if self.type == "altimeter" and self.beams != 1:
            raise ParameterError(f"{label}: beams must be 1 for an altimeter, got {self.beams}")
        sensor.check_fields_of_view(self, label, ("horizontal_fov_rad", "vertical_fov_rad"))
        if not (0.0 <= self.min_range_m < self.max_range_m < math.inf):
            raise ParameterError(
                f"{label}: needs 0 <= min_range_m < max_range_m (finite), got "
                f"{self.min_range_m}, {self.max_range_m}"
            )
        for key in ("absorption_db_per_m", "reflectivity", "range_noise_m"):
            if not (math.isfinite(getattr(self, key)) and getattr(self, key) >= 0.0):
                raise ParameterError(f"{label}: {key} must be finite and >= 0")

    @property
    def range_m(self) -> np.ndarray:
        """The bins' centres (bins,) [m]."""
        step = (self.max_range_m - self.min_range_m) / self.bins
        return self.min_range_m + (np.arange(self.bins) + 0.5) * step

    @property
    def bearing_rad(self) -> np.ndarray:
        """The beams' bearings (beams,) [rad] (0 for an altimeter)."""
        if self.beams == 1:
            return np.zeros(1)
        half = 0.5 * self.horizontal_fov_rad
        return np.linspace(-half, half, self.beams)

    @classmethod
    def from_dict(cls, raw: dict[str, Any], label: str) -> SonarSpec:
        return sensor.spec_from_dict(cls, raw, label)


def _fan(spec: SonarSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(unit rays (beams n, 3) in the sonar's frame, each ray's beam, its elevation weight)."""
    n = spec.rays_per_beam
    half_v = 0.5 * spec.vertical_fov_rad
    across = (np.arange(n) + 0.5) / n * 2.0 - 1.0  # (-1, 1): centres of n equal slices
    if spec.type == "altimeter":
        half = 0.5 * spec.horizontal_fov_rad
        bearing, elevation = (g.ravel() for g in np.meshgrid(half * across, half * across))
        # the cone: the grid's rays within half of the axis (its corners, up to sqrt(2) half
        # off, heard a slope facing the diagonal nearer than the cone can)
        inside = np.cos(bearing) * np.cos(elevation) >= math.cos(half) * (1.0 - 1e-12)
        bearing, elevation = bearing[inside], elevation[inside]
        beam = np.zeros(bearing.size, dtype=np.int64)
        weight = np.exp(-((bearing**2 + elevation**2) / half**2) * math.log(2.0))
    else:
        bearing = np.repeat(spec.bearing_rad, n)
        elevation = np.tile(half_v * across, spec.beams)
        beam = np.repeat(np.arange(spec.beams), n)
        weight = np.exp(-((elevation / half_v) ** 2) * math.log(2.0))
    rays = np.column_stack(
        [
            np.cos(elevation) * np.cos(bearing),
            np.cos(elevation) * np.sin(bearing),
            np.sin(elevation),
        ]
    )
    return rays / np.linalg.norm(rays, axis=1, keepdims=True), beam, weight


def _across_beams(spec: SonarSpec) -> np.ndarray:
    """The array's pattern at 0, +-1, +-2 beams: sinc^2 of the offset in beamwidths."""
    if spec.beams == 1:
        return np.ones(1)
    taps = np.sinc(np.arange(-2, 3) * 0.5) ** 2  # beams spaced half a beamwidth
    return taps / taps.sum()


class Sonar(sensor.Mounted):
    """A `SonarSpec` listening to a `Scene`, its speckle drawn from ``rng``."""

    def __init__(self, spec: SonarSpec, scene: Scene, rng: np.random.Generator):
        super().__init__(spec, scene, f"sonar '{spec.name}'")
        self.spec, self.rng = spec, rng
        self.rays, self.beam, self.weight = _fan(spec)
        self.taps = _across_beams(spec)

    def echoes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """What the rays heard in the scene as it stands: (each heard ray's range bin, beam,
        range [m] and echo), the rays heard within [min_range_m, max_range_m) only."""
        spec = self.spec
        placed = self.placement()
        directions = self.rays @ placed.rotation.T
        hits = self.scene.caster.cast(placed.translation, directions)
        r = hits.range_m
        step = (spec.max_range_m - spec.min_range_m) / spec.bins
        k = np.floor((np.where(np.isfinite(r), r, -1.0) - spec.min_range_m) / step)
        heard = np.isfinite(r) & (k >= 0) & (k < spec.bins)
        cos_incidence = -np.einsum("ij,ij->i", hits.normal_world[heard], directions[heard])
        r_heard = r[heard]
        echo = (
            spec.reflectivity
            * np.maximum(cos_incidence, 0.0) ** 2
            * self.weight[heard]
            * 10.0 ** (-0.2 * spec.absorption_db_per_m * r_heard)
            / np.maximum(r_heard, step) ** 2
        )
        return k[heard].astype(np.int64), self.beam[heard], r_heard, echo

    def intensity(self) -> np.ndarray:
        """The returns (bins, beams) of the scene as it stands."""
        return self._image(*self.echoes())

    def _image(self, k, beam, r, echo) -> np.ndarray:
        """The echoes' image (bins, beams): binned, blurred across beams, speckled."""
        spec = self.spec
        cells = k * spec.beams + beam
        image = np.bincount(cells, echo, minlength=spec.bins * spec.beams)
        image = image.reshape(spec.bins, spec.beams)
        if len(self.taps) > 1:
            padded = np.pad(image, ((0, 0), (2, 2)))
            image = sum(self.taps[j] * padded[:, j : j + spec.beams] for j in range(5))
        if spec.speckle:
            image = image * self.rng.standard_exponential(image.shape)
        return image

    def profile(self, beam, r, echo) -> tuple[np.ndarray, np.ndarray]:
        """Each beam's bottom detection from its heard rays: (range [m] (beams,), the
        echo-weighted mean of its rays' ranges (an altimeter's: the nearest, its echo's first
        arrival) plus noise, NaN where it heard nothing; intensity (beams,), its echoes'
        sum, speckled)."""
        spec = self.spec
        energy = np.bincount(beam, echo, minlength=spec.beams)
        heard = energy > 0.0
        if spec.type == "altimeter":
            echoing = echo > 0.0  # a ray grazing a surface returns nothing
            nearest = np.full(spec.beams, np.inf)
            np.minimum.at(nearest, beam[echoing], r[echoing])
            range_m = np.where(heard, nearest, np.nan)
        else:
            moment = np.bincount(beam, echo * r, minlength=spec.beams)
            range_m = np.where(heard, moment / np.where(heard, energy, 1.0), np.nan)
        if spec.range_noise_m > 0.0:
            range_m = range_m + spec.range_noise_m * self.rng.standard_normal(spec.beams)
        if spec.speckle:
            energy = energy * self.rng.standard_exponential(spec.beams)
        return range_m, energy

    def fire(self, out: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
        """What a firing records: its intensity (float32); a multibeam's or an altimeter's
        detections too, ``beam_range_m`` and ``beam_intensity`` (beams,); copied into
        ``out`` (the same arrays) when given, else new arrays."""
        k, beam, r, echo = self.echoes()
        fired = {"intensity": self._image(k, beam, r, echo).astype(np.float32)}
        if self.spec.type in DETECTING:
            range_m, energy = self.profile(beam, r, echo)
            fired["beam_range_m"], fired["beam_intensity"] = range_m, energy.astype(np.float32)
        return sensor.written(fired, out, f"sonar '{self.spec.name}'")


SONAR = sensor.register(
    sensor.PerceptionKind(
        name="sonar",
        spec=SonarSpec,
        make=Sonar,
        bytes=lambda spec: (
            4 * spec.bins * spec.beams  # the image (float32)
            # the detections: range (float64) and intensity (float32) per beam
            + ((8 + 4) * spec.beams if spec.type in DETECTING else 0)
        ),
        constants=lambda sonar: {
            "range_m": sonar.spec.range_m,
            "bearing_rad": sonar.spec.bearing_rad,
        },
    )
)
