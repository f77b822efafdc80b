"""Several robots' closed loops, stepped together: each measures, commands and acts alone.

Every robot has its own `ClosedLoop` (its sensors with their own seeded noise, its
controller, its actuation, its log): at each control tick each robot's controller is given
its own measurement only (no state is shared between controllers), then the robots' system
(`uvms_pin.sim.system.robots.Robots`) crosses the period with every robot's applied input
held, the contacts between robots included. The loop is sampled and runs in Python: the
reason is recorded where every run records why it is not compiled
(`uvms_pin.sim.pipeline`, the rollout's ``closed_loop``).
"""

from __future__ import annotations

import dataclasses
import functools
import time
import warnings
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from uvms_pin.control.base import Controller
from uvms_pin.errors import ActuationWarning, ParameterError, SimulationError, StiffModeError
from uvms_pin.hydro.vector import cross3
from uvms_pin.results.robots import RobotRollouts
from uvms_pin.results.status import INTERRUPTED, OK, RunStatus
from uvms_pin.sim.closed_loop import ClosedLoop, _diverged, _finished, _stopped
from uvms_pin.sim.compiled_loop import LoopPath
from uvms_pin.sim.divergence import NUMERICAL_FAILURES, diverged, divergence_context
from uvms_pin.sim.log import RolloutLog
from uvms_pin.sim.pipeline import Pipeline, RunParts, why_not_compiled
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import SensorSuite
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.stiff_modes import without_rigid_pairs
from uvms_pin.sim.system import SystemState
from uvms_pin.sim.system.robots import Robots

__all__ = ["RobotsLoop"]


class RobotsLoop:
    """The robots ``plants`` (named ``names``), each with its controller of
    ``controllers``, in one sea.

    Attributes:
        loops: each robot's closed loop. system: the robots stepped together.
        time_s: now [s]. state: every robot's (q, v), stacked (`SystemState`).
    """

    def __init__(
        self,
        plants: Sequence[Plant],
        names: Sequence[str],
        settings: SimulationSettings,
        controllers: Sequence[Controller],
    ):
        if settings.control_period_s is None:
            raise ParameterError(
                "several robots are stepped period by period: they need a sampled "
                "controller ([control] period_s), not a continuous one"
            )
        self.settings = settings
        plants = [plants[0], *(_without_free_objects(p) for p in plants[1:])]
        self.loops = [
            ClosedLoop(p, settings, c, compiled=False)
            for p, c in zip(plants, controllers, strict=True)
        ]
        self.system = Robots([loop.system for loop in self.loops], names)
        self.time_s = 0.0
        self.state: SystemState | None = None

    def start(self, starts: Sequence[tuple[np.ndarray, np.ndarray]], sensors) -> None:
        """t = 0: every robot's loop started at its (q0, v0) with its ``sensors``, the
        robots refused if they start inside each other, then the contacts between robots
        anchored."""
        for loop, (q0, v0), suite in zip(self.loops, starts, sensors, strict=True):
            try:
                loop.start(q0, v0, suite)
            except StiffModeError as error:  # `Robots` refuses rigid moving contacts
                raise without_rigid_pairs(error) from None
        self.time_s = 0.0
        self.state = self.system.layout.join([loop.state for loop in self.loops])
        self.system.check_apart(self.state)  # no robot started inside another
        self.system.start(self.state)
        # the robots whose cameras fire in the loop see the run's world and the others, as
        # they stand when a camera fires (`_scene_view`)
        names = self.system.names
        for k, loop in enumerate(self.loops):
            if loop.sensors.seeing is None:
                continue
            others = [(names[j], other.plant.uvms) for j, other in enumerate(self.loops) if j != k]
            loop.sensors.start_seeing(
                loop.plant, loop.system.layout, self.settings.control_period_s,
                world=self.loops[0].plant.world, others=others,
            )  # fmt: skip
            loop.sensors.scene_view = functools.partial(self._scene_view, k)

    def tick(self, logged: bool) -> list[np.ndarray]:
        """Each robot measures, commands and actuates on its own, then (if ``logged``)
        every robot's sample is logged (with its contacts against the other robots,
        `Robots.contact_signals`): a controller that raises leaves no robot's sample of the
        tick. The applied inputs."""
        ticked = []
        for loop, held in zip(self.loops, self._held_wrenches(), strict=True):
            measurement, contact = loop.observe(held)
            tau = loop.command(measurement)
            ticked.append((measurement, contact, tau, loop.actuate(tau)))
        if logged:
            contacts = self.system.contact_signals(*self.state)
            for loop, made, own in zip(self.loops, ticked, contacts, strict=True):
                sample = loop.sample(*made)
                loop.notify(replace(sample, signals={**sample.signals, **own}))
        return [made[3] for made in ticked]

    def _scene_view(self, k: int) -> tuple[list, list, list]:
        """What robot ``k``'s cameras in the loop see beyond it, as the robots stand: the
        free objects' poses and the fixtures' positions (the first robot's system holds
        them) and the other robots' q (`SensorSuite.scene_view`)."""
        first = self.loops[0]
        _, *bodies = first.system.layout.split(first.state.q, first.state.v)
        world = first.plant.world
        free = 0 if world is None else len(world.free)
        others = [
            loop.system.layout.split(loop.state.q, loop.state.v)[0][0]
            for j, loop in enumerate(self.loops)
            if j != k
        ]
        return [q for q, _ in bodies[:free]], [q for q, _ in bodies[free:]], others

    def _held_wrenches(self) -> list[np.ndarray | None]:
        """What each robot's force/torque sensor measures of the free objects it holds
        (`SensorConfig.held_object_wrench`), at its end-effector frame's origin, world axes:
        `Robots.object_wrenches` with the moment carried from the world's origin; None for a
        robot whose sensor does not."""
        wanted = [loop.sensors.config.held_object_wrench for loop in self.loops]
        if not any(wanted):
            return [None] * len(self.loops)
        wrenches = np.array(self.system.object_wrenches(*self.state)).reshape(-1, 6)
        at_sensor = np.array(
            [loop.plant.ee_state(loop.q, loop.v)[0] if want else np.zeros(3)
             for loop, want in zip(self.loops, wanted, strict=True)]
        )  # fmt: skip
        wrenches[:, 3:] -= cross3(at_sensor, wrenches[:, :3])  # M_p = M_0 - p x F
        return [wrench if want else None for wrench, want in zip(wrenches, wanted, strict=True)]

    def step(self, taus: list[np.ndarray]) -> None:
        """Every robot one control period on, its input of ``taus`` held.

        Raises SimulationError when the state diverges, naming what stood out for each
        robot at the period's start."""
        t0 = self.time_s
        span = (t0, t0 + self.settings.control_period_s)
        try:
            state = self.system.advance(self.settings.integrator, t0, self.state, taus, span[1])
        except (SimulationError, *NUMERICAL_FAILURES) as exc:
            raise _diverged(*span, exc, self._context(span, taus)) from exc
        if diverged(*state):
            raise _diverged(*span, None, self._context(span, taus))
        for part in state:  # new arrays of the system's: frozen, not copied
            part.setflags(write=False)
        self.state = state
        self.time_s = (
            round(span[1] / self.settings.control_period_s) * self.settings.control_period_s
        )
        for loop, (q_k, v_k) in zip(self.loops, self.system.split(*state), strict=True):
            loop.state = SystemState(q_k, v_k)
            loop.time_s = self.time_s

    def _context(self, span: tuple[float, float], taus: list[np.ndarray]) -> str:
        """What stood out for each robot over ``span`` (`divergence_context`)."""
        return "; ".join(
            f"robot {name}: {divergence_context(loop.plant, span, loop.q, loop.v, tau)}"
            for name, loop, tau in zip(self.system.names, self.loops, taus, strict=True)
        )

    def run(
        self,
        starts: Sequence[tuple[np.ndarray, np.ndarray]],
        sensors: Sequence[SensorSuite],
        logs: Sequence[RolloutLog],
    ) -> RobotRollouts:
        """The whole run: every logged sample to each robot's log; the rollouts. Raises as
        `ClosedLoop.run`, the exception's ``rollout`` the `RobotRollouts` so far."""
        wall_start = time.perf_counter()
        path = LoopPath(reason=self.reason(sensors))
        for loop, log in zip(self.loops, logs, strict=True):
            loop.observers.insert(0, log)
        try:
            self.start(starts, sensors)
            together = self.system.integration(self.settings.integrator)
            together = TOGETHER_COMPILED if together is None else TOGETHER_PYTHON.format(together)
            for loop, log in zip(self.loops, logs, strict=True):
                log.rollout.metadata["world"] = loop.system.log.record(self.settings.integrator)
                log.rollout.metadata["world"]["robots_together"] = together
                log.rollout.metadata["stiff_modes"] = loop.stiff_modes
            self._run_ticks(path)
        except SimulationError as exc:  # a divergence, a funnel left, a controller raising
            rollouts = [_stopped(log, wall_start, exc).rollout for log in logs]
            exc.rollout = self._rollouts(rollouts, path)
            raise
        except KeyboardInterrupt as exc:
            _shared_samples(logs)
            status = RunStatus(INTERRUPTED, str(exc) or "interrupted by the user")
            rollouts = [_finished(log, wall_start, status) for log in logs]
            exc.rollout = self._rollouts(rollouts, path)
            raise
        finally:
            for loop, log in zip(self.loops, logs, strict=True):
                loop.observers.remove(log)
                dropped = loop.plant.actuation.dropped()
                if dropped is not None:
                    warnings.warn(dropped, ActuationWarning, stacklevel=2)
        rollouts = [_finished(log, wall_start, RunStatus(OK)) for log in logs]
        return self._rollouts(rollouts, path)

    def reason(self, sensors: Sequence[SensorSuite]) -> str:
        """Why this run is not compiled (`uvms_pin.sim.pipeline.why_not_compiled`)."""
        loop = self.loops[0]
        parts = RunParts(
            loop.system, self.settings, sensors[0].config, loop.controller, robots=len(self.loops)
        )
        return why_not_compiled(parts, Pipeline.LOOP)

    def _run_ticks(self, path: LoopPath) -> None:
        settings = self.settings
        ticks_per_log = settings.ticks_per_log
        n_ticks = (settings.n_log - 1) * ticks_per_log
        for tick in range(n_ticks + 1):
            path.python_ticks += 1
            taus = self.tick(tick % ticks_per_log == 0)
            if tick == n_ticks:
                return
            self.step(taus)

    def _rollouts(self, rollouts: list, path: LoopPath) -> RobotRollouts:
        for rollout in rollouts:
            rollout.metadata["closed_loop"] = path.record()
        names = self.system.names
        return RobotRollouts(dict(zip(names, rollouts, strict=True)))


def _shared_samples(logs: Sequence[RolloutLog]) -> None:
    """Every log cut to the samples all the robots logged. Ctrl-C or SIGTERM between two
    robots' logs of one tick leaves the first a sample ahead (a controller that raises does
    so before any robot logs the tick: `tick`); the rollouts of one run share their samples
    (its replay poses every robot at each)."""
    common = min(log.count for log in logs)
    for log in logs:
        log.count = common


#: what a run records of the periods in which the robots may touch (`Robots.integration`)
TOGETHER_COMPILED = (
    "while they can touch, one compiled call a period crosses it for every robot (the "
    "integration, the anchors' move, each robot's constraints)"
)
TOGETHER_PYTHON = "while they can touch, the Python integrator steps every robot ({})"


def _without_free_objects(plant: Plant) -> Plant:
    """``plant`` in its world without the free objects: they are the first robot's system's
    (`uvms_pin.sim.system.robots`)."""
    if plant.world is None or not plant.world.free:
        return plant
    return dataclasses.replace(plant, world=dataclasses.replace(plant.world, free=()))
