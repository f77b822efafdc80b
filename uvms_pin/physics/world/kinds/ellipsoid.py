"""``type = "ellipsoid"``: an ellipsoid of semi-axes ``semi_axes_m`` (a, b, c) [m] along its
x, y, z, about its centre: a boulder, a buoy or float, a spheroidal hull (a = b).

Its coal shape is coal's ellipsoid (GJK/EPA: one deepest point a pair), the core's too
(``ContactKind::ellipsoid``). As a free object (V = 4/3 pi a b c):

    I = m/5 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2)       (homogeneous solid)

its added mass is the ellipsoid's exact potential-flow one (Lamb 1932, sec. 114-115:
`uvms_pin.hydro.geometry.ellipsoid_added_mass`); its damping is the equal-volume sphere's
(`uvms_pin.hydro.geometry.sphere_hydro`) with the translation's scaled by the projected
area (pi b c across x, pi a c across y, pi a b across z, over the sphere's pi r^2): exact
for a sphere, an estimate otherwise (the rotation keeps the sphere's skin friction: a
slender ellipsoid turning about a transverse axis sheds form drag too, not modelled here).
The free surface cuts it as itself (`uvms_pin.hydro.submerged.Ellipsoid`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.hydro.geometry import ellipsoid_added_mass, sphere_hydro
from uvms_pin.hydro.hull import HullPiece
from uvms_pin.hydro.params import HydroParams
from uvms_pin.hydro.submerged import Ellipsoid
from uvms_pin.model.uvms import HydroBody
from uvms_pin.physics.world import kind


def check(name: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    axes = kind.positive_vector(name, "semi_axes_m", raw["semi_axes_m"])
    return {"semi_axes_m": axes, **kind.checked_pose(name, raw)}


def mass_properties(params: dict[str, Any]) -> tuple[float, np.ndarray, np.ndarray]:
    a, b, c = params["semi_axes_m"]
    unit = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) / 5.0
    return 4.0 / 3.0 * math.pi * a * b * c, np.zeros(3), unit


def hydro_params(semi_axes_m, water_density_kg_m3: float) -> HydroParams:
    """Its coefficients at its centre, in its axes (module docstring)."""
    a, b, c = semi_axes_m
    radius = (a * b * c) ** (1.0 / 3.0)  # the equal-volume sphere's
    sphere = sphere_hydro(radius, water_density_kg_m3)
    area = np.array([b * c, a * c, a * b, radius**2, radius**2, radius**2]) / radius**2
    return replace(
        sphere,
        volume_m3=4.0 / 3.0 * math.pi * a * b * c,
        added_mass=np.diag(ellipsoid_added_mass(a, b, c, water_density_kg_m3)),
        linear_damping=sphere.linear_damping * area,
        quadratic_damping=sphere.quadratic_damping * area,
        origin=f"ellipsoid {a:g}x{b:g}x{c:g} m: potential-flow added mass (Lamb), "
        "the equal-volume sphere's drag over its projected areas",
    )


def hydro_body(link: str, params: dict[str, Any], water_density_kg_m3: float) -> HydroBody:
    axes = tuple(params["semi_axes_m"])
    hull = HullPiece(Ellipsoid(axes), np.eye(3), np.zeros(3))
    coefficients = hydro_params(axes, water_density_kg_m3)
    return HydroBody(f"{link}/collision[0]", 1, pin.SE3.Identity(), coefficients, (hull,))


ELLIPSOID = kind.register(
    kind.ObjectKind(
        name="ellipsoid",
        keys=(kind.Key("semi_axes_m", "vector"), *kind.SOLID_POSE),
        check=check,
        geometry=lambda p: (coal.Ellipsoid(*p["semi_axes_m"]), max(p["semi_axes_m"])),
        placement=kind.solid_placement,
        drawing=lambda p: kind.Drawing("Ellipsoid", (list(p["semi_axes_m"]),)),
        compiled=kind.Compiled(
            coal.Ellipsoid,
            lambda s: ("ellipsoid", np.asarray(s.radii, dtype=float), kind.NO_POINTS),
        ),
        free=kind.FreeShape(mass_properties, hydro_body),
    )
)
