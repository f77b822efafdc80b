"""Scenario files (TOML) -> the objects of one run; ``simulate(scenario)`` runs it.

A scenario is read in two stages: the TOML becomes a plain dict (on which dotted
``overrides`` such as ``{"environment.stiffness_N_m": [20, 20, 20]}`` are applied, which is
how sweeps and robustness tables vary it), then every table is checked and turned into
objects. Unknown keys, wrong types and bad values raise `ScenarioError` naming the file and
the key. See ``scenarios/*.toml`` for documented examples.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import tomllib

from uvms_pin.actuation import Actuation, Thruster, ThrustersAndJointLimits, Unlimited
from uvms_pin.controllers.base import Controller, ZeroController
from uvms_pin.controllers.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.core import BACKENDS
from uvms_pin.environment import CompliantPlane, ContactModel, LinearSpring, SinusoidalDisturbance
from uvms_pin.errors import ParameterError, ScenarioError, UvmsPinError
from uvms_pin.integrators import RK4, Adaptive, Integrator, SemiImplicitEuler
from uvms_pin.model import UVMS, load_uvms
from uvms_pin.plant import Plant
from uvms_pin.rollout import Rollout
from uvms_pin.sensors import NoiseSpec, SensorConfig, SensorSuite
from uvms_pin.simulate import Progress, SimulationSettings, simulate_closed_loop

ControllerFactory = Callable[[UVMS], Controller]


class _Table:
    """One TOML table, read key by key; leftovers are reported as unknown keys."""

    def __init__(self, data: Any, where: str, source: str):
        if not isinstance(data, dict):
            raise ScenarioError(f"{source}: [{where}] must be a table, got {type(data).__name__}")
        self._data = dict(data)
        self._where = where
        self._source = source

    def _err(self, key: str, msg: str) -> ScenarioError:
        where = f"{self._where}.{key}" if self._where else key
        return ScenarioError(f"{self._source}: {where}: {msg}")

    def has(self, key: str) -> bool:
        return key in self._data

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        positive: bool = False,
        nonneg: bool = False,
    ) -> float:
        if key not in self._data:
            if default is None:
                raise self._err(key, "is required")
            return float(default)
        value = self._data.pop(key)
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise self._err(key, f"must be a finite number, got {value!r}")
        if positive and value <= 0:
            raise self._err(key, f"must be positive, got {value}")
        if nonneg and value < 0:
            raise self._err(key, f"must be >= 0, got {value}")
        return float(value)

    def optional_number(self, key: str, **kw) -> float | None:
        return self.number(key, **kw) if key in self._data else None

    def integer(self, key: str, default: int) -> int:
        value = self._data.pop(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self._err(key, f"must be an integer, got {value!r}")
        return value

    def string(
        self, key: str, default: str | None = None, choices: tuple[str, ...] | None = None
    ) -> str:
        if key not in self._data:
            if default is None:
                raise self._err(key, "is required")
            return default
        value = self._data.pop(key)
        if not isinstance(value, str):
            raise self._err(key, f"must be a string, got {value!r}")
        if choices is not None and value not in choices:
            raise self._err(key, f"must be one of {', '.join(choices)}, got '{value}'")
        return value

    def vector(
        self, key: str, size: int | None, default=None, *, nonneg: bool = False
    ) -> np.ndarray:
        if key not in self._data:
            if default is None:
                raise self._err(key, "is required")
            return np.array(default, dtype=float)
        value = self._data.pop(key)
        if isinstance(value, int | float) and not isinstance(value, bool) and size is not None:
            value = [value] * size
        if not isinstance(value, list) or not all(
            isinstance(x, int | float) and not isinstance(x, bool) for x in value
        ):
            raise self._err(key, f"must be a list of numbers, got {value!r}")
        arr = np.array(value, dtype=float)
        if size is not None and arr.size != size:
            raise self._err(key, f"needs {size} numbers, got {arr.size}")
        if not np.all(np.isfinite(arr)):
            raise self._err(key, "has a non-finite value")
        if nonneg and np.any(arr < 0):
            raise self._err(key, f"must be >= 0, got {arr.tolist()}")
        return arr

    def table(self, key: str) -> _Table | None:
        if key not in self._data:
            return None
        where = f"{self._where}.{key}" if self._where else key
        return _Table(self._data.pop(key), where, self._source)

    def pop_raw(self, key: str, default: Any = None) -> Any:
        return self._data.pop(key, default)

    def finish(self) -> None:
        if self._data:
            keys = ", ".join(sorted(self._data))
            raise ScenarioError(f"{self._source}: [{self._where}] has unknown key(s): {keys}")


@dataclass
class Scenario:
    """Everything one run needs, built from a scenario file.

    Attributes:
        name, description: from [scenario].
        path: the file it came from. raw: the dict after overrides (recorded in rollouts).
        plant: UVMS + water + environment + disturbance.
        controller_factory: builds a fresh controller for the plant's UVMS.
        sensor_config: noise of the measurements.
        q0, v0: initial state. settings: integrator, periods, duration, seed.
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

    @property
    def uvms(self) -> UVMS:
        return self.plant.uvms


def apply_overrides(
    raw: dict[str, Any], overrides: dict[str, Any] | None, source: str = "<overrides>"
) -> dict[str, Any]:
    """A deep copy of ``raw`` with dotted keys set, e.g. ``{"water.current_world_m_s": [0.2, 0, 0]}``."""
    out = copy.deepcopy(raw)
    for dotted, value in (overrides or {}).items():
        parts = dotted.split(".")
        node = out
        for part in parts[:-1]:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise ScenarioError(f"{source}: override '{dotted}': '{part}' is not a table")
            node = child
        node[parts[-1]] = copy.deepcopy(value)
    return out


def load_scenario(path: str | Path, overrides: dict[str, Any] | None = None) -> Scenario:
    """Read a scenario TOML file, apply dotted overrides and build the objects."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise ScenarioError(f"{source}: file not found")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{source}: not valid TOML ({exc})") from exc
    raw = apply_overrides(raw, overrides, source)
    try:
        return _build(raw, path, source)
    except ScenarioError:
        raise
    except UvmsPinError as exc:
        raise ScenarioError(f"{source}: {exc}") from exc


def _build(raw: dict[str, Any], path: Path, source: str) -> Scenario:
    top = _Table(raw, "", source)
    head = top.table("scenario") or _Table({}, "scenario", source)
    name = head.string("name", path.stem)
    description = head.string("description", "")
    model_entry = head.string("model")
    duration = head.number("duration_s", positive=True)
    seed = head.integer("seed", 0)
    head.finish()

    water = top.table("water") or _Table({}, "water", source)
    density = water.number("density_kg_m3", 1025.0, positive=True)
    current = water.vector("current_world_m_s", 3, [0.0, 0.0, 0.0])
    water.finish()

    model_path = (path.parent / model_entry).resolve()
    uvms = load_uvms(model_path, water_density_kg_m3=density)

    q0, v0 = _initial_state(top.table("initial") or _Table({}, "initial", source), uvms)
    contact = _environment(top.table("environment"))
    disturbance = _disturbance(top.table("disturbance"))
    actuation = _actuation(top.table("actuation"), uvms)
    sensor_config = _sensors(top.table("sensors") or _Table({}, "sensors", source))
    integrator, backend = _integrator(top.table("integrator") or _Table({}, "integrator", source))
    plant = Plant(uvms, current, contact, disturbance, actuation, backend)

    control = top.table("control") or _Table({}, "control", source)
    control_period = control.optional_number("period_s", positive=True)
    control.finish()
    output = top.table("output") or _Table({}, "output", source)
    log_period = output.number("log_period_s", 0.01, positive=True)
    output.finish()

    controller_table = top.table("controller")
    controller_factory = _controller(controller_table, uvms)
    top.finish()
    try:
        settings = SimulationSettings(duration, integrator, log_period, control_period, seed)
    except ParameterError as exc:
        raise ScenarioError(f"{source}: {exc}") from exc
    return Scenario(
        name, description, path, raw, plant, controller_factory, sensor_config, q0, v0, settings
    )


def _initial_state(t: _Table, uvms: UVMS) -> tuple[np.ndarray, np.ndarray]:
    n_arm = uvms.n_arm_joints
    position = t.vector("position_world_m", 3, [0.0, 0.0, 0.0])
    rpy = t.vector("rpy_rad", 3, [0.0, 0.0, 0.0])
    joints = t.vector("joint_positions_rad", n_arm, uvms.neutral_configuration()[7:])
    velocity = t.vector("velocity", uvms.nv, np.zeros(uvms.nv))
    t.finish()
    lo, hi = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    outside = (joints < lo) | (joints > hi)
    if np.any(outside):
        names = [n for n, o in zip(uvms.arm_joint_names, outside, strict=True) if o]
        raise t._err("joint_positions_rad", f"outside the joint limits for {', '.join(names)}")
    q0 = np.empty(uvms.nq)
    q0[:3] = position
    q0[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    q0[7:] = joints
    return q0, velocity


def _environment(t: _Table | None) -> ContactModel | None:
    if t is None:
        return None
    kind = t.string("type", choices=("spring", "plane"))
    anchor = t.vector("anchor_world_m", 3) if t.has("anchor_world_m") else None
    if kind == "spring":
        model: ContactModel = LinearSpring(t.vector("stiffness_N_m", 3, nonneg=True), anchor)
    else:
        model = CompliantPlane(
            normal_world=t.vector("normal_world", 3, [-1.0, 0.0, 0.0]),
            stiffness_N_m=t.number("stiffness_N_m", positive=True),
            damping_N_s_m=t.number("damping_N_s_m", 0.0, nonneg=True),
            point_world_m=anchor,
        )
    t.finish()
    return model


def _disturbance(t: _Table | None) -> SinusoidalDisturbance | None:
    if t is None:
        return None
    out = SinusoidalDisturbance(
        amplitude=t.vector("amplitude", 6),
        period_s=t.number("period_s", positive=True),
        phase_rad=t.number("phase_rad", 0.0),
    )
    t.finish()
    return out


def _sensors(t: _Table) -> SensorConfig:
    distribution = t.string("distribution", "uniform", ("uniform", "gaussian"))

    def spec(key: str) -> NoiseSpec:
        return NoiseSpec(t.number(key, 0.0, nonneg=True), distribution)

    config = SensorConfig(
        force_noise=spec("force_noise_N"),
        torque_noise=spec("torque_noise_Nm"),
        position_noise=spec("position_noise_m"),
        orientation_noise=spec("orientation_noise_rad"),
        joint_noise=spec("joint_noise_rad"),
        velocity_noise=spec("velocity_noise"),
        sample_period_s=t.number("sample_period_s", 1e-3, positive=True),
    )
    t.finish()
    return config


def _actuation(t: _Table | None, uvms: UVMS) -> Actuation:
    if t is None:
        return Unlimited()
    limit_joints = t.pop_raw("limit_joint_torques", True)
    if not isinstance(limit_joints, bool):
        raise ScenarioError(f"{t._source}: actuation.limit_joint_torques must be true or false")
    entries = t.pop_raw("thruster", [])
    if not isinstance(entries, list) or not entries:
        raise ScenarioError(f"{t._source}: [actuation] needs at least one [[actuation.thruster]]")
    thrusters = []
    for k, entry in enumerate(entries):
        e = _Table(entry, f"actuation.thruster[{k}]", t._source)
        thrusters.append(
            Thruster(
                name=e.string("name", f"thruster{k}"),
                position_body_m=e.vector("position_body_m", 3),
                direction_body=e.vector("direction_body", 3),
                max_forward_N=e.number("max_forward_N", nonneg=True),
                max_reverse_N=e.number("max_reverse_N", nonneg=True),
            )
        )
        e.finish()
    components = t.vector("allocated_components", None, [0, 1, 2, 3, 4, 5])
    t.finish()
    limits = uvms.model.effortLimit[6:].copy() if limit_joints else None
    try:
        return ThrustersAndJointLimits(thrusters, limits, components.astype(int).tolist())
    except ParameterError as exc:
        raise ScenarioError(f"{t._source}: [actuation]: {exc}") from exc


_FIXED_STEP = {"rk4": RK4, "semi_implicit_euler": SemiImplicitEuler}


def _integrator(t: _Table) -> tuple[Integrator, str]:
    """The integrator and the plant's backend ("core": compiled, "python": the reference)."""
    backend = t.string("backend", "core", BACKENDS)
    method = t.string("method", "rk4", (*_FIXED_STEP, *Adaptive._METHODS))
    if method in _FIXED_STEP:
        out = _FIXED_STEP[method](t.number("step_s", 1e-3, positive=True))
    else:
        out = Adaptive(
            method,
            rtol=t.number("rtol", 1e-6, positive=True),
            atol=t.number("atol", 1e-8, positive=True),
            max_step_s=t.number("max_step_s", math.inf, positive=True),
        )
    t.finish()
    return out, backend


def _controller(t: _Table | None, uvms: UVMS) -> ControllerFactory:
    if t is None:
        return lambda u: ZeroController(u.nv)
    kind = t.string("type", choices=tuple(_CONTROLLER_BUILDERS))
    return _CONTROLLER_BUILDERS[kind](t, uvms)


def _zero_controller(t: _Table, uvms: UVMS) -> ControllerFactory:
    t.finish()
    return lambda u: ZeroController(u.nv)


def _sine_profile(t: _Table | None, size: int) -> Callable[[float], np.ndarray]:
    """offset + amplitude sin(2 pi t / period + phase), component-wise."""
    if t is None:
        zero = np.zeros(size)
        return lambda time_s: zero
    offset = t.vector("offset", size, np.zeros(size))
    amplitude = t.vector("amplitude", size, np.zeros(size))
    period = t.number("period_s", 1.0, positive=True)
    phase = t.number("phase_rad", 0.0)
    t.finish()
    omega = 2.0 * math.pi / period
    return lambda time_s: offset + amplitude * math.sin(omega * time_s + phase)


_PPC_FIRST_LEVEL_KEYS = ("k_x", "rho0_x", "rho_inf_x", "l_x_per_s")  # 6 components
_PPC_SECOND_LEVEL_KEYS = ("k_zeta", "rho0_zeta", "rho_inf_zeta", "l_zeta_per_s", "velocity_weights")


def _ppc_controller(t: _Table, uvms: UVMS) -> ControllerFactory:
    """[controller] type = "ppc": the paper's law; omitted keys keep the paper's values."""
    ee_frame = t.string("ee_frame", uvms.model.frames[uvms.ee_frame_id].name)
    fields: dict[str, Any] = {}
    for keys, size in ((_PPC_FIRST_LEVEL_KEYS, 6), (_PPC_SECOND_LEVEL_KEYS, uvms.nv)):
        for key in keys:
            if t.has(key):
                fields[key] = t.vector(key, size)
    for key in ("null_space_gain_per_s", "pinv_relative_cutoff"):
        if t.has(key):
            fields[key] = t.number(key, nonneg=True)
    if t.has("null_space_target"):
        fields["null_space_target"] = t.vector("null_space_target", uvms.n_arm_joints)
    desired_rpy = t.vector("desired_rpy", 3, [0.0, 0.0, 0.0])
    desired_force = _sine_profile(t.table("desired_force"), 3)
    t.finish()
    try:
        params = PPCParams(desired_rpy=desired_rpy, **fields).sized(uvms.nv)
        PrescribedPerformanceController(uvms.model, ee_frame, params, desired_force)
    except ParameterError as exc:
        raise ScenarioError(f"{t._source}: [controller]: {exc}") from exc
    return lambda u: PrescribedPerformanceController(u.model, ee_frame, params, desired_force)


_CONTROLLER_BUILDERS: dict[str, Callable[[_Table, UVMS], ControllerFactory]] = {
    "none": _zero_controller,
    "ppc": _ppc_controller,
}


def simulate(scenario: Scenario, *, progress: Progress | None = None) -> Rollout:
    """Run a scenario: fresh sensors (seeded) and controller, closed loop, rollout.

    Raises FunnelViolation / SimulationError with the partial rollout attached as
    ``exc.rollout`` (see `simulate_closed_loop`).
    """
    settings = scenario.settings
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    controller = scenario.controller_factory(scenario.uvms)
    metadata = {
        "scenario": scenario.name,
        "scenario_path": str(scenario.path),
        "description": scenario.description,
        "parameters": scenario.raw,
    }
    return simulate_closed_loop(
        scenario.plant,
        controller,
        sensors,
        scenario.q0,
        scenario.v0,
        settings,
        metadata=metadata,
        progress=progress,
    )
