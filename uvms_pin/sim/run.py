"""A run: everything one simulation needs (a `Scenario`), and ``simulate(scenario)``.

A scenario is usually read from a TOML file (`uvms_pin.scenario.load_scenario`); it can as
well be built in code from its parts. `simulate` builds a fresh controller and seeded
sensors, runs the closed loop and returns the rollout.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.control.base import Controller
from uvms_pin.errors import ShortenedRunWarning
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.progress import Progress, callback_or_none, progress_printer
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.closed_loop import simulate_closed_loop
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sample import Observer, ProgressReport
from uvms_pin.sim.sensors import SensorConfig, SensorSuite
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.shortened import max_duration_s, shortened_duration_s, shortened_message

ControllerFactory = Callable[[UVMS], Controller]


@dataclass(frozen=True)
class ControllerSpec:
    """A controller factory that says what it builds: ``spec(uvms) -> Controller``.

    Attributes:
        type: what it is ("none", "ppc", a baseline or "package.module:ClassName").
        params: the parameters the controller is built with, as recorded in rollouts
            (for "ppc": every gain and funnel after defaults and broadcasting).
        build: makes a fresh controller for a loaded model.
    """

    type: str
    params: dict[str, Any] = field(default_factory=dict)
    build: ControllerFactory = field(default=None, repr=False)
    #: built from the scenario file's [controller] table (its ``raw`` then records it)
    from_file: bool = field(default=False, compare=False)

    def __call__(self, uvms: UVMS) -> Controller:
        return self.build(uvms)


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
        shortened_from_s: the scenario's own duration [s] when ``UVMS_PIN_MAX_DURATION_S``
            shortened this run (`shortened`), else None.
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
    shortened_from_s: float | None = None

    @property
    def uvms(self) -> UVMS:
        return self.plant.uvms


def simulate(
    scenario: Scenario,
    *,
    progress: bool | Progress | None = True,
    observers: Sequence[Observer] = (),
) -> Rollout:
    """Run a scenario: fresh sensors (seeded) and controller, closed loop, rollout.

    ``progress``: True (default) shows a tqdm bar (notebook widget in Jupyter; text lines
    when stderr is a file) once the run has lasted `uvms_pin.results.progress.BAR_DELAY_S` of
    wall time, so short runs print nothing; False or None: silent; a callable ``(t_s, duration_s)`` is called after
    every logged sample. ``observers``: called with every logged sample (`Observer`), e.g.
    a live view.

    Raises FunnelViolation / SimulationError with the partial rollout attached as
    ``exc.rollout`` (see `uvms_pin.sim.closed_loop.ClosedLoop.run`). With
    ``UVMS_PIN_MAX_DURATION_S`` set, the run is shortened, and says so (`shortened`).
    """
    scenario = shortened(scenario)
    duration_s = scenario.settings.duration_s
    if progress is True:
        with progress_printer(scenario.name, duration_s) as printer:
            return _simulate(scenario, [*observers, ProgressReport(printer, duration_s)])
    callback = callback_or_none(progress)
    reports = [] if callback is None else [ProgressReport(callback, duration_s)]
    return _simulate(scenario, [*observers, *reports])


def _simulate(scenario: Scenario, observers: list[Observer]) -> Rollout:
    settings = scenario.settings
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    controller = scenario.controller_factory(scenario.uvms)
    record = controller_record(scenario.controller_factory, controller)
    metadata = {
        "scenario": scenario.name,
        "scenario_path": str(scenario.path),
        "description": scenario.description,
        "parameters": recorded_parameters(scenario, record),
        "controller": record,
    }
    if scenario.shortened_from_s is not None:
        metadata["shortened_from_s"] = scenario.shortened_from_s
    return simulate_closed_loop(
        scenario.plant,
        controller,
        sensors,
        scenario.q0,
        scenario.v0,
        settings,
        metadata=metadata,
        observers=observers,
    )


def class_path(controller: object) -> str:
    """``module:QualifiedName`` of an object's class (what a scenario's ``type`` names)."""
    cls = type(controller)
    return f"{cls.__module__}:{cls.__qualname__}"


def controller_record(factory: ControllerFactory, controller: Controller) -> dict[str, Any]:
    """What ran: the class of ``controller`` (``module:QualifiedName``), its type and its
    parameters: a `ControllerSpec`'s, else the class path (what a scenario's ``type`` would
    name) and the controller's public numbers, strings and small arrays (`public_parameters`)."""
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


def recorded_parameters(scenario: Scenario, record: dict[str, Any]) -> dict[str, Any]:
    """The scenario's parameters as they ran: its ``raw`` document, whose [controller] table
    says what the run's controller is when it was not built from that table (a
    ``controller_factory`` set in code)."""
    factory = scenario.controller_factory
    if isinstance(factory, ControllerSpec) and factory.from_file:
        return scenario.raw
    table = {"type": record["type"], "set_in_code": True, **(record["params"] or {})}
    return {**scenario.raw, "controller": table}
