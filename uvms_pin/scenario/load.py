"""Scenario files (TOML) -> a `Scenario`, ready for ``simulate``.

A scenario is read in two stages: the TOML becomes a plain dict (on which dotted
``overrides`` such as ``{"environment.stiffness_N_m": [20, 20, 20]}`` or
``{"initial.joint_positions_rad[3]": 0.5}`` are applied, see `uvms_pin.scenario.overrides`;
that is how ``uvms-pin run --set``, sweeps and robustness tables vary it), then every table
is checked and built by the module of its concept: ``[water]`` (`water`), ``[initial]``
(`initial`), ``[environment]`` and ``[disturbance]`` (`world`), ``[world]`` and ``[joints]``
(`objects`), ``[actuation]``,
``[sensors]``, ``[estimator]`` (`estimator`), ``[integrator]``, ``[control]`` and
``[output]`` (`timing`), ``[controller]`` (`controller`), ``[baselines]`` (`baselines`), ``[task]`` (`task`) and ``[metrics]``
(`metrics`). Unknown keys, wrong types and bad values
raise `ScenarioError` naming the file and the key, or the override when an override set it,
with the closest known key. ``model`` is a path relative to the scenario file or the name of
a shipped model (``"uvms_lbv150"``, ``"lbv150"``). See ``scenarios/*.toml`` for documented
examples.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from uvms_pin.errors import ParameterError, PlausibilityWarning, ScenarioError, UvmsPinError
from uvms_pin.model.resources import resolve_model
from uvms_pin.model.urdf.loaded import loaded_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.kinematics import frame_id_from_name
from uvms_pin.scenario.actuation import build_actuation
from uvms_pin.scenario.baselines import check_baselines
from uvms_pin.scenario.controller import build_controller
from uvms_pin.scenario.controller_parts import ControllerContext
from uvms_pin.scenario.estimator import build_estimator
from uvms_pin.scenario.gripper import build_gripper
from uvms_pin.scenario.initial import build_initial_state
from uvms_pin.scenario.joints import build_joint_friction, build_joint_limits, with_joint_lag
from uvms_pin.scenario.metrics import build_metrics
from uvms_pin.scenario.mpc import check_replan_rate
from uvms_pin.scenario.objects import build_world
from uvms_pin.scenario.overrides import apply_overrides, parse_key_path
from uvms_pin.scenario.robots import robot_documents, robot_overrides
from uvms_pin.scenario.schema import Table
from uvms_pin.scenario.sensors import build_sensors
from uvms_pin.scenario.task import build_task
from uvms_pin.scenario.timing import (
    build_control_period,
    build_integrator,
    build_log_period,
    passive_period,
)
from uvms_pin.scenario.toml import read_toml
from uvms_pin.scenario.water import Water, build_water
from uvms_pin.scenario.world import build_disturbance, build_environment
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.robots_run import RobotsScenario, robot_seed
from uvms_pin.sim.run import Scenario, shortened
from uvms_pin.sim.settings import SimulationSettings, check_log_fits
from uvms_pin.sim.system import System


@dataclass(frozen=True)
class Head:
    """``[scenario]``: name, description, model entry, duration [s], master seed, and the
    names of the model's end-effector and force/torque sensor frames ("": the model's
    ``ee`` and ``ft_sensor``, `load_uvms`'s defaults)."""

    name: str
    description: str
    model: str
    duration_s: float
    seed: int
    ee_frame: str = ""
    sensor_frame: str = ""


def load_scenario(
    path: str | Path, overrides: dict[str, Any] | None = None
) -> Scenario | RobotsScenario:
    """Read a scenario TOML file, apply dotted overrides and build the objects.

    Args:
        path: the scenario file.
        overrides: dotted key (optionally ``[i]``-indexed) -> value, e.g.
            ``{"environment.stiffness_N_m": [20, 20, 20], "initial.joint_positions_rad[3]":
            0.5}`` (`uvms_pin.scenario.overrides`).

    With the environment variable ``UVMS_PIN_MAX_DURATION_S`` set, a longer scenario is
    shortened to it, with a warning (`uvms_pin.sim.shortened`).

    Raises:
        ScenarioError: naming the file and the key, or the override that set a bad value.
    """
    if not isinstance(path, str | Path):
        raise ParameterError(f"path must be a scenario file's path, got {path!r}")
    path = Path(path)
    return scenario_from_dict(read_toml(path, ScenarioError), path, overrides)


def scenario_from_dict(
    data: Mapping[str, Any], path: str | Path = "<dict>", overrides: dict[str, Any] | None = None
) -> Scenario | RobotsScenario:
    """A scenario built in code: ``data`` is what the TOML file would hold, as nested dicts
    (``{"scenario": {"model": "uvms_lbv150", "duration_s": 5}, "water": {...}}``), checked
    key by key exactly as a file is (`load_scenario` reads a file and calls this). ``path``:
    as if read from this file (relative model paths, your own controllers and metrics
    resolve in its directory: the working directory by default). ``overrides``: dotted
    keys, as ``uvms-pin run --set``. ``data`` is copied (`apply_overrides`), never changed.

    Raises:
        ScenarioError: naming the key (and ``path``) of a bad value.

    A document with ``[[robots]]`` gives a `RobotsScenario` (`uvms_pin.scenario.robots`).
    """
    path = Path(path)
    source = str(path)
    if not isinstance(data, Mapping):
        raise ScenarioError(
            f"{source}: a scenario is a mapping of tables (what a TOML file holds), got "
            f"{type(data).__name__}"
        )
    raw = apply_overrides(dict(data), overrides)
    overridden = {parse_key_path(text).key: text for text in overrides or {}}
    try:
        documents = robot_documents(raw, source, overridden)
        if documents is not None:  # [[robots]]: several robots in one sea
            return _robots(raw, path, documents, overridden)
        return shortened(_build(raw, path, Table(raw, "", source, overridden)))
    except ScenarioError:
        raise
    except UvmsPinError as exc:
        error = ScenarioError(f"{source}: {exc}")
        error.user_traceback = exc.user_traceback
        raise error from exc


def _robots(
    raw: dict[str, Any], path: Path, documents: list, overridden: dict[str, str]
) -> RobotsScenario:
    """The scenario of several robots: each robot's document read as a single robot's
    (`uvms_pin.scenario.robots`), its sensors' seed its own (`robot_seed`)."""
    robots = []
    for k, (name, document) in enumerate(documents):
        own = robot_overrides(overridden, k)
        try:
            robot = _build(document, path, Table(document, "", str(path), own))
        except ScenarioError as exc:
            raise ScenarioError(f"robot '{name}' ([[robots]] entry {k}): {exc}") from exc
        seeded = replace(robot.settings, seed=robot_seed(robot.settings.seed, k))
        robots.append(shortened(replace(robot, settings=seeded)))
    head = robots[0]
    if len(robots) > 1 and head.settings.control_period_s is None:
        raise ScenarioError(
            f"{path}: [[robots]]: several robots are stepped period by period: they need a "
            "sampled controller ([control] period_s)"
        )
    names = tuple(name for name, _ in documents)
    return RobotsScenario(head.name, head.description, path, raw, tuple(robots), names)


def _build(raw: dict[str, Any], path: Path, top: Table) -> Scenario:
    scenario = top.table_or_empty("scenario")
    head = _head(scenario, path)
    water = build_water(top.table_or_empty("water"), head.seed)
    uvms = _model(head, water, path, scenario)
    q0, v0 = build_initial_state(top.table_or_empty("initial"), uvms)
    task = build_task(top.table("task"), uvms, q0)
    contact = build_environment(top.table("environment"), uvms)
    world = build_world(top.table("world"), uvms, path.parent)
    disturbance = build_disturbance(top.table("disturbance"))
    integrator, backend = build_integrator(top.table_or_empty("integrator"))
    log_period = build_log_period(top.table_or_empty("output"))
    control_period = passive_period(
        build_control_period(top.table_or_empty("control")),
        integrator,
        log_period,
        passive=_controller_type(raw) == "none",
    )
    joints = top.table_or_empty("joints")
    joint_stops, joint_limits = build_joint_limits(joints, uvms, control_period is not None)
    friction, coulomb = build_joint_friction(joints, uvms, control_period is not None)
    actuation = with_joint_lag(joints, build_actuation(top.table("actuation"), uvms), uvms)
    joints.finish()
    sensor_config = build_sensors(top.table_or_empty("sensors"), water.density_kg_m3, world)
    estimator = build_estimator(top.table("estimator"), sensor_config.navigation)
    sensor_config = replace(sensor_config, estimator=estimator)
    if control_period is None and sensor_config.navigation.fitted:
        raise top.error(
            "sensors", "navigation sensors sample at the control ticks: set [control] period_s"
        )
    gripper = build_gripper(top.table("gripper"), uvms, control_period)
    arm_uvms = uvms if gripper is None else gripper.arm_uvms
    context = ControllerContext(arm_uvms, path.parent, task, actuation)
    controller = build_controller(top.table("controller"), context)
    if gripper is not None:
        controller = gripper.wrap(controller).checked(uvms)
    check_replan_rate(top, raw.get("controller"), control_period)
    extra_metrics = build_metrics(top.table("metrics"), path.parent)
    check_baselines(top.table("baselines"), (raw.get("controller") or {}).get("type"))
    top.finish()
    plant = Plant(
        uvms,
        water.current_world_m_s,
        contact,
        disturbance,
        actuation,
        water.flow,
        backend,
        free_surface=water.free_surface,
        stop_at_surface=water.stop_at_surface,
        joint_friction=friction,
        world=world,
        joint_stops=joint_stops,
        joint_limits=joint_limits,
        joint_coulomb=coulomb,
    )
    try:
        settings = SimulationSettings(
            head.duration_s, integrator, log_period, control_period, head.seed
        )
        check_log_fits(settings, uvms.nq, uvms.nv, System(plant).log.n_columns)
    except ParameterError as exc:
        raise ScenarioError(f"{top.source}: {exc}") from exc
    return Scenario(
        head.name,
        head.description,
        path,
        raw,
        plant,
        controller,
        sensor_config,
        q0,
        v0,
        settings,
        extra_metrics=extra_metrics,
        task=task,
        jaw_servo=None if gripper is None else gripper.servo,
    )


def _controller_type(raw: dict[str, Any]) -> Any:
    """``[controller] type`` as written ("none" without the table), before the table is
    read: a table that is no table is refused when it is read, naming it."""
    controller = raw.get("controller")
    return controller.get("type", "none") if isinstance(controller, dict) else "none"


def _head(t: Table, path: Path) -> Head:
    head = Head(
        name=t.string("name", path.stem),
        description=t.string("description", ""),
        model=t.string("model"),
        duration_s=t.number("duration_s", positive=True),
        seed=t.seed("seed", 0),
        ee_frame=t.string("ee_frame", ""),
        sensor_frame=t.string("sensor_frame", ""),
    )
    t.finish()
    return head


def _model(head: Head, water: Water, path: Path, scenario: Table) -> UVMS:
    """The model ``[scenario] model`` names, in water of ``[water]``'s density."""
    try:
        model_path = resolve_model(head.model, path.parent)
    except ParameterError as exc:
        raise scenario.error("model", str(exc)) from None
    with warnings.catch_warnings():  # the density was judged as [water] density_kg_m3
        warnings.simplefilter("ignore", PlausibilityWarning)
        # parsed once per process (a study loads the same model for every run)
        uvms = loaded_uvms(model_path, water_density_kg_m3=water.density_kg_m3)
    frames = {}
    for key, name in (("ee_frame", head.ee_frame), ("sensor_frame", head.sensor_frame)):
        if name:  # a model whose frames have other names (an imported ROS model's)
            try:
                frames[f"{key}_id"] = frame_id_from_name(uvms.model, name, "frame")
            except ParameterError as exc:
                raise scenario.error(key, str(exc)) from None
    return replace(uvms, **frames) if frames else uvms
