"""The one interface every controller implements."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np

from uvms_pin.control.measurement import Measurement
from uvms_pin.results.signal import Signal


class Controller(ABC):
    """A feedback law tau = k(t, measurement).

    Controllers see only a `Measurement` (and whatever kinematics they were built with),
    never the plant's dynamics; that is what "model-free" means in this package.
    """

    @abstractmethod
    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        """Generalized input tau (nv,): body wrench on the vehicle [N, N m], joint torques."""

    def reset(self) -> None:  # noqa: B027 - optional hook, stateless controllers skip it
        """Forget any internal state before a new run."""

    def signals(self) -> dict[str, np.ndarray | Signal]:
        """Internal signals of the last ``compute`` worth logging, by name: a 1-D array
        (table columns ``<name>.0``, ``<name>.1``, ...) or a `Signal` carrying a name and a
        unit per component (columns ``<name>.<component>_<unit>``)."""
        return {}

    def funnel_margin(self) -> float:
        """min over funnel components of 1 - |xi| at the last ``compute`` (inf: no funnels)."""
        return math.inf

    def set_funnel_extension(self, enabled: bool) -> None:  # noqa: B027 - optional hook
        """For continuous-time simulation with an adaptive integrator only.

        When enabled, ``compute`` evaluates its barrier (clamped) outside a funnel instead
        of raising, so that a trial stage the integrator will reject does not end the run;
        the simulator watches ``funnel_margin()`` on accepted steps instead and reports a
        genuine violation. Controllers without funnels ignore it.
        """


class ZeroController(Controller):
    """No input at all: the passive system.

    Args:
        nv: the velocity dimension (tau's size). nq: the configuration's, when known (the
            compiled loop's zero law needs it to check it is the plant's; without it the
            loop runs in Python).
    """

    def __init__(self, nv: int, nq: int | None = None):
        self._tau = np.zeros(nv)
        self._nq = None if nq is None else int(nq)

    @property
    def nv(self) -> int:
        return int(self._tau.size)

    @property
    def nq(self) -> int | None:
        return self._nq

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        return self._tau
