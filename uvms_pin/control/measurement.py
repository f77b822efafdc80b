"""What a controller is allowed to see: one sample of the (possibly noisy) sensors."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Measurement:
    """One sensor sample; the only input of a controller.

    Attributes:
        time_s: sample time t [s].
        q: measured configuration (nq,): [p (3), quaternion xyzw (4), arm joints].
        v: measured generalized velocity zeta (nv,): [body linear v, body angular w,
            joint rates] (Pinocchio's v).
        wrench_world: measured wrench the end-effector exerts on the environment,
            lambda + noise, at the sensor frame origin with world-aligned axes,
            [force N (3); torque N m (3)].
    """

    time_s: float
    q: np.ndarray
    v: np.ndarray
    wrench_world: np.ndarray

    @property
    def force_world_N(self) -> np.ndarray:
        """Measured contact force f_e + Delta f_e in world axes [N]."""
        return self.wrench_world[:3]
