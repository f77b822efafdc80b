"""``type = "cylinder"``: a cylinder of ``radius_m`` and ``length_m`` [m] along its z, about
its centre (a pipe section, a pile).

As a free object: I = diag(m (3 r^2 + L^2)/12, same, m r^2 / 2); its hydrodynamics are a
URDF ``<cylinder>``'s (`uvms_pin.hydro.geometry.cylinder_hydro`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import coal
import numpy as np

from uvms_pin.physics.world import kind

#: meshcat's cylinder lies along its y, the object's along z
ALONG_Z = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def check(name: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    return {
        "radius_m": kind.positive(name, "radius_m", raw["radius_m"]),
        "length_m": kind.positive(name, "length_m", raw["length_m"]),
        **kind.checked_pose(name, raw),
    }


def geometry(params: dict[str, Any]) -> tuple[coal.Cylinder, float]:
    r, length = params["radius_m"], params["length_m"]
    return coal.Cylinder(r, length), float(np.hypot(r, 0.5 * length))


def mass_properties(params: dict[str, Any]) -> tuple[float, np.ndarray, np.ndarray]:
    r, length = float(params["radius_m"]), float(params["length_m"])
    side = (3.0 * r * r + length * length) / 12.0
    return math.pi * r * r * length, np.zeros(3), np.diag([side, side, 0.5 * r * r])


def _urdf(params: dict[str, Any]) -> str:
    r, length = float(params["radius_m"]), float(params["length_m"])
    return f'<cylinder radius="{r!r}" length="{length!r}"/>'


def _core(shape: coal.Cylinder) -> tuple[str, np.ndarray, np.ndarray]:
    return "cylinder", np.array([shape.radius, 2.0 * shape.halfLength]), kind.NO_POINTS


CYLINDER = kind.register(
    kind.ObjectKind(
        name="cylinder",
        keys=(kind.Key("radius_m"), kind.Key("length_m"), *kind.SOLID_POSE),
        check=check,
        geometry=geometry,
        placement=kind.solid_placement,
        drawing=lambda p: kind.Drawing("Cylinder", (p["length_m"], p["radius_m"]), ALONG_Z),
        compiled=kind.Compiled(coal.Cylinder, _core),
        free=kind.FreeShape(
            mass_properties, lambda n, p, rho: kind.collision_body(n, _urdf(p), rho)
        ),
    )
)
