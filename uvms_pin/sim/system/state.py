"""The state of a system of bodies: q and v of every body, stacked, and where each sits."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

__all__ = ["Layout", "SystemState"]


@dataclass(frozen=True)
class Layout:
    """Where each body's coordinates sit in the system's (q, v).

    Attributes:
        names: the bodies, the robot first (``"robot"``), then each free object by name.
        q_slices, v_slices: each body's part of q (nq,) and v (nv,).
    """

    names: tuple[str, ...]
    q_slices: tuple[slice, ...]
    v_slices: tuple[slice, ...]

    @staticmethod
    def of(bodies: list[tuple[str, int, int]]) -> Layout:
        """The layout of ``bodies``, each (name, nq, nv), in that order."""
        q_slices, v_slices, iq, iv = [], [], 0, 0
        for _, nq, nv in bodies:
            q_slices.append(slice(iq, iq + nq))
            v_slices.append(slice(iv, iv + nv))
            iq, iv = iq + nq, iv + nv
        return Layout(tuple(b[0] for b in bodies), tuple(q_slices), tuple(v_slices))

    @property
    def nq(self) -> int:
        return self.q_slices[-1].stop

    @property
    def nv(self) -> int:
        return self.v_slices[-1].stop

    def split(self, q: np.ndarray, v: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Each body's (q, v), views of ``q`` and ``v``."""
        return [(q[a], v[b]) for a, b in zip(self.q_slices, self.v_slices, strict=True)]

    def join(self, states: list[tuple[np.ndarray, np.ndarray]]) -> SystemState:
        """The system's state from each body's (q, v), in order."""
        return SystemState(
            np.concatenate([s[0] for s in states]), np.concatenate([s[1] for s in states])
        )


class SystemState(NamedTuple):
    """q (nq,) and v (nv,) of every body of a system, stacked as its `Layout` says: the
    robot's configuration and generalized velocity (free-flyer: position [m], quaternion
    (x, y, z, w); body velocity [m/s, rad/s]; joints [rad, rad/s]) first, then each free
    object's pose (7,) and body velocity (6,). (A tuple: made once a control period.)"""

    q: np.ndarray
    v: np.ndarray
