"""The core's batch of plants (src/uvms_core/batch_plant.hpp) of a `Plant`."""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType
from typing import Any

from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.sim.compiled.actuation import actuation_to_core
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.integrators import Integrator

__all__ = ["batch_to_core"]


def batch_to_core(
    plant: Any,
    integrator: Integrator,
    period_s: float,
    sample_period_s: float,
    noise_rows: int,
    silent: Sequence[bool],
    num_envs: int,
    num_threads: int,
    core: ModuleType,
):
    """``num_envs`` copies of ``plant``'s compiled plant (its prototype, as attached now)
    advanced by ``integrator`` over ``period_s`` [s] with its actuation, on ``num_threads``
    threads, and their sensor noise: tables of ``noise_rows`` samples every
    ``sample_period_s`` [s] per channel, none for a ``silent`` one. The pipeline's choice
    (`uvms_pin.sim.pipeline`) has checked that every part has its counterpart."""
    parts = (
        integrator_to_core(integrator, core),
        actuation_to_core(plant.actuation, core, plant.uvms.nv),
    )
    fallback = next((p for p in parts if isinstance(p, Fallback)), None)
    if fallback is not None:  # (the pipeline's choice refuses these first)
        raise ParameterError(f"the batched plant does not simulate {fallback.reason}")
    noise = core.BatchNoise()
    noise.sample_period_s = float(sample_period_s)
    noise.rows = int(noise_rows)
    noise.silent = [int(s) for s in silent]
    return core.BatchPlant(
        plant.compiled, parts[0], float(period_s), parts[1], noise, num_envs, num_threads
    )
