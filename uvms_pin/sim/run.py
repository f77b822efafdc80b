"""A run: everything one simulation needs (a `Scenario`), and ``simulate(scenario)``.

A scenario is usually read from a TOML file (`uvms_pin.scenario.load_scenario`) or from
nested dicts (`uvms_pin.scenario.scenario_from_dict`): the scenario layer builds it; it can
as well be built in code from its parts. `simulate` builds a fresh controller and seeded
sensors, runs the closed loop and returns the rollout.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.control.base import Controller
from uvms_pin.control.jaw_servo import JawServo
from uvms_pin.control.spec import ControllerFactory, ControllerSpec
from uvms_pin.control.tracking.task import TrackingTask
from uvms_pin.errors import ParameterError, ScenarioError, ShortenedRunWarning, SimulationError
from uvms_pin.model.uvms import UVMS
from uvms_pin.perception.scene import scene_of
from uvms_pin.perception.suite import check_mounts, perceive
from uvms_pin.results.extra_metrics import DIRECTORY_KEY, REFERENCES_KEY
from uvms_pin.results.progress import Progress, callback_or_none, progress_printer
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.closed_loop import simulate_closed_loop
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sample import Observer, ProgressReport
from uvms_pin.sim.sensors import SensorConfig, SensorSuite
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.shortened import max_duration_s, shortened_duration_s, shortened_message
from uvms_pin.sim.task_record import record_task


@dataclass
class Scenario:
    """Everything one run needs.

    Attributes:
        name, description: what the run is.
        path: the file it came from (relative model paths and custom controllers resolve
            next to it). raw: the scenario's parameters (recorded in rollouts).
        plant: UVMS + water + environment + disturbance + actuation.
        controller_factory: builds a fresh controller for the plant's UVMS (a
            `ControllerSpec` records its type and parameters in the rollout).
        sensor_config: noise of the measurements.
        q0, v0: initial state. settings: integrator, periods, duration, seed.
        extra_metrics: your own metric functions, ``"package.module:function"``
            (`uvms_pin.results.extra_metrics`), resolved next to ``path``.
        task: a tracking task (``[task]``): its reference and true pose are added to the
            rollout (`uvms_pin.sim.task_record`), and its metrics to ``metrics()``.
        shortened_from_s: the scenario's own duration [s] when ``UVMS_PIN_MAX_DURATION_S``
            shortened this run (`shortened`), else None.
        jaw_servo: the servo of the model's jaw joints (``[gripper]``), None when the model
            has none or the controller commands them (``by_controller``). The controller
            factory already includes it; a policy that replaces the controller (the gym
            environments) drives the other joints and leaves the jaw to it.
    """

    name: str
    description: str
    path: Path
    raw: dict[str, Any]
    plant: Plant
    controller_factory: ControllerFactory
    sensor_config: SensorConfig
    q0: np.ndarray
    v0: np.ndarray
    settings: SimulationSettings
    extra_metrics: tuple[str, ...] = ()
    task: TrackingTask | None = None
    shortened_from_s: float | None = None
    jaw_servo: JawServo | None = None

    @property
    def uvms(self) -> UVMS:
        return self.plant.uvms


def simulate(
    scenario: Scenario,
    *,
    progress: bool | Progress | None = True,
    observers: Sequence[Observer] = (),
    controller: Controller | None = None,
    compiled_loop: bool = True,
) -> Rollout:
    """Run a scenario: fresh sensors (seeded) and controller, closed loop, rollout.

    ``progress``: True (default) shows a tqdm bar (notebook widget in Jupyter; text lines
    when stderr is a file) once the run has lasted `uvms_pin.results.progress.BAR_DELAY_S` of
    wall time, so short runs print nothing; False or None: silent; a callable ``(t_s, duration_s)`` is called after
    every logged sample. ``observers``: called with every logged sample (`Observer`), e.g.
    a live view. ``controller``: an instance to run instead of the one the scenario builds
    (it is reset first; the rollout records its class, with type and parameters None).
    ``compiled_loop``: False runs a sampled loop tick by tick in Python even when the core
    could run it (`uvms_pin.sim.compiled_loop`; the rollout's ``closed_loop`` metadata says
    which path ran).

    Raises FunnelViolation / SimulationError with the partial rollout attached as
    ``exc.rollout`` (see `uvms_pin.sim.closed_loop.ClosedLoop.run`). With
    ``UVMS_PIN_MAX_DURATION_S`` set, the run is shortened, and says so (`shortened`).
    """
    if isinstance(scenario, str | Path):
        raise ParameterError(
            f"simulate takes a Scenario, got the path {str(scenario)!r}: load it first, "
            "uvms_pin.simulate(uvms_pin.load_scenario(path))"
        )
    if not hasattr(scenario, "sensor_config"):  # a RobotsScenario says what to run instead
        raise ParameterError(
            f"simulate takes a Scenario (uvms_pin.load_scenario), got {type(scenario).__name__}"
        )
    scenario = shortened(scenario)
    duration_s = scenario.settings.duration_s
    if progress is True:
        with progress_printer(scenario.name, duration_s) as printer:
            reports = [ProgressReport(printer, duration_s)]
            return _simulate(scenario, [*observers, *reports], controller, compiled_loop)
    callback = callback_or_none(progress)
    reports = [] if callback is None else [ProgressReport(callback, duration_s)]
    return _simulate(scenario, [*observers, *reports], controller, compiled_loop)


def run_parts(
    scenario: Scenario, given: Controller | None = None
) -> tuple[Controller, SensorSuite, dict[str, Any]]:
    """What a run of ``scenario`` starts from: (a fresh controller, or the instance
    ``given``; its sensors, seeded with the settings' seed; its rollout's metadata)."""
    settings = scenario.settings
    check_mounts(
        scenario.sensor_config.perception,
        scenario.uvms.model,
        settings.duration_s,
        settings.log_period_s,
        settings.control_period_s,
    )
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    if given is not None and not isinstance(given, Controller):
        raise ParameterError(
            f"controller must be a uvms_pin Controller instance, got {type(given).__name__}"
        )
    controller = scenario.controller_factory(scenario.uvms) if given is None else given
    record = controller_record(scenario.controller_factory if given is None else None, controller)
    metadata = {
        "scenario": scenario.name,
        "scenario_path": str(scenario.path),
        "description": scenario.description,
        "parameters": recorded_parameters(scenario, record, instance=given is not None),
        "controller": record,
        REFERENCES_KEY: list(scenario.extra_metrics),
        DIRECTORY_KEY: str(Path(scenario.path).parent.resolve()),
    }
    if scenario.shortened_from_s is not None:
        metadata["shortened_from_s"] = scenario.shortened_from_s
    return controller, sensors, metadata


def _simulate(
    scenario: Scenario, observers: list[Observer], given: Controller | None, compiled: bool
) -> Rollout:
    settings = scenario.settings
    if scenario.sensor_config.held_object_wrench:
        raise ScenarioError(
            f"{scenario.path}: [sensors] held_object_wrench is measured in runs of several "
            "robots ([[robots]]) only"
        )
    controller, sensors, metadata = run_parts(scenario, given)
    try:
        rollout = simulate_closed_loop(
            scenario.plant,
            controller,
            sensors,
            scenario.q0,
            scenario.v0,
            settings,
            metadata=metadata,
            observers=observers,
            compiled=compiled,
        )
    except (SimulationError, KeyboardInterrupt) as exc:  # the partial rollout too
        partial = getattr(exc, "rollout", None)
        if scenario.task is not None and partial is not None:
            record_task(partial, scenario.task, scenario.uvms)
        if partial is not None:
            _perceive(partial, scenario)
        raise
    if scenario.task is not None:
        record_task(rollout, scenario.task, scenario.uvms)
    _perceive(rollout, scenario)
    return rollout


def _perceive(rollout: Rollout, scenario: Scenario) -> None:
    """The scenario's cameras and sonars fired over the rollout's logged states
    (`uvms_pin.perception.suite`); nothing without them."""
    spec = scenario.sensor_config.perception
    if not spec.fitted or len(rollout) == 0:
        return
    plant = scenario.plant
    world = plant.world
    n_objects = len(world.free) if world is not None and "free_objects" in rollout.signals else 0
    scene = scene_of(plant.uvms, world, surface=plant.free_surface, backend=plant.backend)
    perceive(rollout, spec, scene, scenario.settings.seed, n_objects)


def class_path(controller: object) -> str:
    """``module:QualifiedName`` of an object's class (what a scenario's ``type`` names)."""
    cls = type(controller)
    return f"{cls.__module__}:{cls.__qualname__}"


def controller_record(factory: ControllerFactory | None, controller: Controller) -> dict[str, Any]:
    """What ran: the class of ``controller`` (``module:QualifiedName``), its type and its
    parameters: a `ControllerSpec`'s, else (another factory, or an instance given to
    `simulate`: ``factory`` None) the class path (what a scenario's ``type`` would name)
    and the controller's public numbers, strings and small arrays (`public_parameters`)."""
    if isinstance(factory, ControllerSpec):
        return {"class": class_path(controller), "type": factory.type, "params": factory.params}
    return {
        "class": class_path(controller),
        "type": class_path(controller),
        "params": public_parameters(controller),
    }


def shortened(scenario: Scenario, environ: Mapping[str, str] | None = None) -> Scenario:
    """``scenario``, or a copy shortened to the cap ``UVMS_PIN_MAX_DURATION_S`` sets in
    ``environ`` (default: the process's environment; `uvms_pin.sim.shortened`).

    A shortened copy has the new duration in its settings and parameters, its own duration
    in ``shortened_from_s``, and a `ShortenedRunWarning` says so. A scenario that is not
    longer than the cap comes back unchanged, without a warning.

    Raises:
        ParameterError: the variable holds no positive number.
    """
    cap_s = max_duration_s(environ)
    settings = scenario.settings
    if cap_s is None:
        return scenario
    duration_s = shortened_duration_s(settings.duration_s, settings.log_period_s, cap_s)
    if duration_s is None:
        return scenario
    own_s = scenario.shortened_from_s or settings.duration_s
    warnings.warn(
        ShortenedRunWarning(shortened_message(str(scenario.path), own_s, duration_s, cap_s)),
        stacklevel=2,
    )
    head = {**scenario.raw.get("scenario", {}), "duration_s": duration_s}
    return dataclasses.replace(
        scenario,
        raw={**scenario.raw, "scenario": head},
        settings=dataclasses.replace(settings, duration_s=duration_s),
        shortened_from_s=own_s,
    )


def public_parameters(controller: object) -> dict[str, Any]:
    """The controller's public attributes that are numbers, strings, booleans or numeric
    arrays of at most 64 entries (as lists): what can be recorded of a controller built in
    code."""
    out: dict[str, Any] = {}
    for name, value in vars(controller).items():
        if name.startswith("_"):
            continue
        if isinstance(value, bool | int | float | str):
            out[name] = value
        elif isinstance(value, np.ndarray) and value.dtype.kind in "biuf" and value.size <= 64:
            out[name] = value.tolist()
    return out


def recorded_parameters(
    scenario: Scenario, record: dict[str, Any], *, instance: bool = False
) -> dict[str, Any]:
    """The scenario's parameters as they ran: its ``raw`` document, whose [controller] table
    says what the run's controller is when it was not built from that table (a
    ``controller_factory`` set in code, or an ``instance`` given to `simulate`)."""
    factory = scenario.controller_factory
    if isinstance(factory, ControllerSpec) and factory.from_file and not instance:
        return scenario.raw
    table = {"type": record["type"], "set_in_code": True, **(record["params"] or {})}
    return {**scenario.raw, "controller": table}
