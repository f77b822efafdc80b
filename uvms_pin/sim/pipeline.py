"""Whether a run is compiled: decided once, before it starts, from one list of reasons.

Three compiled pipelines serve a run: the compiled sampled loop (`Pipeline.LOOP`: a run's
ticks in chunks of one core call, `uvms_pin.sim.compiled_loop`), the batched plant
(`Pipeline.BATCH`: N environments' periods in one call, `uvms_pin.sim.batched_plant`) and the
compiled system of bodies (`Pipeline.SYSTEM`: the period of a robot with free objects or
fixtures in one call, `uvms_pin.sim.system.period`). Each reason below names a part without a compiled
counterpart and the pipelines it keeps in Python; `why_not_compiled` gives the first that
applies. The rollout records it (its metadata's ``closed_loop`` for the loop, ``world.integration``
for the system's period), the batched plant refuses with it. The plant's own right-hand side
and period are compiled part by part whatever the pipeline; a world keeps the loop and the
batch in Python (its contacts are stepped period by period), not the system's period.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.sim.compiled.actuation import actuation_to_core
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.compiled.laws import law_to_core
from uvms_pin.sim.compiled.plant import plant_to_core
from uvms_pin.sim.integrators import Integrator
from uvms_pin.sim.sample import ProgressReport
from uvms_pin.sim.sensors import SensorConfig
from uvms_pin.sim.settings import SimulationSettings

__all__ = ["REASONS", "Pipeline", "RunParts", "why_not_compiled"]


class Pipeline(enum.Flag):
    """The compiled pipelines a reason can keep in Python."""

    LOOP = enum.auto()  # the compiled sampled loop of a run
    BATCH = enum.auto()  # the batched plant of the vector environments
    SYSTEM = (
        enum.auto()
    )  # the period of a system with free objects or fixtures in one compiled call
    BOTH = LOOP | BATCH  # the closed loop's two: the run's ticks, the environments' periods
    ALL = LOOP | BATCH | SYSTEM


@dataclass(frozen=True)
class RunParts:
    """What a run is made of, as the choice reads it.

    Attributes:
        system: the bodies and their world (a `uvms_pin.sim.system.System`, whose period
            step asks this list). settings: periods, integrator, duration (None: the
            system's period alone is asked, with ``integrator``). sensors: the sensors'
            configuration (None likewise). controller: the law (None: the caller gives tau,
            as a policy does). observers: what watches every sample (besides the log).
        integrator: the integrator of a system's period without settings (None: not asked).
        robots: how many robots the run holds (`uvms_pin.sim.robots_loop`).
    """

    system: Any
    settings: SimulationSettings | None = None
    sensors: SensorConfig | None = None
    controller: Any = None
    observers: Sequence[Any] = ()
    integrator: Integrator | None = None
    robots: int = 1

    @property
    def stepped_by(self) -> Integrator | None:
        """The integrator of the run's periods (the settings', else ``integrator``)."""
        return self.integrator if self.settings is None else self.settings.integrator


def _fallback(built: Any) -> str | None:
    return built.reason if isinstance(built, Fallback) else None


def _integrator(parts: RunParts) -> str | None:
    integrator = parts.stepped_by
    return None if integrator is None else _fallback(integrator_to_core(integrator, core_module()))


def _plant(parts: RunParts) -> str | None:
    plant = parts.system.plant
    if plant.compiled is not None:
        return None
    return _fallback(plant_to_core(plant, core_module())) or "a plant part"


#: (the pipelines it keeps in Python, the check: the reason, or None when it does not apply),
#: in the order they are asked
REASONS: tuple[tuple[Pipeline, Callable[[RunParts], str | None]], ...] = (
    (Pipeline.BOTH, lambda p: "several robots (their system is integrated in Python)" if p.robots > 1 else None),
    (Pipeline.LOOP, lambda p: None if p.system.compiled_allowed else "the Python loop was asked for"),
    (Pipeline.SYSTEM, lambda p: None if p.system.compiled_allowed else "the Python integration was asked for"),
    (Pipeline.ALL, lambda p: "the Python backend" if p.system.plant.backend == "python" else None),
    (Pipeline.BOTH, lambda p: "continuous-time control" if p.settings.control_period_s is None else None),
    (Pipeline.ALL, _integrator),
    (Pipeline.LOOP, lambda p: None if p.controller is None else _fallback(law_to_core(p.controller, core_module()))),
    (Pipeline.BOTH, lambda p: "a world (its contacts are stepped period by period)" if p.system.plant.world is not None else None),
    (Pipeline.BATCH, lambda p: "a flow (waves, sea states, varying currents)" if p.system.plant.flow is not None else None),
    (Pipeline.BOTH, lambda p: "stop_at_surface" if p.system.plant.stop_at_surface else None),
    (Pipeline.BOTH, lambda p: "navigation sensors" if p.sensors.navigation.fitted else None),
    (Pipeline.BOTH, lambda p: "a navigation estimator" if p.sensors.estimator is not None else None),
    (Pipeline.BOTH, lambda p: "cameras in the loop" if p.sensors.perception.in_loop else None),
    (Pipeline.BOTH, lambda p: _fallback(actuation_to_core(p.system.plant.actuation, core_module(), p.system.plant.uvms.nv))),
    (Pipeline.LOOP, lambda p: "an observer that needs every sample" if any(not isinstance(o, ProgressReport) for o in p.observers) else None),
    (Pipeline.ALL, _plant),
    (Pipeline.SYSTEM, lambda p: _fallback(p.system.compiled)),
)  # fmt: skip


def why_not_compiled(parts: RunParts, pipeline: Pipeline) -> str | None:
    """Why ``parts`` cannot run in ``pipeline`` (the first reason of `REASONS` that
    applies), or None: every part has a compiled counterpart."""
    for pipelines, check in REASONS:
        if pipeline & pipelines:
            reason = check(parts)
            if reason is not None:
                return reason
    return None
