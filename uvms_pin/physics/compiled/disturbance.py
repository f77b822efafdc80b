"""A disturbance as the core's (src/uvms_core/disturbance.hpp): `SinusoidalDisturbance`."""

from __future__ import annotations

from functools import singledispatch
from types import ModuleType

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.disturbance import Disturbance, SinusoidalDisturbance


@singledispatch
def disturbance_to_core(disturbance: Disturbance | None, core: ModuleType):
    """The core's disturbance (None: none), or the Fallback saying why not (a disturbance
    written in Python is a function the core cannot call)."""
    return Fallback(f"the disturbance {disturbance!r}")


@disturbance_to_core.register(type(None))
def _(disturbance: None, core: ModuleType):
    return None


@disturbance_to_core.register
def _(disturbance: SinusoidalDisturbance, core: ModuleType):
    out = core.SinusoidalDisturbance()
    out.amplitude = disturbance.amplitude
    out.period_s = float(disturbance.period_s)
    out.phase_rad = float(disturbance.phase_rad)
    return out
