"""``type = "sphere"``: a sphere of ``radius_m`` [m] about its centre.

As a free object: I = 2/5 m r^2 (each axis); its hydrodynamics are a URDF ``<sphere>``'s
(`uvms_pin.hydro.geometry.sphere_hydro`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import coal
import numpy as np

from uvms_pin.physics.world import kind


def check(name: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    return {
        "radius_m": kind.positive(name, "radius_m", raw["radius_m"]),
        **kind.checked_pose(name, raw),
    }


def mass_properties(params: dict[str, Any]) -> tuple[float, np.ndarray, np.ndarray]:
    r = float(params["radius_m"])
    return 4.0 / 3.0 * math.pi * r**3, np.zeros(3), np.eye(3) * 0.4 * r * r


def _urdf(params: dict[str, Any]) -> str:
    return f'<sphere radius="{float(params["radius_m"])!r}"/>'


SPHERE = kind.register(
    kind.ObjectKind(
        name="sphere",
        keys=(kind.Key("radius_m"), *kind.SOLID_POSE),
        check=check,
        geometry=lambda p: (coal.Sphere(p["radius_m"]), p["radius_m"]),
        placement=kind.solid_placement,
        drawing=lambda p: kind.Drawing("Sphere", (p["radius_m"],)),
        compiled=kind.Compiled(
            coal.Sphere, lambda s: ("sphere", np.array([s.radius]), kind.NO_POINTS)
        ),
        free=kind.FreeShape(
            mass_properties, lambda n, p, rho: kind.collision_body(n, _urdf(p), rho)
        ),
    )
)
