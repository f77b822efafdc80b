"""The bandwidth of the arm's joint drives: each joint's torque follows its command with a
first-order lag, tau_dot = (tau_cmd - tau) / T_j.

The command is held over a control period, so the lag is solved exactly per period
(`uvms_pin.sim.thruster_drive.first_order_step`) and the plant gets the torque's mean over
it. It wraps another actuation: the vehicle's part and the joints' limits are that one's.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.sim.actuation import Actuation
from uvms_pin.sim.thruster_drive import first_order_step

__all__ = ["LaggedJointTorques"]


class LaggedJointTorques(Actuation):
    """``inner``'s applied joint torques, lagged by T_j [s] per joint (>= 0; 0: none)."""

    def __init__(self, inner: Actuation, time_constant_s: np.ndarray):
        tau = np.asarray(time_constant_s, dtype=float).reshape(-1)
        if not np.all(np.isfinite(tau)) or np.any(tau < 0.0):
            raise ParameterError(
                f"joint torque time constants must be finite and >= 0, got {tau.tolist()}"
            )
        self.inner = inner
        self.time_constant_s = tau
        self._infinite_rate = np.full(tau.size, np.inf)
        self._torque = np.zeros(tau.size)
        self._period_s: float | None = None

    def start(self, period_s: float | None = None) -> None:
        if period_s is None and np.any(self.time_constant_s > 0.0):
            raise ParameterError("a joint torque lag needs a sampled loop: set [control] period_s")
        self.inner.start(period_s)
        self._period_s = period_s
        self._torque = np.zeros(self.time_constant_s.size)

    def apply(self, tau_commanded: np.ndarray) -> np.ndarray:
        out = np.array(self.inner.apply(tau_commanded), dtype=float)
        if out[6:].shape != self._torque.shape:
            raise ParameterError(
                f"{out.size - 6} joint torques for {self._torque.size} time constants"
            )
        if self._period_s is not None:
            self._torque, out[6:] = first_order_step(
                self._torque, out[6:], self.time_constant_s, self._infinite_rate, self._period_s
            )
        return out

    def saturated(self, tau_commanded: np.ndarray) -> bool:
        return self.inner.saturated(tau_commanded)

    def dropped(self) -> str | None:
        return self.inner.dropped()

    def signals(self) -> dict[str, np.ndarray]:
        return self.inner.signals()

    def signal_columns(self) -> dict[str, list[tuple[str, str]]]:
        return self.inner.signal_columns()
