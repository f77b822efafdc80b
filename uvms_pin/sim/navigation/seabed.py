"""What a DVL needs of the world: its altitude above the bottom. A flat bottom at a depth
now; a seafloor of the world table can answer the same question later."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from uvms_pin.errors import ParameterError

__all__ = ["FlatSeabed", "Seabed"]


class Seabed(Protocol):
    """The bottom under a point."""

    def altitude_m(self, position_world_m: np.ndarray) -> float:
        """Height [m] of the point above the bottom straight below it (negative: under it)."""
        ...


@dataclass(frozen=True)
class FlatSeabed:
    """A flat bottom at z = -depth_m (the surface at z = 0, z up)."""

    depth_m: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.depth_m) and self.depth_m > 0.0):
            raise ParameterError(f"sea-bottom depth must be finite and > 0, got {self.depth_m}")

    def altitude_m(self, position_world_m: np.ndarray) -> float:
        return float(position_world_m[2] + self.depth_m)
