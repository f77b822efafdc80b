"""A flow field as the core's `FlowField` (src/uvms_core/flow.hpp): a uniform current plus
linear wave components, all in one water depth.

The core knows `UniformCurrent` and the wave fields (`AiryWave`, `IrregularSea`: any
`WaveField`), and their sums. A current that varies in time or with depth
(`GaussMarkovCurrent`, `DepthProfileCurrent`), or waves in different depths, have no
counterpart: their `Fallback` says so and the Python reference computes.
"""

from __future__ import annotations

import math
from functools import singledispatch
from types import ModuleType

import numpy as np

from uvms_pin.flow import FlowField, SumFlow, UniformCurrent
from uvms_pin.flow.components import WaveField
from uvms_pin.physics.compiled.backend import Fallback


@singledispatch
def flow_to_core(flow: FlowField | None, core: ModuleType):
    """The core's FlowField of ``flow`` (None: still water), or the Fallback saying why not."""
    return Fallback(
        f"the flow {flow!r} (it knows uniform currents and linear waves in one water depth)"
    )


@flow_to_core.register(type(None))
def _(flow: None, core: ModuleType):
    return core.FlowField()


@flow_to_core.register
def _(flow: UniformCurrent, core: ModuleType):
    out = core.FlowField()
    out.current_world_m_s = flow.velocity_world_m_s
    return out


@flow_to_core.register
def _(flow: WaveField, core: ModuleType):
    c = flow.components
    out = core.FlowField()
    out.waves = [
        _wave(core, *row)
        for row in zip(
            c.amplitude_m,
            c.angular_frequency_rad_s,
            c.wavenumber_rad_m,
            c.heading_rad,
            c.phase_rad,
            strict=True,
        )
    ]
    out.water_depth_m = float(c.water_depth_m)
    return out


@flow_to_core.register
def _(flow: SumFlow, core: ModuleType):
    """The currents add, the wave components are listed together (one depth for all)."""
    parts = [flow_to_core(field, core) for field in flow.fields]
    fallback = next((p for p in parts if isinstance(p, Fallback)), None)
    if fallback is not None:
        return fallback
    depths = {p.water_depth_m for p in parts if p.waves}
    if len(depths) > 1:
        return Fallback(f"waves in different water depths ({sorted(depths)} m)")
    out = core.FlowField()
    out.current_world_m_s = np.sum([p.current_world_m_s for p in parts], axis=0)
    out.waves = [wave for p in parts for wave in p.waves]
    out.water_depth_m = depths.pop() if depths else math.inf
    return out


def _wave(core: ModuleType, amplitude, frequency, wavenumber, heading, phase):
    wave = core.WaveComponent()
    wave.amplitude_m = float(amplitude)
    wave.angular_frequency_rad_s = float(frequency)
    wave.wavenumber_rad_m = float(wavenumber)
    wave.heading_rad = float(heading)
    wave.phase_rad = float(phase)
    return wave
