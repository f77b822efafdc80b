"""What a controller is allowed to see: one sample of the (possibly noisy) sensors, read-only."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError

#: a measurement without images
_NO_IMAGES: Mapping[str, Any] = MappingProxyType({})


def read_only(array: np.ndarray) -> np.ndarray:
    """``array`` itself, marked read-only: whoever holds it can no longer write into it."""
    array.setflags(write=False)
    return array


def _frozen(value) -> bool:
    """A read-only float64 array (nobody can write into it)."""
    return type(value) is np.ndarray and value.dtype.char == "d" and not value.flags.writeable


@dataclass(frozen=True)
class Measurement:
    """One sensor sample; the only input of a controller. Its arrays are read-only.

    Attributes:
        time_s: sample time t [s].
        q: measured configuration (nq,): [p (3), quaternion xyzw (4), arm joints].
        v: measured generalized velocity zeta (nv,): [body linear v, body angular w,
            joint rates] (Pinocchio's v).
        wrench_world: measured wrench the end-effector exerts on the environment,
            lambda + noise, at the sensor frame origin with world-aligned axes,
            [force N (3); torque N m (3)].
        images: the latest image of each camera in the loop, by name
            (`uvms_pin.perception.loop.LoopImage`; empty without one).
    """

    time_s: float
    q: np.ndarray
    v: np.ndarray
    wrench_world: np.ndarray
    images: Mapping[str, Any] = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.images is None:  # the one empty mapping, not a dict per measurement
            object.__setattr__(self, "images", _NO_IMAGES)
        # a measurement never aliases anything writable (the plant's state): arrays that are
        # not already read-only float arrays are copied, and the copies frozen
        q, v, w = self.q, self.v, self.wrench_world
        if (  # the engine's case, inline: three read-only float arrays
            type(q) is type(v) is type(w) is np.ndarray
            and not (q.flags.writeable or v.flags.writeable or w.flags.writeable)
            and q.dtype.char == v.dtype.char == w.dtype.char == "d"
        ):
            return
        for name in ("q", "v", "wrench_world"):
            value = getattr(self, name)
            if not _frozen(value):
                try:
                    array = np.array(value, dtype=float)
                except (TypeError, ValueError):  # strings, ragged lists (the loop's: arrays)
                    raise ParameterError(
                        f"measurement {name} must be numbers, got {value!r}"
                    ) from None
                object.__setattr__(self, name, read_only(array))

    @property
    def force_world_N(self) -> np.ndarray:
        """Measured contact force f_e + Delta f_e in world axes [N]."""
        return self.wrench_world[:3]
