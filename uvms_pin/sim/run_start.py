"""What every run checks at its start, before it takes a step: the state of its system of
bodies, the robot's own start clear of the fixed world, a sampled controller where the system
is stepped period by period, and the explicit stiff modes at the integrator's step. One place
for the closed loop (`uvms_pin.sim.closed_loop.ClosedLoop.start`) and the vector environments
(`uvms_pin.apps.gym.vector`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.physics.world.overlap import robot_started_apart
from uvms_pin.sim.divergence import singular_mass
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.stiffness import check_stiff_modes
from uvms_pin.sim.system import System, SystemState

__all__ = ["checked_run_start"]


def checked_run_start(
    system: System, q0: np.ndarray, v0: np.ndarray, settings: SimulationSettings
) -> tuple[SystemState, dict[str, Any]]:
    """(the system's state at t = 0 from the robot's (q0, v0), the record of its stiff modes).

    Raises:
        ParameterError: a state of the wrong size or with a non-finite value; free objects or
            joint-limit constraints under a continuous controller.
        InitialOverlapError: a free object, or the robot itself, starts inside another body
            (a fixed object, a fixture's link: `uvms_pin.physics.world.overlap`).
        StiffModeError: a spring-damper integrated explicitly is unstable at the integrator's
            step (`uvms_pin.sim.stiffness`).
        ModelError: the robot's mass matrix at the start is singular (a body without mass,
            added mass or armature about some motion: no step could be taken).
    """
    state = system.initial_state(q0, v0)
    plant = system.plant
    singular = singular_mass(plant.uvms, state.q[: plant.uvms.nq])
    if singular:
        raise ModelError(f"model '{plant.uvms.model.name}': at the start {singular}")
    robot_started_apart(plant.world, plant.uvms.model, state.q[: plant.uvms.nq])
    if system.fixtures:  # nor inside a fixture's link
        robot, *bodies = system.layout.split(state.q, state.v)
        system.moving.check_robot_clear(robot[0], bodies)
    period_by_period = {
        "free objects": bool(system.objects),
        "joint limits as constraints": plant.joint_limits is not None,
    }
    for what, present in period_by_period.items():
        if present and settings.control_period_s is None:
            raise ParameterError(
                f"{what} are stepped with the UVMS period by period: they need a "
                "sampled controller ([control] period_s), not a continuous one"
            )
    return state, check_stiff_modes(system, state, settings.integrator)
