"""Signals of time a scenario describes in a table (e.g. a desired force)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvms_pin.scenario.schema import Table


def sine_profile(t: Table | None, size: int) -> Callable[[float], np.ndarray]:
    """offset + amplitude sin(2 pi t / period + phase), component-wise (zero without a table)."""
    if t is None:
        zero = np.zeros(size)
        return lambda time_s: zero
    offset = t.vector("offset", size, np.zeros(size))
    amplitude = t.vector("amplitude", size, np.zeros(size))
    period = t.number("period_s", 1.0, positive=True)
    phase = t.number("phase_rad", 0.0)
    t.finish()
    omega = 2.0 * math.pi / period
    return lambda time_s: offset + amplitude * math.sin(omega * time_s + phase)


def plain(value: Any) -> Any:
    """numpy arrays and scalars as lists and floats (for the rollout's JSON)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value.item() if isinstance(value, np.generic) else value
