"""``type = "box"``: a rectangular box of edges ``size_m`` (3,) [m] about its centre.

As a free object: I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2) for edges a x b x c; its
hydrodynamics are a URDF ``<box>``'s (`uvms_pin.hydro.geometry.box_hydro`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import coal
import numpy as np

from uvms_pin.physics.world import kind


def check(name: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    return {
        "size_m": kind.positive_vector(name, "size_m", raw["size_m"]),
        **kind.checked_pose(name, raw),
    }


def geometry(params: dict[str, Any]) -> tuple[coal.Box, float]:
    a, b, c = params["size_m"]
    return coal.Box(a, b, c), 0.5 * float(np.linalg.norm(params["size_m"]))


def mass_properties(params: dict[str, Any]) -> tuple[float, np.ndarray, np.ndarray]:
    size = np.asarray(params["size_m"], dtype=float)
    a, b, c = size
    unit = 1.0 / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    return float(np.prod(size)), np.zeros(3), np.diag(unit)


def _urdf(params: dict[str, Any]) -> str:
    return '<box size="{} {} {}"/>'.format(*map(repr, map(float, params["size_m"])))


BOX = kind.register(
    kind.ObjectKind(
        name="box",
        keys=(kind.Key("size_m", "vector"), *kind.SOLID_POSE),
        check=check,
        geometry=geometry,
        placement=kind.solid_placement,
        drawing=lambda params: kind.Drawing("Box", (list(params["size_m"]),)),
        compiled=kind.Compiled(
            coal.Box, lambda s: ("box", 2.0 * np.asarray(s.halfSide, dtype=float), kind.NO_POINTS)
        ),
        free=kind.FreeShape(
            mass_properties, lambda n, p, rho: kind.collision_body(n, _urdf(p), rho)
        ),
    )
)
