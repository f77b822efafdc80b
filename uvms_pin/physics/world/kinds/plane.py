"""``type = "plane"``: the half-space below ``point_world_m`` along the outward
``normal_world`` (normalised; a tilted normal gives a slope). It touches a piece by the
piece's corners below it; it cannot be free."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.physics.world import kind

PATCH_HALF_M = 6.0  # half the side of the drawn patch of the (infinite) plane
SLAB_M = 0.04  # the drawn patch's thickness, below the plane


#: the outward normal, world axes (normalised; default: up, a flat seafloor)
UP = kind.Key("normal_world", "vector", (0.0, 0.0, 1.0))


def _frame_with_z(normal: np.ndarray) -> np.ndarray:
    """A rotation whose z axis is the unit vector ``normal``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, normal)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(normal, x), normal])


def check(name: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    point = finite_vector(f"object '{name}' point_world_m", raw["point_world_m"], 3)
    normal = finite_vector(f"object '{name}' normal_world", raw.get("normal_world", (0, 0, 1)), 3)
    largest = float(np.max(np.abs(normal)))
    if largest == 0.0:
        raise kind.invalid(name, "normal_world", "must be non-zero")
    normal = normal / largest  # a direction: its norm then cannot overflow (1e300 entries)
    return {
        "point_world_m": point.tolist(),
        "normal_world": (normal / np.linalg.norm(normal)).tolist(),
    }


def placement(params: dict[str, Any]) -> pin.SE3:
    """The plane's frame: its point, z along its outward normal."""
    normal = np.asarray(params["normal_world"], dtype=float)
    return pin.SE3(_frame_with_z(normal), np.asarray(params["point_world_m"], dtype=float))


PLANE = kind.register(
    kind.ObjectKind(
        name="plane",
        keys=(kind.Key("point_world_m", "vector"), UP),
        check=check,
        geometry=lambda _: (coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0), np.inf),
        placement=placement,
        drawing=lambda _: kind.Drawing(
            "Box",
            ([2.0 * PATCH_HALF_M, 2.0 * PATCH_HALF_M, SLAB_M],),
            offset_in_object_m=np.array([0.0, 0.0, -0.5 * SLAB_M]),
            unbounded=True,
        ),
        compiled=kind.Compiled(coal.Halfspace, lambda _: ("plane", np.zeros(0), kind.NO_POINTS)),
    )
)
