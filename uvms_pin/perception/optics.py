"""Light in water: the Jerlov water types and the revised underwater image formation model.

A pixel whose ray meets a surface of reflectance rho_c at range z [m] (Akkaynak and Treibitz,
"A Revised Underwater Image Formation Model", CVPR 2018, eq. 2) reads, per channel c (R, G, B)

    I_c = rho_c E_c exp(-beta_D_c z)  +  B_inf_c (1 - exp(-beta_B_c z))

the direct signal attenuated with beta_D, plus the backscatter that grows towards the
veiling light B_inf with beta_B (a ray that meets nothing reads B_inf_c). The irradiance E_c
on the surface is the daylight from above, E0 exp(-K_d,c depth) (1 + n_z) / 2 (the sky's
hemisphere seen by a surface of normal n), plus each of the vehicle's lights,

    I_L cone(theta) max(0, n . l) exp(-beta_D_c d) / d^2

(d the light-to-surface distance, theta the angle off the light's axis; cone = 1 inside its
half-angle, falling smoothly to 0 over ``edge_rad`` beyond it). The veiling light is the
daylight scattered back at the camera's depth, B_inf_c = b E0 exp(-K_d,c depth_camera).

The water types are Jerlov's (N. G. Jerlov, Marine Optics, 2nd ed., Elsevier 1976, Table
XXVII: the diffuse attenuation K_d of downwelling irradiance, per metre) at 650, 550 and
450 nm for R, G and B. The presets take beta_D = beta_B = K_d, the narrow-band limit of the
revised model (both coefficients tend to the same attenuation of a narrow band), a
simplification of the wide-band coefficients a camera's response gives (Akkaynak et al.,
"What is the space of attenuation coefficients in underwater computer vision?", CVPR 2017):
give ``attenuation_per_m`` and ``backscatter_per_m`` for measured ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvms_pin.checks import finite_vector, nonnegative, number_fields
from uvms_pin.errors import ParameterError

__all__ = ["JERLOV_KD_PER_M", "Light", "WaterOptics", "backscatter", "cone"]

#: Jerlov (1976), Table XXVII: K_d [1/m] at 650, 550, 450 nm (R, G, B) of each water type:
#: the oceanic types I to III and the coastal types 1C to 9C (all 30 entries checked against
#: an independent transcription of the table, 400 to 700 nm every 25 nm; Austin and Petzold's
#: 1986 revision of the oceanic types differs by up to 8 %, e.g. 0.0176 for I at 450 nm)
JERLOV_KD_PER_M: dict[str, tuple[float, float, float]] = {
    "I": (0.36, 0.063, 0.019),
    "IA": (0.37, 0.067, 0.026),
    "IB": (0.375, 0.072, 0.036),
    "II": (0.40, 0.089, 0.068),
    "III": (0.445, 0.12, 0.135),
    "1C": (0.45, 0.12, 0.25),
    "3C": (0.46, 0.19, 0.39),
    "5C": (0.54, 0.30, 0.56),
    "7C": (0.63, 0.46, 0.89),
    "9C": (0.76, 0.63, 1.6),
}


@dataclass(frozen=True)
class WaterOptics:
    """The water's optics for a camera.

    Attributes:
        water_type: a Jerlov type (`JERLOV_KD_PER_M`): its K_d, and beta_D, beta_B when not
            given.
        attenuation_per_m, backscatter_per_m: beta_D, beta_B (R, G, B) [1/m], or None.
        surface_irradiance: E0, the daylight just under the surface (0: night).
        backscatter_albedo: b, the fraction of the ambient light scattered back as B_inf.
    """

    water_type: str = "IB"
    attenuation_per_m: tuple[float, float, float] | None = None
    backscatter_per_m: tuple[float, float, float] | None = None
    surface_irradiance: float = 1.0
    backscatter_albedo: float = 0.2

    def __post_init__(self) -> None:
        number_fields(self)
        if not isinstance(self.water_type, str) or self.water_type not in JERLOV_KD_PER_M:
            raise ParameterError(
                f"water_type must be a Jerlov type ({', '.join(JERLOV_KD_PER_M)}), "
                f"got {self.water_type!r}"
            )
        for name in ("attenuation_per_m", "backscatter_per_m"):
            value = getattr(self, name)
            if value is not None and not np.all(finite_vector(name, value, 3) >= 0.0):
                raise ParameterError(f"{name} needs 3 finite numbers >= 0 (R, G, B), got {value}")
        if not (self.surface_irradiance >= 0.0 and np.isfinite(self.surface_irradiance)):
            raise ParameterError(f"surface_irradiance must be >= 0, got {self.surface_irradiance}")
        if not (0.0 <= self.backscatter_albedo <= 1.0):
            raise ParameterError(
                f"backscatter_albedo must be in [0, 1], got {self.backscatter_albedo}"
            )

    @property
    def kd_per_m(self) -> np.ndarray:
        return np.asarray(JERLOV_KD_PER_M[self.water_type])

    @property
    def beta_d_per_m(self) -> np.ndarray:
        given = self.attenuation_per_m
        return self.kd_per_m if given is None else np.asarray(given, dtype=float)

    @property
    def beta_b_per_m(self) -> np.ndarray:
        given = self.backscatter_per_m
        return self.kd_per_m if given is None else np.asarray(given, dtype=float)

    def daylight(self, depth_m: np.ndarray) -> np.ndarray:
        """E0 exp(-K_d depth) (..., 3) at depths (...) [m] below the surface (>= 0)."""
        depth = np.maximum(np.asarray(depth_m, dtype=float), 0.0)[..., None]
        return self.surface_irradiance * np.exp(-self.kd_per_m * depth)

    def veiling_light(self, camera_depth_m: float) -> np.ndarray:
        """B_inf (3,) at the camera's depth."""
        return self.backscatter_albedo * self.daylight(camera_depth_m)


@dataclass(frozen=True)
class Light:
    """A light on the camera: ``position_m`` and unit ``direction`` in the camera's optical
    frame, ``intensity`` I_L, lit within ``half_angle_rad`` of its axis, fading to dark over
    ``edge_rad`` beyond it."""

    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] = (0.0, 0.0, 1.0)
    intensity: float = 1.0
    half_angle_rad: float = 0.5
    edge_rad: float = 0.1

    def __post_init__(self) -> None:
        number_fields(self)
        # finite: an inf or nan here would make the lit pixels' radiance nan, read as 0
        # counts, a black image and no error
        finite_vector("a light's position_m", self.position_m, 3)
        direction = finite_vector("a light's direction", self.direction, 3)
        norm = float(np.linalg.norm(direction))
        if not norm > 0.0:
            raise ParameterError(f"a light's direction must not be zero, got {self.direction}")
        object.__setattr__(self, "direction", tuple(direction / norm))
        nonnegative("a light's intensity", self.intensity)
        nonnegative("a light's edge_rad", self.edge_rad)
        if not 0.0 < self.half_angle_rad < np.pi:
            raise ParameterError(
                f"a light's half_angle_rad must be in (0, pi), got {self.half_angle_rad}"
            )


def cone(off_axis_rad: np.ndarray, half_angle_rad: float, edge_rad: float) -> np.ndarray:
    """1 within the half-angle, a smoothstep down to 0 at half-angle + edge, 0 beyond."""
    if edge_rad <= 0.0:
        return (off_axis_rad <= half_angle_rad).astype(float)
    s = np.clip((off_axis_rad - half_angle_rad) / edge_rad, 0.0, 1.0)
    return 1.0 - s * s * (3.0 - 2.0 * s)


def cone_of_cosine(cosine: np.ndarray, half_angle_rad: float, edge_rad: float) -> np.ndarray:
    """`cone` of the angles whose cosines are ``cosine`` (n,): 1 within the half-angle and
    0 beyond its edge without an arccos, which only the rays on the edge take."""
    out = (cosine >= np.cos(half_angle_rad)).astype(float)
    if edge_rad > 0.0:
        outer = min(np.pi, half_angle_rad + edge_rad)
        band = np.flatnonzero((out == 0.0) & (cosine > np.cos(outer)))
        angle = np.arccos(np.clip(cosine[band], -1.0, 1.0))
        out[band] = cone(angle, half_angle_rad, edge_rad)
    return out


def backscatter(veiling: np.ndarray, range_m: np.ndarray, beta_b: np.ndarray) -> np.ndarray:
    """B_inf_c (1 - exp(-beta_B_c z)) (n, 3); B_inf where z is inf."""
    return veiling * -np.expm1(-beta_b * range_m[:, None])
