"""A run of several robots: a `RobotsScenario` (one `Scenario` per robot, sharing the
water, the world and the run's timing), and ``simulate_robots(scenario)``.

Each robot's scenario is what a single-robot scenario of its tables would be, but for its
seed: robot k's sensors draw their noise from `robot_seed` (the scenario's seed and k),
recorded in its rollout; the water (a sea state's phases) keeps the scenario's seed, the
same for every robot. One robot alone runs as a single-robot scenario does (the same
rollout, bit for bit); several run in `uvms_pin.sim.robots_loop`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from uvms_pin.errors import ParameterError, ScenarioError, SimulationError
from uvms_pin.perception.scene import scene_of
from uvms_pin.perception.suite import SceneLog, fixture_positions, object_poses, perceive
from uvms_pin.results.progress import Progress, callback_or_none, progress_printer
from uvms_pin.results.robots import RobotRollouts
from uvms_pin.sim.log import RolloutLog, described_columns, run_metadata
from uvms_pin.sim.robots_loop import RobotsLoop
from uvms_pin.sim.run import (
    Scenario,
    run_parts,
    shortened,
    simulate,
)
from uvms_pin.sim.sample import ProgressReport
from uvms_pin.sim.sensors import SensorSuite
from uvms_pin.sim.settings import check_log_fits
from uvms_pin.sim.task_record import record_task

__all__ = ["RobotsScenario", "robot_seed", "shortened_robots", "simulate_robots"]

#: what a single robot's scenario has and several robots have each (`RobotsScenario`)
_ONE_ROBOTS = frozenset(
    ("plant", "controller_factory", "sensor_config", "q0", "v0", "uvms", "task", "extra_metrics",
     "shortened_from_s")
)  # fmt: skip
#: the odd constant of Fibonacci hashing, 2^64 / golden ratio: the seeds of robots 0, 1, ...
#: are spread over the seeds' range
_SPREAD = 0x9E3779B97F4A7C15
_SEEDS = 2**63


def robot_seed(seed: int, index: int) -> int:
    """Robot ``index``'s seed: (seed + index * 0x9E3779B97F4A7C15) mod 2^63; robot 0's is
    the scenario's ``seed`` itself."""
    return (seed + index * _SPREAD) % _SEEDS


@dataclass
class RobotsScenario:
    """Several robots in one sea.

    Attributes:
        name, description, path, raw: as a `Scenario`'s (``raw`` the whole document).
        robots: each robot's scenario (its plant, controller, sensors, start, task, its
            settings with its own seed), in the document's order. names: the robots'.
    """

    name: str
    description: str
    path: Path
    raw: dict[str, Any]
    robots: tuple[Scenario, ...]
    names: tuple[str, ...]

    @property
    def settings(self):
        """The run's timing (the first robot's settings: every robot's but for the seed)."""
        return self.robots[0].settings

    def __getattr__(self, name: str) -> Any:
        """A single robot's part asked of several robots (a study, a comparison, the gym
        environments run one robot): a `ScenarioError` saying so."""
        if name in _ONE_ROBOTS:
            raise ScenarioError(
                f"{self.path}: a scenario of several robots ([[robots]]) has no single "
                f"'{name}': run it with uvms_pin.simulate_robots or `uvms-pin run`, or take "
                "one robot's scenario (RobotsScenario.robot(name))"
            )
        raise AttributeError(name)

    def robot(self, name: str) -> Scenario:
        """The scenario of the robot ``name``."""
        if name not in self.names:
            raise ParameterError(f"no robot '{name}' in this scenario (robots: {list(self.names)})")
        return self.robots[self.names.index(name)]


def shortened_robots(
    scenario: RobotsScenario, environ: Mapping[str, str] | None = None
) -> RobotsScenario:
    """``scenario`` with every robot's run shortened as `uvms_pin.sim.run.shortened` says
    (``UVMS_PIN_MAX_DURATION_S`` of ``environ``)."""
    return replace(scenario, robots=tuple(shortened(r, environ) for r in scenario.robots))


def simulate_robots(
    scenario: RobotsScenario,
    *,
    controllers: Sequence | None = None,
    progress: bool | Progress | None = None,
) -> RobotRollouts:
    """Run every robot of ``scenario``, each with a fresh controller (or the instances
    ``controllers``, one per robot, reset first) and its own seeded sensors; ``progress``
    as `uvms_pin.simulate`'s (True: a progress bar; a callable ``(t_s, duration_s)`` called
    after every logged sample; False or None, the default: silent).

    Raises FunnelViolation / SimulationError with the rollouts so far attached as
    ``exc.rollout`` (a `RobotRollouts`)."""
    if not isinstance(scenario, RobotsScenario):
        raise ParameterError(
            f"simulate_robots takes a scenario of several robots ([[robots]]), got "
            f"{type(scenario).__name__} {getattr(scenario, 'name', '')!r}: run a single "
            "robot's scenario with uvms_pin.simulate"
        )
    if progress is True:
        with progress_printer(scenario.name, scenario.settings.duration_s) as printer:
            return _simulate_robots(scenario, controllers, printer)
    return _simulate_robots(scenario, controllers, callback_or_none(progress))


def _simulate_robots(
    scenario: RobotsScenario, controllers: Sequence | None, progress: Progress | None
) -> RobotRollouts:
    robots = scenario.robots
    if controllers is not None and (
        not isinstance(controllers, Sequence) or isinstance(controllers, str)
    ):
        raise ParameterError(
            f"controllers must be a list of one Controller (or None) per robot, got {controllers!r}"
        )
    given = list(controllers) if controllers is not None else [None] * len(robots)
    if len(given) != len(robots):
        raise ParameterError(f"{len(given)} controllers for {len(robots)} robots")
    if len(robots) == 1:  # one robot: the single-robot run itself
        try:
            rollout = simulate(robots[0], progress=progress or False, controller=given[0])
        except (SimulationError, KeyboardInterrupt) as exc:  # the partial rollout too
            if getattr(exc, "rollout", None) is not None:
                exc.rollout = RobotRollouts({scenario.names[0]: exc.rollout})
            raise
        return RobotRollouts({scenario.names[0]: rollout})
    parts = []
    for name, robot, controller in zip(scenario.names, robots, given, strict=True):
        try:
            parts.append(_parts(robot, controller))
        except ParameterError as exc:  # which robot's sensors or controller
            raise ParameterError(f"robot '{name}': {exc}") from exc
    loop = RobotsLoop(
        [r.plant for r in robots], scenario.names, scenario.settings, [p[0] for p in parts]
    )
    logs = []
    for robot, (_, sensors, metadata), own in zip(robots, parts, loop.loops, strict=True):
        plant, settings = robot.plant, robot.settings
        pairs = loop.system.contact_pair_names(len(logs))
        columns = own.system.log.n_columns + 9 * len(pairs)
        check_log_fits(settings, plant.uvms.nq, plant.uvms.nv, columns)
        meta = {**metadata, **run_metadata(plant, settings)}
        if pairs:  # the signal robot_contact's pairs (`Robots.contact_signals`)
            meta["robot_contact_pairs"] = pairs
        if sensors.navigation is not None:
            meta["signal_units"].update(described_columns(sensors.navigation.signal_columns()))
        logs.append(
            RolloutLog(plant.uvms, settings.n_log, meta, backend=plant.backend, system=own.system)
        )
    if progress is not None:  # the first robot's samples are every robot's times
        loop.loops[0].observers.append(ProgressReport(progress, scenario.settings.duration_s))
    starts = [(r.q0, r.v0) for r in robots]
    try:
        out = loop.run(starts, [p[1] for p in parts], logs)
    except (SimulationError, KeyboardInterrupt) as exc:  # the partial rollouts too
        if getattr(exc, "rollout", None) is not None:
            _record_tasks(scenario, exc.rollout)
            _perceive_robots(scenario, exc.rollout)  # what the sensors saw until the stop
        raise
    _record_tasks(scenario, out)
    _perceive_robots(scenario, out)
    return out


def _parts(robot: Scenario, given) -> tuple[Any, SensorSuite, dict[str, Any]]:
    """(the robot's controller, its seeded sensors, its rollout's metadata): a single
    robot's (`run_parts`); its cameras and sonars fire after the run too
    (`_perceive_robots`), its cameras in the loop see the other robots
    (`uvms_pin.sim.robots_loop`)."""
    return run_parts(robot, given)


def _perceive_robots(scenario: RobotsScenario, rollouts: RobotRollouts) -> None:
    """Each robot's cameras and sonars fired over the run's logged states: in the world
    the first robot's rollout logs (its free objects, its fixtures), seeing the other
    robots where their rollouts put them (`uvms_pin.perception.suite`)."""
    first = rollouts.robot(scenario.names[0])
    if len(first) == 0:
        return
    for k, (name, robot) in enumerate(zip(scenario.names, scenario.robots, strict=True)):
        spec = robot.sensor_config.perception
        if not spec.fitted:
            continue
        plant, world = robot.plant, robot.plant.world
        others = [j for j in range(len(scenario.robots)) if j != k]
        scene = scene_of(
            plant.uvms,
            world,
            surface=plant.free_surface,
            backend=plant.backend,
            others=[(scenario.names[j], scenario.robots[j].uvms) for j in others],
        )
        free = len(world.free) if world is not None and "free_objects" in first.signals else 0
        log = SceneLog(
            rollouts.robot(name).q,
            object_poses(first, free),
            fixture_positions(first, scene.fixture_names),
            [rollouts.robot(scenario.names[j]).q for j in others],
        )
        perceive(rollouts.robot(name), spec, scene, robot.settings.seed, free, log)


def _record_tasks(scenario: RobotsScenario, rollouts: RobotRollouts) -> None:
    for name, robot in zip(scenario.names, scenario.robots, strict=True):
        if robot.task is not None and len(rollouts.robot(name)):
            record_task(rollouts.robot(name), robot.task, robot.uvms)
