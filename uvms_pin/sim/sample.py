"""One instant of the closed loop as its observers see it, and what an observer is."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from uvms_pin.control.measurement import Measurement
from uvms_pin.results.signal import Signal


@dataclass(frozen=True)
class Sample:
    """The loop at one control tick (every array read-only).

    Attributes:
        time_s: t [s].
        q, v: the true state (nq,), (nv,).
        measurement: what the controller (or policy) was given.
        contact_world: lambda, the true wrench the end-effector exerts on the environment
            [N (3); N m (3)], world axes.
        disturbance_body: delta(t), the disturbance wrench on the vehicle [N; N m], body axes.
        tau_commanded: the controller's output (nv,) [N, N m]; tau_applied: what the
            actuation made of it (held over the next control period).
        signals: the controller's internal signals after this call, by name (arrays, or
            `Signal` records with component names and units).
    """

    time_s: float
    q: np.ndarray
    v: np.ndarray
    measurement: Measurement
    contact_world: np.ndarray
    disturbance_body: np.ndarray
    tau_commanded: np.ndarray
    tau_applied: np.ndarray
    signals: dict[str, np.ndarray | Signal]


class Observer(Protocol):
    """Something that watches a run: called with every logged sample, in order."""

    def on_sample(self, sample: Sample) -> None: ...


@dataclass(frozen=True)
class ProgressReport:
    """An observer calling ``progress(t_s, duration_s)`` after every logged sample."""

    progress: Callable[[float, float], None]
    duration_s: float

    def on_sample(self, sample: Sample) -> None:
        self.progress(sample.time_s, self.duration_s)
