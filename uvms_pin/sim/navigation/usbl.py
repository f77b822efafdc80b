"""USBL position fixes: a fix of the vehicle position (world, + white noise sigma [m]) every
period T; each is lost with probability p_drop, and a kept one arrives latency L after it
was taken. Reports the newest arrived fix [x, y, z, age_s, new] (age: now minus its time of
measurement; before the first fix every entry is 0 and age is -1) (``[sensors.usbl]``)."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from uvms_pin.sim.navigation.sensor import SensorKind, check_fields, register

__all__ = ["Usbl", "UsblSpec"]


@dataclass(frozen=True)
class UsblSpec:
    """A USBL's parameters (``[sensors.usbl]``).

    Attributes:
        noise_m: sigma of the white noise on each position component [m] (>= 0).
        period_s: the time between pings [s] (> 0). latency_s: a fix's delay [s] (>= 0).
        dropout_probability: the chance a fix is lost, in [0, 1).
    """

    noise_m: float = 0.0
    period_s: float = 1.0
    latency_s: float = 0.0
    dropout_probability: float = 0.0

    def __post_init__(self) -> None:
        check_fields(self, "USBL", positive=("period_s",), probability=("dropout_probability",))


class Usbl:
    def __init__(self, spec: UsblSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng
        self._next_ping_s = 0.0
        self._in_flight: deque[tuple[float, np.ndarray]] = deque()  # (time taken, fix)
        self._latest: tuple[float, np.ndarray] | None = None

    def measure(self, time_s: float, position_world_m: np.ndarray) -> np.ndarray:
        """[x, y, z (world, m), age_s, new (1 on the tick a fix arrives)]."""
        spec = self.spec
        # a ping at or before now is taken now (the ticks are the sensor's clock)
        if time_s + 1e-12 >= self._next_ping_s:
            draws = self.rng.standard_normal(3)
            lost = self.rng.random() < spec.dropout_probability
            if not lost:
                self._in_flight.append((time_s, position_world_m + spec.noise_m * draws))
            self._next_ping_s += spec.period_s * max(
                1, math.floor((time_s - self._next_ping_s) / spec.period_s) + 1
            )
        new = 0.0
        while self._in_flight and self._in_flight[0][0] + spec.latency_s <= time_s + 1e-12:
            self._latest = self._in_flight.popleft()
            new = 1.0
        if self._latest is None:
            return np.array([0.0, 0.0, 0.0, -1.0, 0.0])
        taken, fix = self._latest
        return np.r_[fix, time_s - taken, new]


USBL = register(
    SensorKind(
        name="usbl",
        spec=UsblSpec,
        streams=(4,),
        columns={"usbl": [("x", "m"), ("y", "m"), ("z", "m"), ("age", "s"), ("new", "")]},
        make=lambda spec, nav, rngs: Usbl(spec, rngs[0]),
        read=lambda usbl, tick: {"usbl": usbl.measure(tick.time_s, tick.position_world_m)},
    )
)
