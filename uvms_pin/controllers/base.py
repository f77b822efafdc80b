"""The one interface every controller implements."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from uvms_pin.measurement import Measurement


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


class ZeroController(Controller):
    """No input at all: the passive system."""

    def __init__(self, nv: int):
        self._tau = np.zeros(nv)

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        return self._tau
