"""The core's settings of a compiled sampled loop (src/uvms_core/sampled_loop.hpp)."""

from __future__ import annotations

from types import ModuleType

from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.settings import SimulationSettings

__all__ = ["loop_settings_to_core"]


def loop_settings_to_core(core: ModuleType, settings: SimulationSettings, state_noisy: bool):
    """The core's LoopSettings of a sampled run with ``settings``: its fixed-step integrator,
    control period [s], ticks per logged sample and last tick; ``state_noisy``: q and v are
    measured with noise (else as they are)."""
    out = core.LoopSettings()
    out.integrator = integrator_to_core(settings.integrator, core)
    out.period_s = float(settings.control_period_s)
    out.ticks_per_log = int(settings.ticks_per_log)
    out.final_tick = (settings.n_log - 1) * settings.ticks_per_log
    out.state_noisy = bool(state_noisy)
    return out
